"""Bone names by role (core/rigging/role_names.py) on the procedural
generator's exact skeletons and on skeletons built here by hand."""

import re

import numpy as np
import pytest

from autorig_addon.core.dataset.normalise import normalise
from autorig_addon.core.errors import InputError
from autorig_addon.core.procedural import KINDS, generate_character
from autorig_addon.core.rigging.role_names import BIPED, OTHER, QUADRUPED, classify_body, role_names
from autorig_addon.core.skeleton.naming import LEFT_SUFFIX, RIGHT_SUFFIX, mirror_name

#: The generator's biped is Rigify's basic human: these names are ours too.
BIPED_ROLE_NAMES = (
    "spine", "spine.001", "spine.002", "spine.003", "thigh.L", "shin.L", "foot.L", "toe.L",
    "shoulder.L", "upper_arm.L", "forearm.L", "hand.L",
)
#: Rigify's human numbers neck and head on along the spine; we name them.
BIPED_RENAMED = {"spine.004": "neck", "spine.005": "neck.001", "spine.006": "head"}
#: The generator's quadruped is Rigify's basic quadruped without its tail
#: bones, so our trunk numbering starts at ``spine`` where Rigify's starts at
#: ``spine.004``; legs and the grown tail keep their names.
QUADRUPED_RENAMED = {
    "spine.004": "spine", "spine.005": "spine.001", "spine.006": "spine.002", "spine.007": "spine.003",
    "spine.008": "spine.004", "spine.009": "neck", "spine.010": "neck.001", "spine.011": "head",
    "ear.L": "limb.L", "ear.R": "limb.R",
}
#: Every structural (not recognised) name: a base, a chain number, a number along, a side.
STRUCTURAL_NAME = re.compile(r"^(root|spine|tail|chain|limb|leg)(_\d+)?(\.\d{3})?(\.L|\.R)?$")


def mirror_indices(names):
    """(j,) mirror twins from the generator's ``.L``/``.R`` names."""
    index = {name: k for k, name in enumerate(names)}
    return np.array([index.get(mirror_name(name), -1) if mirror_name(name) != name else -1 for name in names])


def procedural_skeleton(kind, seed, deform_only=True):
    """The generator's skeleton in the normalised frame, with its mirror twins."""
    character = generate_character(seed, kind)
    skeleton = normalise(character.mesh, character.skeleton).skeleton
    if deform_only:
        skeleton = skeleton.deform_subset()
    return skeleton, mirror_indices(skeleton.names)


def named(skeleton, mirror):
    return role_names(skeleton.joints, skeleton.parents, mirror)


class Builder:
    """A skeleton built joint by joint: midline joints and mirrored pairs
    (the left one given; the right one is its mirror image across x = 0)."""

    def __init__(self):
        self.joints, self.parents, self.mirror = [], [], []

    def add(self, point, parent=-1):
        self.joints.append(point)
        self.parents.append(parent)
        self.mirror.append(-1)
        return len(self.joints) - 1

    def add_pair(self, left_point, parent):
        """``parent``: a midline index or a (left, right) pair; returns the new pair."""
        left_parent, right_parent = parent if isinstance(parent, tuple) else (parent, parent)
        left = self.add(left_point, left_parent)
        right = self.add([-left_point[0], left_point[1], left_point[2]], right_parent)
        self.mirror[left], self.mirror[right] = right, left
        return left, right

    def add_pair_chain(self, left_points, parent):
        pairs = []
        for point in left_points:
            parent = self.add_pair(point, parent)
            pairs.append(parent)
        return pairs

    def names(self):
        return role_names(np.array(self.joints, dtype=float), np.array(self.parents), np.array(self.mirror))

    def kind(self):
        return classify_body(np.array(self.joints, dtype=float), np.array(self.parents), np.array(self.mirror))


def hand_built_biped(spine_joints=4, arm=((0.03, 0, 0.78), (0.15, 0, 0.8), (0.32, 0, 0.8), (0.48, 0, 0.8)),
                     fingers=False):
    """A T-posed biped one unit tall: hips at 0.5, the arms hang from the
    last spine joint, neck and head above; returns the builder and the
    indices of the left arm joints and of the left finger roots."""
    skeleton = Builder()
    spine = [skeleton.add([0, 0, 0.5])]
    for z in np.linspace(0.5, 0.8, spine_joints)[1:]:
        spine.append(skeleton.add([0, 0, z], spine[-1]))
    skeleton.add_pair_chain([(0.1, 0, 0.48), (0.1, -0.02, 0.27), (0.1, 0, 0.05), (0.1, -0.1, 0.01)], spine[0])
    arm_pairs = skeleton.add_pair_chain(arm, spine[-1])
    finger_roots = []
    if fingers:
        wrist = np.array(arm[-1], dtype=float)
        thumb = skeleton.add_pair_chain([wrist + (0.02, -0.03, -0.01), wrist + (0.04, -0.05, -0.01)], arm_pairs[-1])
        finger_roots.append(thumb[0][0])
        for y in (-0.02, -0.005, 0.01, 0.025):
            finger = skeleton.add_pair_chain([wrist + (0.06, y, 0), wrist + (0.09, y, 0)], arm_pairs[-1])
            finger_roots.append(finger[0][0])
    neck = skeleton.add([0, 0, 0.85], spine[-1])
    skeleton.add([0, 0, 0.92], neck)
    return skeleton, [left for left, _ in arm_pairs], finger_roots


@pytest.mark.parametrize("seed", range(6))
def test_procedural_biped_gets_rigify_names(seed):
    skeleton, mirror = procedural_skeleton("biped", seed)
    names = named(skeleton, mirror)
    assert classify_body(skeleton.joints, skeleton.parents, mirror) == BIPED
    given = dict(zip(skeleton.names, names))
    for name in BIPED_ROLE_NAMES:
        assert given[name] == name
        assert given[mirror_name(name)] == mirror_name(name)
    for rigify_name, ours in BIPED_RENAMED.items():
        assert given[rigify_name] == ours
    for name in skeleton.names:  # the generator's fingers are Rigify's: thumb.01.L ... f_pinky.03.R
        if name.startswith(("thumb.", "f_")):
            assert given[name] == name


def test_procedural_biped_names_in_full():
    # Seed 0: a ponytail hangs from the head (a chain, not the head); the
    # full skeleton adds a root bone on the floor and foot-roll heels.
    skeleton, mirror = procedural_skeleton("biped", 0)
    expected = [BIPED_RENAMED.get(name, name) for name in skeleton.names]
    expected = [{"hair": "chain", "hair.001": "chain.001", "hair.002": "chain.002"}.get(n, n) for n in expected]
    assert named(skeleton, mirror) == tuple(expected)

    full, full_mirror = procedural_skeleton("biped", 0, deform_only=False)
    given = dict(zip(full.names, named(full, full_mirror)))
    assert (given["root"], given["heel.02.L"], given["heel.02.R"]) == ("root", "limb.L", "limb.R")
    assert (given["spine"], given["thigh.L"], given["upper_arm.R"],
            given["spine.006"]) == ("spine", "thigh.L", "upper_arm.R", "head")


@pytest.mark.parametrize("seed", range(6))
def test_procedural_quadruped_gets_rigify_leg_names_and_its_tail(seed):
    skeleton, mirror = procedural_skeleton("quadruped", seed)
    names = named(skeleton, mirror)
    assert classify_body(skeleton.joints, skeleton.parents, mirror) == QUADRUPED
    assert names == tuple(QUADRUPED_RENAMED.get(name, name) for name in skeleton.names)
    assert {"front_thigh.L", "front_toe.R", "thigh.R", "toe.L", "shoulder.L", "tail", "tail.001", "head"} <= set(names)


def test_quadruped_with_a_root_bone_below_its_feet():
    # Seed 5's root bone lies below the toes: the ground is the lowest limb joint.
    skeleton, mirror = procedural_skeleton("quadruped", 5, deform_only=False)
    names = named(skeleton, mirror)
    assert names[0] == "root"
    assert names[1:] == tuple(QUADRUPED_RENAMED.get(name, name) for name in skeleton.names[1:])


def test_lizard_is_a_quadruped_with_three_joint_front_legs():
    skeleton, mirror = procedural_skeleton("tailed", 0)
    assert generate_character(0, "tailed").variant == "lizard"
    given = dict(zip(skeleton.names, named(skeleton, mirror)))
    assert classify_body(skeleton.joints, skeleton.parents, mirror) == QUADRUPED
    assert [given[n] for n in ("upper_arm.L", "forearm.L", "hand.R")] == [
        "front_thigh.L", "front_shin.L", "front_foot.R"]
    assert [given[n] for n in ("thigh.L", "shin.L", "foot.L")] == ["thigh.L", "shin.L", "foot.L"]
    assert [given[n] for n in ("spine", "spine.002", "spine.003", "head", "tail", "tail.007")] == [
        "spine", "spine.002", "neck", "head", "tail", "tail.007"]


@pytest.mark.parametrize("kind,seed,expected", [
    ("prop", 0, ("root", "spine", "spine.001")),  # lamp: base, lower arm, shade
    ("prop", 1, ("root", "spine")),                # chest: base, lid
])
def test_props_get_structural_names(kind, seed, expected):
    skeleton, mirror = procedural_skeleton(kind, seed)
    assert classify_body(skeleton.joints, skeleton.parents, mirror) == OTHER
    assert named(skeleton, mirror) == expected


def test_fish_gets_a_spine_forward_and_a_tail_backward():
    # Rigify's shark: spine.003 in the middle, the tail spine.002..spine
    skeleton, mirror = procedural_skeleton("fish", 0)
    given = dict(zip(skeleton.names, named(skeleton, mirror)))
    assert classify_body(skeleton.joints, skeleton.parents, mirror) == OTHER
    assert [given[n] for n in ("spine.003", "spine.008", "spine.004", "spine.002", "spine.001", "spine")] == [
        "root", "spine", "spine.001", "tail", "tail.001", "tail.002"]
    assert (given["chest_fin.Bot.L"], given["chest_fin.Bot.R"]) == ("limb.L", "limb.R")
    assert all(STRUCTURAL_NAME.match(name) for name in given.values())


def test_long_chain_gets_one_numbered_spine():
    skeleton, mirror = procedural_skeleton("long_chain", 4)  # a rope, every joint on its own
    names = named(skeleton, mirror)
    assert names == ("root",) + tuple(["spine"] + [f"spine.{k:03d}" for k in range(1, skeleton.bone_count - 1)])


def test_spider_legs_are_numbered_legs():
    skeleton, mirror = procedural_skeleton("multileg", 0)
    given = dict(zip(skeleton.names, named(skeleton, mirror)))
    assert classify_body(skeleton.joints, skeleton.parents, mirror) == OTHER
    assert [given[f"leg_0{k}.L"] for k in range(1, 5)] == ["leg.L", "leg_2.L", "leg_3.L", "leg_4.L"]
    assert given["leg_04.003.R"] == "leg_4.003.R"


@pytest.mark.parametrize("kind", KINDS)
def test_names_are_unique_and_mirrored_for_every_kind(kind):
    for seed in range(8):
        for deform_only in (True, False):
            skeleton, mirror = procedural_skeleton(kind, seed, deform_only)
            names = named(skeleton, mirror)
            assert len(set(names)) == len(names) == skeleton.bone_count
            for k, name in enumerate(names):
                if mirror[k] < 0:
                    assert not name.endswith((LEFT_SUFFIX, RIGHT_SUFFIX))
                else:
                    assert names[mirror[k]] == mirror_name(name) != name
                    x, twin_x = skeleton.joints[k, 0], skeleton.joints[mirror[k], 0]
                    at_left = x > twin_x or (x == twin_x and k < mirror[k])  # a dolphin's flukes start at x = 0
                    assert name.endswith(LEFT_SUFFIX if at_left else RIGHT_SUFFIX)


def test_names_do_not_depend_on_scale_or_position():
    skeleton, mirror = procedural_skeleton("biped", 3)
    moved = skeleton.joints * 3.7 + np.array([2.0, -1.0, 0.5])
    assert role_names(moved, skeleton.parents, mirror) == named(skeleton, mirror)


def test_hand_built_biped():
    skeleton, arm, _ = hand_built_biped()
    assert skeleton.kind() == BIPED
    assert skeleton.names() == (
        "spine", "spine.001", "spine.002", "spine.003",
        "thigh.L", "thigh.R", "shin.L", "shin.R", "foot.L", "foot.R", "toe.L", "toe.R",
        "shoulder.L", "shoulder.R", "upper_arm.L", "upper_arm.R", "forearm.L", "forearm.R", "hand.L", "hand.R",
        "neck", "head",
    )


def test_biped_with_a_seven_joint_spine():
    skeleton, _, _ = hand_built_biped(spine_joints=7)
    names = skeleton.names()
    assert names[:7] == ("spine", "spine.001", "spine.002", "spine.003", "spine.004", "spine.005", "spine.006")
    assert names[-2:] == ("neck", "head")


def test_arm_without_clavicle_starts_at_the_upper_arm():
    skeleton, arm, _ = hand_built_biped(arm=((0.15, 0, 0.8), (0.32, 0, 0.8), (0.48, 0, 0.8)))
    names = skeleton.names()
    assert [names[k] for k in arm] == ["upper_arm.L", "forearm.L", "hand.L"]


def test_arm_with_an_extra_joint_before_a_hand_with_five_fingers():
    arm = ((0.03, 0, 0.78), (0.15, 0, 0.8), (0.32, 0, 0.8), (0.40, 0, 0.8), (0.48, 0, 0.8))
    skeleton, arm_joints, fingers = hand_built_biped(arm=arm, fingers=True)
    names = skeleton.names()
    assert [names[k] for k in arm_joints] == ["shoulder.L", "upper_arm.L", "forearm.L", "forearm.001.L", "hand.L"]
    assert [names[k] for k in fingers] == ["thumb.01.L", "f_index.01.L", "f_middle.01.L", "f_ring.01.L", "f_pinky.01.L"]
    assert [names[k + 2] for k in fingers] == [
        "thumb.02.L", "f_index.02.L", "f_middle.02.L", "f_ring.02.L", "f_pinky.02.L"]
    assert names[fingers[0] + 1] == "thumb.01.R"


def test_arm_with_an_extra_joint_and_no_fingers_continues_the_hand():
    arm = ((0.03, 0, 0.78), (0.15, 0, 0.8), (0.32, 0, 0.8), (0.48, 0, 0.8), (0.56, 0, 0.8))
    skeleton, arm_joints, _ = hand_built_biped(arm=arm)
    names = skeleton.names()
    assert [names[k] for k in arm_joints] == ["shoulder.L", "upper_arm.L", "forearm.L", "hand.L", "hand.001.L"]


def test_single_joint_two_joints_and_a_star():
    assert role_names([[0.0, 0.0, 0.0]], [-1], [-1]) == ("root",)
    assert role_names([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]], [-1, 0], [-1, -1]) == ("root", "spine")
    assert role_names([[0.0, 0.0, 0.5], [0.3, 0.0, 0.5], [-0.3, 0.0, 0.5]], [-1, 0, 0], [-1, 2, 1]) == (
        "root", "limb.L", "limb.R")
    directions = np.array([[0, 0, 1], [0, 1, 0], [0, -1, 0], [0, 0, -1], [0, 0.5, 0.5], [0, -0.5, 0.5]], dtype=float)
    joints = np.vstack([[0.0, 0.0, 0.0], directions])
    names = role_names(joints, [-1] + [0] * 6, [-1] * 7)
    assert names == ("root", "spine", "tail", "chain", "chain_2", "chain_3", "chain_4")


def test_mirrored_chains_of_length_one_and_coincident_joints():
    skeleton = Builder()
    root = skeleton.add([0, 0, 0.5])
    for k in range(4):
        skeleton.add_pair([0.1 + 0.05 * k, 0.0, 0.5], root)
    skeleton.add_pair([0.0, 0.0, 0.5], root)  # twins at the same place: the lower index is the left one
    names = skeleton.names()
    assert names == ("root", "limb.L", "limb.R", "limb_2.L", "limb_2.R", "limb_3.L", "limb_3.R", "limb_4.L", "limb_4.R",
                     "limb_5.L", "limb_5.R")


@pytest.mark.parametrize("joints,parents,mirror,message", [
    (np.zeros((2, 2)), [-1, 0], [-1, -1], r"non-empty \(j, 3\) array"),
    (np.zeros((0, 3)), [], [], r"non-empty \(j, 3\) array"),
    ([[0, 0, 0], [0, 0, np.nan]], [-1, 0], [-1, -1], "finite"),
    (np.zeros((2, 3)), [-1, -1], [-1, -1], "exactly one root"),
    (np.zeros((3, 3)), [-1, 2, 0], [-1, -1, -1], "before their children"),
    (np.zeros((2, 3)), [-1, 0, 0], [-1, -1], r"\(2,\) integer array"),
    (np.zeros((2, 3)), [-1, 0.5], [-1, -1], "whole joint indices"),
    (np.zeros((2, 3)), [-1, 0], [-1, 5], "from -1 to 1"),
    (np.zeros((3, 3)), [-1, 0, 0], [-1, 2, -1], "pairs"),
    (np.zeros((2, 3)), [-1, 0], [-1, 1], "pairs"),
    ("joints", [-1], [-1], r"non-empty \(j, 3\) array"),
])
def test_malformed_arrays_are_refused(joints, parents, mirror, message):
    with pytest.raises(InputError, match=message):
        role_names(joints, parents, mirror)


def test_legs_hanging_from_a_root_on_the_floor():
    # As many glTF rigs have it: the root on the floor carries the hips and the legs.
    skeleton = Builder()
    root = skeleton.add([0, 0, 0])
    hips = skeleton.add([0, 0, 0.5], root)
    chest = skeleton.add([0, 0, 0.75], hips)
    head = skeleton.add([0, 0, 0.9], chest)
    legs = skeleton.add_pair_chain([(0.1, 0, 0.5), (0.1, 0, 0.27), (0.1, 0, 0.04)], root)
    arms = skeleton.add_pair_chain([(0.15, 0, 0.8), (0.32, 0, 0.8), (0.48, 0, 0.8)], chest)
    controls = skeleton.add_pair([0.1, 0.0, 0.0], root)  # an IK control lying on the floor is no leg
    names = skeleton.names()
    assert skeleton.kind() == BIPED
    assert [names[k] for k in (root, hips, chest, head)] == ["root", "spine", "spine.001", "head"]
    assert [names[left] for left, _ in legs] == ["thigh.L", "shin.L", "foot.L"]
    assert [names[right] for _, right in arms] == ["upper_arm.R", "forearm.R", "hand.R"]
    assert [names[k] for k in controls] == ["limb.L", "limb.R"]


def test_predicted_quadruped_with_a_branch_at_the_shoulders_and_hips_off_the_trunk():
    # As the predictor gives them: the root mid-body, the hind legs hanging
    # from a joint just behind it (their chains start far back), and a short
    # pair of branches at the shoulders beside the front legs.
    skeleton = Builder()
    root = skeleton.add([0, -0.2, 0.6])
    hips = skeleton.add([0, -0.3, 0.5], root)
    chest = skeleton.add([0, -0.4, 0.6], root)
    neck = skeleton.add([0, -0.5, 0.75], chest)
    head = skeleton.add([0, -0.6, 0.8], neck)
    tail = skeleton.add([0, 0.5, 0.6], root)
    front = skeleton.add_pair_chain([(0.1, -0.4, 0.5), (0.1, -0.4, 0.25), (0.1, -0.42, 0.02)], chest)
    hind = skeleton.add_pair_chain([(0.1, 0.35, 0.5), (0.1, 0.4, 0.25), (0.1, 0.35, 0.02)], hips)
    branch = skeleton.add_pair([0.12, -0.45, 0.65], chest)
    names = skeleton.names()
    assert skeleton.kind() == QUADRUPED
    assert [names[k] for k in (hips, root, chest, neck, head, tail)] == [
        "spine", "spine.001", "spine.002", "neck", "head", "tail"]
    assert [names[left] for left, _ in front] == ["front_thigh.L", "front_shin.L", "front_foot.L"]
    assert [names[right] for _, right in hind] == ["thigh.R", "shin.R", "foot.R"]
    assert [names[k] for k in branch] == ["limb.L", "limb.R"]


def test_predicted_biped_with_its_root_above_the_hips():
    # The predictor's root may be a belly joint the hips hang below and the spine rises from.
    skeleton = Builder()
    root = skeleton.add([0, 0, 0.6])
    hips = skeleton.add([0, 0, 0.5], root)
    chest = skeleton.add([0, 0, 0.75], root)
    head = skeleton.add([0, 0, 0.9], chest)
    legs = skeleton.add_pair_chain([(0.1, 0, 0.5), (0.1, 0, 0.27), (0.1, 0, 0.04)], hips)
    arms = skeleton.add_pair_chain([(0.15, 0, 0.8), (0.32, 0, 0.8), (0.48, 0, 0.8)], chest)
    names = skeleton.names()
    assert skeleton.kind() == BIPED
    assert [names[k] for k in (hips, root, chest, head)] == ["spine", "spine.001", "spine.002", "head"]
    assert [names[left] for left, _ in legs] == ["thigh.L", "shin.L", "foot.L"]
    assert [names[right] for _, right in arms] == ["upper_arm.R", "forearm.R", "hand.R"]
