"""Bone tails derived from the joints (autorig_addon.core.skeleton.tails), and
their use when a glTF file's importer bones come out point-like."""

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.skeleton import tails as bone_tails
from autorig_addon.core.skeleton.tails import (
    LEAF_LENGTH_FRACTION,
    LONE_ROOT_LENGTH_FRACTION,
    assess_stored_tails,
    continued_children,
    derived_tails,
    with_reliable_tails,
)
from autorig_addon.core.types import Skeleton
from gltf_fixtures import write_box_character_gltf, write_skinned_gltf

UP = np.array([0.0, 0.0, 1.0])


def point_like(skeleton: Skeleton, length: float = 1e-4) -> Skeleton:
    """``skeleton`` with every bone shrunk to ``length`` along the +X axis
    (a direction that points at no child), as an importer guess."""
    return Skeleton(skeleton.joints, skeleton.parents, skeleton.names,
                    skeleton.joints + [length, 0.0, 0.0], skeleton.deform)


def biped() -> Skeleton:
    """Root on the floor, hips, a spine chain up to the head, two legs.

    Indices: 0 root, 1 hips, 2 spine, 3 chest, 4 head, 5 thigh.L, 6 shin.L,
    7 thigh.R, 8 shin.R. Tails sit on the child heads (a real rig)."""
    joints = np.array([
        [0, 0, 0], [0, 0, 1.0], [0, 0, 1.3], [0, 0, 1.6], [0, 0, 1.9],
        [0.15, 0, 0.95], [0.15, 0, 0.5], [-0.15, 0, 0.95], [-0.15, 0, 0.5],
    ])
    parents = np.array([-1, 0, 1, 2, 3, 1, 5, 1, 7])
    names = ("root", "hips", "spine", "chest", "head", "thigh.L", "shin.L", "thigh.R", "shin.R")
    tails = np.array([
        joints[1], joints[2], joints[3], joints[4], joints[4] + [0, 0, 0.25],
        joints[6], [0.15, 0, 0.05], joints[8], [-0.15, 0, 0.05],
    ])
    return Skeleton(joints, parents, names, tails)


# --------------------------------------------------------------------------- derivation


def test_straight_chain_tails_land_on_the_next_head():
    joints = np.array([[0, 0, 0], [0, 0, 1.0], [0, 0, 3.0]])
    tails = derived_tails(joints, [-1, 0, 1])
    np.testing.assert_allclose(tails[:2], joints[1:])
    # The leaf continues its parent's direction (up) for the fraction of the parent's 2 units.
    np.testing.assert_allclose(tails[2], [0, 0, 3.0 + 2.0 * LEAF_LENGTH_FRACTION])


def test_leaf_continues_the_line_from_its_parent_by_the_fraction():
    joints = np.array([[0, 0, 0], [1.0, 0, 0], [1.0, 2.0, 0]])
    tails = derived_tails(joints, [-1, 0, 1])
    np.testing.assert_allclose(tails[1], [1.0, 2.0, 0])
    np.testing.assert_allclose(tails[2], [1.0, 2.0 + 2.0 * LEAF_LENGTH_FRACTION, 0])


def test_branch_the_child_with_most_descendants_wins_when_alignment_is_unclear():
    # Incoming direction +Z; child 2 leans 48 deg off it and has a chain of 2
    # below; child 5 leans 40 deg (better aligned, by less than the margin), no chain.
    joints = np.array([[0, 0, 0], [0, 0, 1.0], [1.0, 0, 1.9], [2.0, 0, 2.8], [3.0, 0, 3.7], [-1.0, 0, 2.2]])
    parents = np.array([-1, 0, 1, 2, 3, 1])
    child, _ = continued_children(joints, parents)
    assert child[1] == 2
    np.testing.assert_allclose(derived_tails(joints, parents)[1], joints[2])


def test_branch_a_clearly_aligned_child_continues_the_bone():
    # Child 2 straight up (cos 1), child 3 sideways (cos 0) with more descendants.
    joints = np.array([[0, 0, 0], [0, 0, 1.0], [0, 0, 2.0], [1.0, 0, 1.0], [2.0, 0, 1.0], [3.0, 0, 1.0]])
    parents = np.array([-1, 0, 1, 1, 3, 4])
    assert continued_children(joints, parents)[0][1] == 2


def test_root_branch_goes_to_the_child_with_most_descendants():
    # No incoming direction at a root: the chain of three beats the single child.
    joints = np.array([[0, 0, 0], [0, 1.0, 0], [1.0, 0, 0], [2.0, 0, 0], [3.0, 0, 0]])
    parents = np.array([-1, 0, 0, 2, 3])
    np.testing.assert_allclose(derived_tails(joints, parents)[0], joints[2])


def test_mirror_twins_never_continue_a_bone():
    # The neck goes to the head, not to one of the two ears (each with a child).
    joints = np.array([[0, 0, 0], [0, 0, 1.0], [0, 0.1, 1.3], [0.2, 0, 1.3], [0.3, 0, 1.5], [-0.2, 0, 1.3],
                       [-0.3, 0, 1.5]])
    parents = np.array([-1, 0, 1, 1, 3, 1, 5])
    np.testing.assert_allclose(derived_tails(joints, parents)[1], joints[2])


def test_children_at_the_head_are_skipped_and_lone_roots_have_no_direction():
    # 0 root with its only child (hips) at its own place, 2 spine above; 3 a lone bone.
    joints = np.array([[0, 0, 1.0], [0, 0, 1.0], [0, 0, 2.0], [5.0, 0, 0]])
    tails = derived_tails(joints, [-1, 0, 1, -1])
    assert np.isnan(tails[0]).all() and np.isnan(tails[3]).all()
    np.testing.assert_allclose(tails[1], joints[2])
    # The spine's parent direction comes from the root-hips point, one unit below.
    np.testing.assert_allclose(tails[2], [0, 0, 2.0 + LEAF_LENGTH_FRACTION])


def test_stored_directions_orient_leaves_and_choose_among_twins():
    joints = np.array([[0, 0, 0], [0, 0, 1.0], [0.2, 0, 1.3], [-0.2, 0, 1.3], [0, 0, 2.0]])
    parents = np.array([-1, 0, 1, 1, 1])
    directions = np.array([UP, [0.2, 0, 0.3], [1.0, 0, 0], [0, 0, 0], [0, 1.0, 0]])
    tails = derived_tails(joints, parents, directions)
    np.testing.assert_allclose(tails[1], joints[2])  # its direction points at the left twin
    np.testing.assert_allclose(tails[2], joints[2] + [np.hypot(0.2, 0.3) * LEAF_LENGTH_FRACTION, 0, 0])
    np.testing.assert_allclose(tails[3], joints[3] + LEAF_LENGTH_FRACTION * (joints[3] - joints[1]))  # no direction
    np.testing.assert_allclose(tails[4], joints[4] + [0, LEAF_LENGTH_FRACTION, 0])


# --------------------------------------------------------------------------- per-armature decision


def test_point_like_armature_is_unusable_and_a_real_one_usable():
    real = biped()
    assert assess_stored_tails(real, 2.0).usable
    assessment = assess_stored_tails(point_like(real), 2.0)
    assert not assessment.usable
    assert assessment.median_length_fraction == pytest.approx(1e-4 / 2.0)
    assert "point-like" in assessment.reason


def test_bones_stopping_short_of_their_children_are_unusable():
    real = biped()
    short = Skeleton(real.joints, real.parents, real.names, real.joints + 0.1 * (real.tails - real.joints))
    assessment = assess_stored_tails(short, 2.0)
    assert not assessment.usable and assessment.median_reach == pytest.approx(0.1)
    assert "stop short" in assessment.reason


def test_point_like_armature_gets_derived_tails_and_heads_stay():
    real = biped()
    fixed, decision = with_reliable_tails(point_like(real), 2.0)
    np.testing.assert_array_equal(fixed.joints, real.joints)
    assert fixed.names == real.names and np.array_equal(fixed.parents, real.parents)
    # Every bone with a child ends on the child that continues it: the hips on the spine.
    for j in (0, 1, 2, 3, 5, 7):
        np.testing.assert_allclose(fixed.tails[j], real.tails[j], atol=1e-12)
    np.testing.assert_allclose(fixed.tails[4],
                               real.joints[4] + LEAF_LENGTH_FRACTION * (real.joints[4] - real.joints[3]))
    assert decision.whole_armature and decision.derived == real.names
    assert decision.note.startswith("bone tails derived from the joints: the stored bones are point-like")
    assert "0.005 % of the character" in decision.note
    assert "directions" not in decision.note  # +X points at no child: not kept


def test_point_like_directions_that_point_at_children_are_kept():
    real = biped()
    directions = real.tails - real.joints
    shrunk = Skeleton(real.joints, real.parents, real.names, real.joints + 1e-4 * directions, real.deform)
    fixed, decision = with_reliable_tails(shrunk, 2.0)
    np.testing.assert_allclose(fixed.tails[:4], real.tails[:4], atol=1e-12)
    # The shin (a leaf) keeps its stored direction, straight down, one thigh long.
    np.testing.assert_allclose(fixed.tails[6], real.joints[6] + [0, 0, -LEAF_LENGTH_FRACTION * 0.45], atol=1e-12)
    assert "directions" in decision.note


def test_lone_root_of_a_point_like_armature_points_up():
    skeleton = Skeleton(np.array([[0, 0, 0], [1.0, 0, 0]]), [-1, -1], ("a", "b"), np.array([[0, 0, 0.0], [1.0, 0, 0]]))
    fixed, decision = with_reliable_tails(skeleton, 2.0)
    np.testing.assert_allclose(fixed.tails,
                               [[0, 0, LONE_ROOT_LENGTH_FRACTION * 2.0], [1.0, 0, LONE_ROOT_LENGTH_FRACTION * 2.0]])
    assert decision.whole_armature


def test_real_armature_keeps_its_tails():
    real = biped()
    fixed, decision = with_reliable_tails(real, 2.0)
    assert fixed is real
    assert not decision.any_derived and decision.note.startswith("stored bone tails used: the stored bones are real")


def test_point_like_bone_with_a_child_in_a_real_armature_ends_at_the_child():
    real = biped()
    tails = real.tails.copy()
    tails[2] = real.joints[2] + [0, 0, 1e-6]
    fixed, decision = with_reliable_tails(Skeleton(real.joints, real.parents, real.names, tails), 2.0)
    np.testing.assert_allclose(fixed.tails, real.tails)
    assert decision.derived == ("spine",) and not decision.whole_armature
    assert "'spine'" in decision.note
    assert decision.note.startswith("bone tails derived from the joints for 1 point-like bone")


def test_point_like_deform_leaf_in_a_real_armature_is_refused_by_name():
    real = biped()
    tails = real.tails.copy()
    tails[4] = real.joints[4] + [0, 0, 1e-6]
    with pytest.raises(InputError,
                       match=r"Deform bone 'head' has zero length and no child to point at: give it a length"):
        with_reliable_tails(Skeleton(real.joints, real.parents, real.names, tails), 2.0)
    # A non-deform leaf (a control) is no obstacle and keeps its tail.
    deform = np.ones(real.bone_count, dtype=bool)
    deform[4] = False
    fixed, decision = with_reliable_tails(Skeleton(real.joints, real.parents, real.names, tails, deform), 2.0)
    np.testing.assert_array_equal(fixed.tails, tails)
    assert not decision.any_derived


def test_several_point_like_deform_leaves_are_listed():
    real = biped()
    tails = real.tails.copy()
    tails[[6, 8]] = real.joints[[6, 8]]
    with pytest.raises(InputError, match=r"Deform bones 'shin.L', 'shin.R' have zero length"):
        with_reliable_tails(Skeleton(real.joints, real.parents, real.names, tails), 2.0)


def test_thresholds_are_shares_of_the_size():
    # The same skeleton is point-like next to a large mesh and real next to its own size.
    real = biped()
    threshold = float(np.median(real.bone_lengths)) / bone_tails.MIN_MEDIAN_LENGTH_FRACTION
    assert assess_stored_tails(real, 0.99 * threshold).usable
    assert not assess_stored_tails(real, 1.01 * threshold).usable


# --------------------------------------------------------------------------- a glTF file with point-like bones

#: The chain of the test file: joints this far apart in the armature's
#: units, the armature node scaled by ARMATURE_SCALE (the Quaternius layout).
JOINT_STEP = 0.005
ARMATURE_SCALE = 100.0
CHAIN_JOINTS = 3


def write_point_like_gltf(path) -> None:
    """A .gltf (buffer embedded) with a 3-joint chain going up and a skinned box
    around it, laid out as the Quaternius files are: the armature node scaled
    by 100, joint translations in hundredths, so Blender's importer (which
    sizes bones in the armature's own units) makes bones 1 % of their length."""
    step = JOINT_STEP * ARMATURE_SCALE  # world distance between joints (glTF is Y-up)
    heights = np.linspace(0.0, step * (CHAIN_JOINTS - 1) + 0.3, 13)
    half = 0.1
    corners = [(-half, -half), (half, -half), (half, half), (-half, half)]
    positions = np.array([[x, y, z] for y in heights for x, z in corners], dtype=np.float32)
    triangles = []
    for ring in range(len(heights) - 1):
        for side in range(4):
            a, b = 4 * ring + side, 4 * ring + (side + 1) % 4
            triangles += [(a, a + 4, b), (b, a + 4, b + 4)]
    top = 4 * (len(heights) - 1)
    triangles += [(0, 1, 2), (0, 2, 3), (top, top + 2, top + 1), (top, top + 3, top + 2)]
    indices = np.array(triangles, dtype=np.uint16).ravel()
    joint_ids = np.zeros((len(positions), 4), dtype=np.uint8)
    joint_ids[:, 0] = np.minimum((positions[:, 1] / step).astype(int), CHAIN_JOINTS - 1)
    weights = np.zeros((len(positions), 4), dtype=np.float32)
    weights[:, 0] = 1.0
    inverse_binds = []
    for k in range(CHAIN_JOINTS):
        matrix = np.eye(4) / ARMATURE_SCALE
        matrix[3, 3] = 1.0
        matrix[1, 3] = -JOINT_STEP * k
        inverse_binds.append(matrix.T.ravel())  # glTF matrices are column-major
    nodes = [{"name": "Armature", "scale": [ARMATURE_SCALE] * 3, "children": [1]}]
    for k in range(CHAIN_JOINTS):
        node = {"name": f"Bone{k}", "translation": [0.0, JOINT_STEP if k else 0.0, 0.0]}
        if k + 1 < CHAIN_JOINTS:
            node["children"] = [k + 2]
        nodes.append(node)
    write_skinned_gltf(path, nodes, [0], list(range(1, CHAIN_JOINTS + 1)), positions, joint_ids, weights, indices,
                       inverse_binds)


def test_point_like_gltf_bones_get_tails_on_the_child_heads(clean_scene, tmp_path):
    import bpy

    from autorig_addon.blender import bone_heat, characters, convert

    path = tmp_path / "chain.gltf"
    write_point_like_gltf(path)
    character = characters.load_character(path)
    armature = bpy.data.objects[character.armature_name]
    stored = convert.read_skeleton(armature)
    step = JOINT_STEP * ARMATURE_SCALE
    # Blender's importer indeed makes point-like bones: 1 % of the way to the child.
    np.testing.assert_allclose(stored.joints, [[0, 0, 0], [0, 0, step], [0, 0, 2 * step]], atol=1e-5)
    assert stored.bone_lengths.max() < 0.02 * step
    skeleton = character.skeleton
    assert skeleton.names == ("Bone0", "Bone1", "Bone2")
    np.testing.assert_allclose(skeleton.joints, stored.joints, atol=1e-9)
    np.testing.assert_allclose(skeleton.tails[:2], stored.joints[1:], atol=1e-5)
    np.testing.assert_allclose(skeleton.tails[2], [0, 0, (2 + LEAF_LENGTH_FRACTION) * step], atol=1e-5)
    assert any(note.startswith("bone tails derived from the joints") for note in character.notes)
    # The file's own armature is unchanged, and so is its bone heat input after a run.
    bones_before = [(bone.name, tuple(bone.tail_local)) for bone in armature.data.bones]
    objects_before = sorted(obj.name for obj in bpy.data.objects)
    armatures_before = len(bpy.data.armatures)
    weights = bone_heat.bone_heat_weights(character.mesh, skeleton, armature)
    assert [(bone.name, tuple(bone.tail_local)) for bone in armature.data.bones] == bones_before
    assert sorted(obj.name for obj in bpy.data.objects) == objects_before
    assert len(bpy.data.armatures) == armatures_before
    # With real bones bone heat gives the bottom to the first bone and the top to the last.
    share = weights.matrix / np.maximum(weights.matrix.sum(axis=1, keepdims=True), 1e-12)
    z = character.mesh.vertices[:, 2]
    assert share[z < 0.2 * step, 0].min() > 0.9
    assert share[z > 2.2 * step, 2].min() > 0.9


def test_point_like_bone_above_mirrored_children_continues_its_parent_line():
    # spine (real) -> pelvis (point-like, deform) -> thigh.L / thigh.R (mirror twins).
    joints = [[0, 0, 2], [0, 0, 1], [0.2, 0, 1], [-0.2, 0, 1]]
    tails = [[0, 0, 1], [0, 0, 1.0000001], [0.2, 0, 0], [-0.2, 0, 0]]
    skeleton = Skeleton(joints, [-1, 0, 1, 1], ("spine", "pelvis", "thigh.L", "thigh.R"), tails)
    fixed, decision = with_reliable_tails(skeleton, 3.0)
    # No child continues the pelvis, so it keeps the spine's downward line for the spine's length.
    np.testing.assert_allclose(fixed.tails[1], [0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(fixed.tails[[0, 2, 3]], skeleton.tails[[0, 2, 3]])
    assert decision.derived == ("pelvis",)
    assert decision.note.endswith("continue their parent's line between mirrored children")


# --------------------------------------------------------------------------- bones all pointing one way


def one_way(skeleton: Skeleton, direction=(0.0, 1.0, 0.0), bones=None) -> Skeleton:
    """``skeleton`` with its bones (all, or the indices ``bones``) turned to
    ``direction``, lengths kept: what Blender's glTF importer makes of a file
    whose joint frames were never turned (Kenney's minis)."""
    tails = skeleton.tails.copy()
    chosen = np.arange(skeleton.bone_count) if bones is None else np.asarray(bones)
    tails[chosen] = skeleton.joints[chosen] + skeleton.bone_lengths[chosen, None] * np.asarray(direction)
    return Skeleton(skeleton.joints, skeleton.parents, skeleton.names, tails, skeleton.deform)


def test_bones_all_pointing_one_way_and_not_at_their_children_get_derived_tails():
    real = biped()
    turned = one_way(real)
    assessment = assess_stored_tails(turned, 2.0)
    assert assessment.one_way_share == 1.0 and assessment.direction_agreement == 0.0
    assert not assessment.usable
    fixed, decision = with_reliable_tails(turned, 2.0)
    # Every bone with a child ends on it; the shins continue their thighs' line
    # down to where the real ones end; only the head (a leaf) is a guess.
    np.testing.assert_allclose(fixed.tails[:4], real.tails[:4], atol=1e-12)
    np.testing.assert_allclose(fixed.tails[5:], real.tails[5:], atol=1e-12)
    head_line = real.joints[4] - real.joints[3]
    np.testing.assert_allclose(fixed.tails[4], real.joints[4] + LEAF_LENGTH_FRACTION * head_line)
    assert decision.whole_armature
    assert decision.note == ("bone tails derived from the joints: the stored bones point one way "
                             "(100 % of them), not at their children (0 % do): the importer's joint axis, "
                             "not the bones")


def test_point_like_bones_pointing_one_way_are_told_point_like_and_zero_length_ones_do_not_vote():
    real = biped()
    assessment = assess_stored_tails(one_way(point_like(real)), 2.0)
    assert not assessment.usable and assessment.reason.startswith("the stored bones are point-like")
    # Two bones of zero length (no direction) are left out of the share: the other 7 all point one way.
    tails = one_way(real).tails
    tails[[4, 8]] = real.joints[[4, 8]]
    assessment = assess_stored_tails(Skeleton(real.joints, real.parents, real.names, tails), 2.0)
    assert assessment.one_way_share == 1.0 and not assessment.usable


def test_one_way_bones_are_kept_below_the_share_or_when_they_point_at_their_children():
    real = biped()
    # 8 of the 9 bones one way (89 %) is below ONE_WAY_SHARE: kept.
    most = one_way(real, bones=range(8))
    assessment = assess_stored_tails(most, 2.0)
    assert assessment.one_way_share == pytest.approx(8 / 9) and assessment.usable
    # A straight vertical chain (a tentacle, a fish's spine) points one way, at its children: real bones.
    joints = np.array([[0, 0, 0], [0, 0, 1.0], [0, 0, 2.0], [0, 0, 3.0]])
    chain = Skeleton(joints, [-1, 0, 1, 2], ("a", "b", "c", "d"), joints + [0, 0, 1.0])
    fixed, decision = with_reliable_tails(chain, 5.0)
    assert assess_stored_tails(chain, 5.0).one_way_share == 1.0
    assert fixed is chain and not decision.any_derived
    # Parallel bones with no children (a curtain of roots) have no children to disagree with: kept.
    feet = np.array([[0, 0, 0], [1.0, 0, 0], [2.0, 0, 0], [3.0, 0, 0]])
    roots = Skeleton(feet, [-1, -1, -1, -1], ("a", "b", "c", "d"), feet + [0, 0, 1.0])
    assert assess_stored_tails(roots, 5.0).usable
    # A comb of parallel teeth on a bar parallel to them: one bone with children is one vote, too few.
    comb = Skeleton(np.vstack([[1.5, 0, 1.0], feet]), [-1, 0, 0, 0, 0], ("bar", "a", "b", "c", "d"),
                    np.vstack([[1.5, 0, 0.5], feet - [0, 0, 0.5]]))
    assessment = assess_stored_tails(comb, 5.0)
    assert assessment.one_way_share == 1.0 and assessment.direction_agreement == 0.0 and assessment.usable
    # Two bones are too few to tell an importer's axis from a rig.
    pair = Skeleton([[0, 0, 0], [1.0, 0, 0]], [-1, 0], ("a", "b"), [[0, 0, 1.0], [1.0, 0, 1.0]])
    assessment = assess_stored_tails(pair, 3.0)
    assert assessment.one_way_share == 0.0 and assessment.usable


#: A blocky character as Kenney's minis are laid out: the root on the floor,
#: the legs hanging from the hips, the torso and head a few centimetres off
#: the root's vertical (name, parent, head, box it carries). Those offsets
#: (8.5 and 9.5 degrees, as the minis' own) are what tell the stored
#: directions from the bones: with the root, torso and head stacked within
#: 8 degrees, the root and torso would point at a child and the upward legs
#: would be kept (the rule's known limit, core.skeleton.tails).
UNTURNED_MINI = (
    ("root", -1, (0.0, 0.0, 0.0), None),
    ("leg.L", 0, (0.1, 0.0, 0.2), ((0.04, -0.05, 0.0), (0.16, 0.05, 0.2))),
    ("leg.R", 0, (-0.1, 0.0, 0.2), ((-0.16, -0.05, 0.0), (-0.04, 0.05, 0.2))),
    ("torso", 0, (0.0, -0.03, 0.2), ((-0.18, -0.1, 0.2), (0.18, 0.1, 0.5))),
    ("head", 3, (0.0, 0.02, 0.5), ((-0.2, -0.15, 0.5), (0.2, 0.15, 0.85))),
)


def test_gltf_joints_never_turned_get_bones_along_the_hierarchy(clean_scene, tmp_path):
    import bpy

    from autorig_addon.blender import characters, convert
    from autorig_addon.core.skinning.methods import DEFAULT_SKIN_METHOD, skin_weights
    from autorig_addon.core.skinning.options import SkinningOptions

    path = tmp_path / "mini.gltf"
    write_box_character_gltf(path, UNTURNED_MINI)
    character = characters.load_character(path)
    stored = convert.read_skeleton(bpy.data.objects[character.armature_name])
    # Blender's importer points every bone up, along the unturned joint frames: the legs into the torso.
    directions = stored.tails - stored.joints
    np.testing.assert_allclose(directions / np.linalg.norm(directions, axis=1, keepdims=True),
                               np.tile(UP, (5, 1)), atol=1e-6)
    skeleton = character.skeleton
    heads = np.array([head for _, _, head, _ in UNTURNED_MINI])
    np.testing.assert_allclose(skeleton.joints, heads, atol=1e-6)
    np.testing.assert_allclose(skeleton.tails[3], heads[4], atol=1e-6)  # the torso ends at the head
    # The legs (leaves) continue the line from the root through the hips, out and up, no longer along the torso.
    np.testing.assert_allclose(skeleton.tails[1], heads[1] + LEAF_LENGTH_FRACTION * heads[1], atol=1e-6)
    assert ("bone tails derived from the joints: the stored bones point one way (100 % of them), not at their "
            "children (0 % do): the importer's joint axis, not the bones") in character.notes
    # The default network gives most of the torso box to the torso along the derived bones. (What the
    # stored bones cost depends on how finely this toy is cut; on the minis: docs/skinning.md.)
    weights = skin_weights(character.mesh, skeleton, SkinningOptions(method=DEFAULT_SKIN_METHOD))
    torso_box = character.weights.matrix[:, character.weights.bone_names.index("torso")] > 0.5
    dominant = np.array(weights.bone_names)[weights.matrix.argmax(axis=1)]
    assert np.mean(dominant[torso_box] == "torso") > 2 / 3
