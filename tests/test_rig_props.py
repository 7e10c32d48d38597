"""Rigid props of their own in Predict Skeleton, Auto-Rig and the ``rig``
command (``core.rigging.props`` through ``blender.jobs.rig``): a sword held
in the procedural biped's right hand gets no bones and is bound wholly to
the hand; a helmet and a bracer lying on the body are skinned as before.
Built as a user builds them, with real bpy."""

import json
import re
from itertools import combinations

import bpy
import numpy as np
import pytest

from autorig_addon.blender import convert, scene_io
from autorig_addon.blender.armature_builder import build_armature
from autorig_addon.blender.jobs.rig import (
    HANDS_READING_LABEL,
    HANDS_READING_SHARE,
    plan_rig_steps,
    planned_rig_steps,
    run_steps,
)
from autorig_addon.blender.jobs.skin import SkinSettings
from autorig_addon.cli.main import main
from autorig_addon.core.errors import Cancelled
from autorig_addon.core.geometry.normals import vertex_normals
from autorig_addon.core.geometry.segments import point_segment_distances
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.held_at_hands import hand_candidates
from blender_fixtures import (
    BIPED_SEED,
    add_biped,
    armatures,
    bind,
    evaluated_world_vertices,
    group_weights,
    local_positions,
    make_armature,
    mesh_object,
    parent_to_bone,
    pose_bone_turned,
    scene_state,
    select_only,
)
from geometry_fixtures import box_mesh, procedural_biped_with

pytestmark = pytest.mark.all_blenders

# The biped (blender_fixtures.add_biped): 0.94 tall, facing -Y, arms out and down; its right hand near x -0.28, z 0.57.
#: The sword: a blade 1.6 cm square from its pommel 3 cm behind the right hand to its tip 0.5 forward.
SWORD_LOW, SWORD_HIGH = (-0.286, -0.5, 0.565), (-0.27, 0.03, 0.581)
#: Where the sword passes through the right hand.
GRIP = np.array([-0.278, -0.01, 0.573])
#: The holding bone passes this close to the grip (the hand is about 4 cm across).
GRIP_DISTANCE = 0.03
#: Sword vertices this far before the hand are its blade: no bone may come this close to them.
BLADE_CLEARANCE = 0.1


def add_sword():
    blade = box_mesh(SWORD_LOW, SWORD_HIGH, 0.02)
    obj = mesh_object("Sword", blade.vertices, blade.triangles)
    bpy.context.view_layer.update()
    return obj


def add_shell(name, rows_of):
    """A garment as a user makes one: the body's faces whose corners all
    pass ``rows_of(vertices)`` duplicated and pushed 1 cm out along the
    normals (Shift+D, P, Alt+S)."""
    mesh = generate_character(BIPED_SEED, "biped").mesh
    normals = vertex_normals(mesh.vertices, mesh.triangles)
    chosen = rows_of(mesh.vertices)
    kept = mesh.triangles[chosen[mesh.triangles].all(axis=1)]
    used, triangles = np.unique(kept, return_inverse=True)
    obj = mesh_object(name, mesh.vertices[used] + 0.01 * normals[used], triangles.reshape(-1, 3))
    bpy.context.view_layer.update()
    return obj


def blade_vertices(sword) -> np.ndarray:
    world = evaluated_world_vertices(sword)
    return world[world[:, 1] < GRIP[1] - BLADE_CLEARANCE]


def pairwise_distances(points) -> np.ndarray:
    return np.array([np.linalg.norm(a - b) for a, b in combinations(points, 2)])


def assert_no_bone_near_the_blade(armature, sword):
    skeleton = convert.read_skeleton(armature)
    blade = blade_vertices(sword)
    distances = point_segment_distances(blade, skeleton.joints, skeleton.tails)
    assert distances.min() > BLADE_CLEARANCE - 0.05


def turn_fk_hand(rig, degrees: float) -> None:
    """Turn Rigify's FK hand control of the right arm (its deform bone follows it), the arm switched to FK."""
    rig.pose.bones["upper_arm_parent.R"]["IK_FK"] = 1.0
    pose_bone_turned(rig, "hand_fk.R", degrees)


def assert_bound_wholly_to(sword, armature, bone: str, turn=None):
    """Every sword vertex weighs exactly 1 on ``bone`` and nothing else, and
    posing that bone by 30 degrees (``turn(armature, degrees)``, by default
    turning the pose bone itself) moves the sword without bending it."""
    skeleton = convert.read_skeleton(armature)
    weights = group_weights(sword, skeleton.names)
    column = skeleton.names.index(bone)
    assert np.array_equal(weights[:, column], np.ones(len(sword.data.vertices)))
    assert not np.delete(weights, column, axis=1).any()
    modifiers = [modifier for modifier in sword.modifiers if modifier.type == "ARMATURE"]
    assert len(modifiers) == 1 and modifiers[0].object == armature and sword.parent == armature
    head, tail = skeleton.joints[column], skeleton.tails[column]
    assert point_segment_distances(GRIP[None], head[None], tail[None])[0, 0] < GRIP_DISTANCE
    rest = evaluated_world_vertices(sword)
    if turn is None:
        pose_bone_turned(armature, bone, 30.0)
    else:
        turn(armature, 30.0)
    posed = evaluated_world_vertices(sword)
    assert np.linalg.norm(posed - rest, axis=1).max() > 0.05
    np.testing.assert_allclose(pairwise_distances(posed), pairwise_distances(rest), atol=1e-5)


def test_auto_rig_gives_a_held_sword_no_bones_and_binds_it_wholly_to_the_hand(clean_scene, capfd):
    """Before, the sword was read as part of the body and skinned smoothly
    over the arm's bones, so posing the hand bent its blade."""
    body = add_biped()
    select_only([body], active=body)
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    (alone,) = armatures()
    bones_alone = [bone.name for bone in alone.data.bones]
    bpy.data.objects.remove(alone)
    sword = add_sword()
    select_only([body, sword], active=sword)

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    assert armature.name == "Biped_rig"
    assert [bone.name for bone in armature.data.bones] == bones_alone
    assert_no_bone_near_the_blade(armature, sword)
    skeleton = convert.read_skeleton(armature)
    np.testing.assert_allclose(group_weights(body, skeleton.names).sum(axis=1), 1.0, atol=1e-5)
    assert "'Sword' held: bound wholly to bone 'hand.R' (a rigid prop, left out of the skeleton)" \
        in capfd.readouterr().out
    assert_bound_wholly_to(sword, armature, "hand.R")


def test_predict_skeleton_leaves_a_held_sword_out_and_untouched(clean_scene, capfd):
    body, sword = add_biped(), add_sword()
    select_only([body, sword], active=body)
    before = scene_state([sword])
    before.pop("objects")

    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}

    (armature,) = armatures()
    assert_no_bone_near_the_blade(armature, sword)
    after = scene_state([sword])
    after.pop("objects")
    assert after == before
    assert "'Sword' is held: a rigid prop, left out of the skeleton" in capfd.readouterr().out


def rig_saved_scene(tmp_path, capsys, name: str, option: str) -> dict:
    """Save the scene as ``name``.blend, run ``rig`` on it with ``option`` into
    ``tmp_path/out``, check it exits 0, and return its one summary item."""
    source = tmp_path / f"{name}.blend"
    scene_io.save_scene(source)
    capsys.readouterr()
    code = main(["rig", str(source), "--out", str(tmp_path / "out"), option, "--quiet"])
    assert code == 0
    (item,) = json.loads(capsys.readouterr().out)["succeeded"]
    return item


def bones_of_the_biped_alone() -> tuple[list, np.ndarray]:
    """The bone names and joints Predict Skeleton gives the biped with nothing else in the scene (removed after)."""
    alone = add_biped("Alone")
    select_only([alone], active=alone)
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    (armature,) = armatures()
    names, joints = [bone.name for bone in armature.data.bones], convert.read_skeleton(armature).joints
    for obj in (armature, alone):
        bpy.data.objects.remove(obj)
    return names, joints


def add_body_with_a_sword_in_each_hand_on_a_rig() -> tuple:
    """KayKit's knight with its off-hand sword: the biped skinned to the file's
    rig, the sword on its right hand's bone and its mirror image on the left's."""
    body, sword = add_biped(), add_sword()
    blade = box_mesh(SWORD_LOW, SWORD_HIGH, 0.02)
    offhand = mesh_object("Sword_Offhand", blade.vertices * [-1.0, 1.0, 1.0], blade.triangles[:, ::-1])
    bpy.context.view_layer.update()
    old_rig = build_armature(generate_character(BIPED_SEED, "biped").skeleton, "Rig", bpy.context)
    bind(body, old_rig)
    parent_to_bone(sword, old_rig, "hand.R")
    parent_to_bone(offhand, old_rig, "hand.L")
    return body, sword, offhand


def assert_wholly_on(obj, armature, bone: str) -> None:
    """Every vertex of ``obj`` weighs exactly 1 on ``bone``."""
    skeleton = convert.read_skeleton(armature)
    weights = group_weights(obj, skeleton.names)
    assert np.array_equal(weights[:, skeleton.names.index(bone)], np.ones(len(weights)))


def add_body_holding_a_joined_sword():
    """The biped with the sword joined into its mesh (selected both, Ctrl+J): one object."""
    character = generate_character(BIPED_SEED, "biped").mesh
    blade = box_mesh(SWORD_LOW, SWORD_HIGH, 0.02)
    obj = mesh_object("Biped", np.vstack([character.vertices, blade.vertices]),
                      np.vstack([character.triangles, blade.triangles + character.vertex_count]))
    bpy.context.view_layer.update()
    return obj, character.vertex_count


def test_a_sword_joined_into_the_body_gets_no_bones_and_is_weighted_wholly_to_the_hand(clean_scene, capfd):
    """The sword is a loose piece of the body's mesh: left out of the
    skeleton (the same bones as the biped alone, none near the blade) and
    weighted wholly to the hand holding it, so posing the hand moves it
    without bending it. Before, it was skinned as body: 3 of its 232
    vertices mostly on the forearm, some only 54 % on the hand, and a 30
    degree hand turn bent it by 7 mm."""
    bones_alone, joints_alone = bones_of_the_biped_alone()
    body, sword_start = add_body_holding_a_joined_sword()
    select_only([body], active=body)

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    skeleton = convert.read_skeleton(armature)
    assert [bone.name for bone in armature.data.bones] == bones_alone
    np.testing.assert_allclose(skeleton.joints, joints_alone, atol=1e-6)
    assert "'Biped': a loose piece of 232 vertices held: bound wholly to bone 'hand.R' (a rigid prop, left out " \
        "of the skeleton)" in capfd.readouterr().out
    weights = group_weights(body, skeleton.names)
    hand = skeleton.names.index("hand.R")
    assert np.array_equal(weights[sword_start:, hand], np.ones(len(weights) - sword_start))
    assert not np.delete(weights[sword_start:], hand, axis=1).any()
    np.testing.assert_allclose(weights[:sword_start].sum(axis=1), 1.0, atol=1e-5)
    rest = evaluated_world_vertices(body)[sword_start:]
    pose_bone_turned(armature, "hand.R", 30.0)
    posed = evaluated_world_vertices(body)[sword_start:]
    assert np.linalg.norm(posed - rest, axis=1).max() > 0.05
    np.testing.assert_allclose(pairwise_distances(posed), pairwise_distances(rest), atol=1e-5)


def test_predict_skeleton_leaves_a_joined_sword_out_and_the_mesh_untouched(clean_scene, capfd):
    body, _ = add_body_holding_a_joined_sword()
    select_only([body], active=body)
    before = scene_state([body])
    before.pop("objects")

    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}

    (armature,) = armatures()
    skeleton = convert.read_skeleton(armature)
    blade = local_positions(body)[-232:]
    blade = blade[blade[:, 1] < GRIP[1] - BLADE_CLEARANCE]
    assert point_segment_distances(blade, skeleton.joints, skeleton.tails).min() > BLADE_CLEARANCE - 0.05
    after = scene_state([body])
    after.pop("objects")
    assert after == before
    assert "'Biped': a loose piece of 232 vertices is held: a rigid prop, left out of the skeleton" \
        in capfd.readouterr().out


def test_a_helmet_and_a_bracer_on_one_arm_are_skinned_not_held(clean_scene, capfd):
    """A helmet has a twin of itself across the mirror plane; a bracer on the
    right forearm (from just past the elbow) has none but lies on the body: both are skinned as the
    body is, through vertex groups, not held by one bone. The bracer, one
    piece weighted mostly to the forearm, is then bound wholly to it (a
    rigid loose part); without rigid parts it spreads over several bones."""
    body = add_biped()
    helmet = add_shell("Helmet", lambda vertices: vertices[:, 2] > 0.86)
    bracer = add_shell("Bracer", lambda vertices: (vertices[:, 0] < -0.165) & (vertices[:, 0] > -0.235))
    select_only([body, helmet, bracer], active=body)

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    skeleton = convert.read_skeleton(armature)
    assert "held" not in capfd.readouterr().out
    for garment in (helmet, bracer):
        weights = group_weights(garment, skeleton.names)
        np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-5)
        assert garment.parent == armature
    bracer_weights = group_weights(bracer, skeleton.names)
    np.testing.assert_allclose(bracer_weights[:, skeleton.names.index("forearm.R")], 1.0, atol=1e-6)

    # Skinned again with the body, rigid parts off.
    select_only([armature, body, helmet, bracer], active=armature)
    assert bpy.ops.autorig.skin_weights(skin_rigid_parts=False) == {"FINISHED"}
    bracer_bones = group_weights(bracer, skeleton.names).max(axis=0) > 0.1
    assert bracer_bones.sum() >= 2 and bracer_bones[skeleton.names.index("forearm.R")]


def test_the_rig_command_with_rigify_binds_the_sword_to_the_def_hand(clean_scene, tmp_path, capsys):
    """Every mesh of the file is taken; the sword goes to the generated
    rig's deform bone of the hand."""
    add_biped(), add_sword()
    item = rig_saved_scene(tmp_path, capsys, "knight", "--rigify")
    assert item["meshes"] == ["Biped"] and item["rigify"]
    assert "'Sword' held: bound wholly to bone 'DEF-hand.R' (a rigid prop, left out of the skeleton)" \
        in item["notes"]
    scene_io.load_scene(tmp_path / "out" / "knight.blend")
    armature, sword = bpy.data.objects[item["armature"]], bpy.data.objects["Sword"]
    assert_no_bone_near_the_blade(armature, sword)
    assert_bound_wholly_to(sword, armature, "DEF-hand.R", turn_fk_hand)


def test_the_rig_command_replacing_a_posed_rig_takes_the_sword_from_its_bone_where_it_is_at_rest(
        clean_scene, tmp_path, capsys):
    """KayKit's way: the file's armature posed (the right arm lowered), the
    sword parented to the hand's bone. ``--replace`` unbinds the body, which
    takes its rest shape, so the sword is taken off its bone where it is at
    rest: in the rest hand, bound to the new hand bone. Before, it stayed
    where the pose held it, 0.14 from the body at rest, and was left out as
    a prop nothing holds."""
    character = generate_character(BIPED_SEED, "biped")
    body, sword = add_biped(), add_sword()
    old_rig = build_armature(character.skeleton, "Rig", bpy.context)
    bind(body, old_rig)
    parent_to_bone(sword, old_rig, "hand.R")
    pose_bone_turned(old_rig, "upper_arm.R", 60.0)
    assert np.abs(evaluated_world_vertices(sword) - box_mesh(SWORD_LOW, SWORD_HIGH, 0.02).vertices).max() > 0.2
    item = rig_saved_scene(tmp_path, capsys, "posed", "--replace")
    assert item["meshes"] == ["Biped"] and item["replaced"] == ["Rig"]
    assert "'Sword' held: bound wholly to bone 'hand.R' (a rigid prop, left out of the skeleton)" in item["notes"]
    scene_io.load_scene(tmp_path / "out" / "posed.blend")
    armature, sword = bpy.data.objects[item["armature"]], bpy.data.objects["Sword"]
    np.testing.assert_allclose(evaluated_world_vertices(sword), box_mesh(SWORD_LOW, SWORD_HIGH, 0.02).vertices,
                               atol=1e-5)
    assert_bound_wholly_to(sword, armature, "hand.R")


def test_the_rig_command_replacing_a_rig_takes_a_sword_in_each_hand_off_the_hand_bones_as_props(
        clean_scene, tmp_path, capsys):
    """A sword in each hand, mirrored, each parented to its hand's bone of
    the file's rig, the body skinned to it (KayKit's knight with its off-hand
    sword). Each is the other's twin, so their shapes do not tell them from
    the body; the rig carrying them on its hand bones does: ``--replace``
    leaves both out of the skeleton (the bones of the biped alone) and binds
    each wholly to its hand. Before, both were skinned with the body, as part
    of it."""
    bones_alone = bones_of_the_biped_alone()[0]
    add_body_with_a_sword_in_each_hand_on_a_rig()
    item = rig_saved_scene(tmp_path, capsys, "two_swords", "--replace")
    assert item["meshes"] == ["Biped"] and item["template"] == "biped"
    for name, bone in (("Sword", "hand.R"), ("Sword_Offhand", "hand.L")):
        assert f"'{name}' held: bound wholly to bone '{bone}' (a rigid prop, left out of the skeleton)" \
            in item["notes"]
    scene_io.load_scene(tmp_path / "out" / "two_swords.blend")
    armature = bpy.data.objects[item["armature"]]
    assert [bone.name for bone in armature.data.bones] == bones_alone
    assert_bound_wholly_to(bpy.data.objects["Sword"], armature, "hand.R")
    assert_wholly_on(bpy.data.objects["Sword_Offhand"], armature, "hand.L")


def test_auto_rig_replacing_a_rig_takes_a_sword_in_each_hand_off_the_hand_bones_as_props(clean_scene, capfd):
    """The same in the panel: the body bound to the file's rig, a mirrored
    sword on each hand's bone, all three selected, Auto-Rig with *Replace
    Binding*: the rig being replaced says what it carried, so both swords
    are held props bound wholly to the new hands; the old rig goes (nothing
    follows it any more)."""
    body, sword, offhand = add_body_with_a_sword_in_each_hand_on_a_rig()
    select_only([body, sword, offhand], active=body)

    assert bpy.ops.autorig.auto_rig(rig_replace=True) == {"FINISHED"}

    (armature,) = armatures()
    assert armature.name == "Biped_rig"
    out = capfd.readouterr().out
    for name, bone in (("Sword", "hand.R"), ("Sword_Offhand", "hand.L")):
        assert f"'{name}' held: bound wholly to bone '{bone}' (a rigid prop, left out of the skeleton)" in out
    assert_bound_wholly_to(sword, armature, "hand.R")
    assert_wholly_on(offhand, armature, "hand.L")


def test_auto_rig_replacing_a_posed_rig_takes_the_swords_where_they_are_at_rest(clean_scene):
    """The old rig posed in the scene (the right forearm turned 60 degrees,
    carrying the sword 0.34 m away): the body is rigged at rest, and so is
    the sword, bound to the new right hand where the old rig's rest put it.
    Before, unbinding kept the sword where the pose held it, so at the new
    rig's rest it floated 0.34 m from the hand."""
    body, sword, offhand = add_body_with_a_sword_in_each_hand_on_a_rig()
    sword_at_rest = evaluated_world_vertices(sword)
    pose_bone_turned(bpy.data.objects["Rig"], "forearm.R", 60.0)
    assert np.abs(evaluated_world_vertices(sword) - sword_at_rest).max() > 0.3
    select_only([body, sword, offhand], active=body)

    assert bpy.ops.autorig.auto_rig(rig_replace=True) == {"FINISHED"}

    (armature,) = armatures()
    assert armature.data.pose_position == "POSE"
    for pose_bone in armature.pose.bones:
        assert tuple(pose_bone.rotation_quaternion) == (1.0, 0.0, 0.0, 0.0)
    np.testing.assert_allclose(evaluated_world_vertices(sword), sword_at_rest, atol=1e-5)
    assert_bound_wholly_to(sword, armature, "hand.R")


def add_mirrored_swords():
    """The sword in the right hand and its mirror image in the left, objects of their own, no rig."""
    sword = add_sword()
    blade = box_mesh(SWORD_LOW, SWORD_HIGH, 0.02)
    offhand = mesh_object("Sword_Offhand", blade.vertices * [-1.0, 1.0, 1.0], blade.triangles[:, ::-1])
    bpy.context.view_layer.update()
    return sword, offhand


def auto_rigged_with_mirrored_swords(readings: list | None = None) -> tuple:
    """Auto-Rig on the biped holding a sword in each hand (objects of their own, no rig), checked to give the
    bones of the biped alone: (armature, body, sword, offhand). ``readings`` (:func:`counted_readings`) is
    cleared after the biped alone is read, so it counts Auto-Rig's readings only."""
    names_alone, _ = bones_of_the_biped_alone()
    if readings is not None:
        readings.clear()
    body = add_biped()
    sword, offhand = add_mirrored_swords()
    select_only([body, sword, offhand], active=body)
    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}
    (armature,) = armatures()
    assert [bone.name for bone in armature.data.bones] == names_alone
    return armature, body, sword, offhand


def test_auto_rig_binds_a_sword_in_each_hand_wholly_to_its_hand_without_a_rig(clean_scene, capfd):
    """A mirrored pair has a twin each, so props.py kept them as body: the
    hands' bones ran along the blades (5 mm from them) and each blade was
    skinned over the hand and the forearm. Thin, sticking out and touching
    the body only where the landmark network puts its wrists, they are now
    held props (core.rigging.held_at_hands)."""
    armature, _, sword, offhand = auto_rigged_with_mirrored_swords()

    out = capfd.readouterr().out
    for obj, bone in ((sword, "hand.R"), (offhand, "hand.L")):
        assert f"'{obj.name}' held: bound wholly to bone '{bone}' (a rigid prop, left out of the skeleton)" in out
        assert_no_bone_near_the_blade(armature, obj)
    assert_bound_wholly_to(sword, armature, "hand.R")
    assert_wholly_on(offhand, armature, "hand.L")


#: A mug (a box 6 cm across and 8 cm tall) held in front of the right hand, its mirror image in the left.
MUG_LOW, MUG_HIGH = (-0.33, -0.06, 0.50), (-0.27, 0.0, 0.58)


def add_mirrored_mugs() -> list:
    """A mug in each hand (MUG_LOW, MUG_HIGH and its mirror image), objects of their own."""
    right = box_mesh(np.array(MUG_LOW), np.array(MUG_HIGH), 0.01)
    mugs = [mesh_object("Mug", right.vertices, right.triangles),
            mesh_object("Mug.L", right.vertices * [-1.0, 1.0, 1.0], right.triangles[:, ::-1])]
    bpy.context.view_layer.update()
    return mugs


def test_auto_rig_binds_a_mug_in_each_hand_wholly_to_its_hand(clean_scene, capfd):
    """A mug in each hand, mirror images: not thin, so before they stayed
    part of the body (a twin each) and were skinned over the hand and the
    forearm. Small, sticking out and touching the body in a hand of its own
    (core.rigging.held_at_hands.thick_candidates), each is now a held prop:
    no bones of its own, bound wholly to its hand, posing the hand moves it
    without bending it."""
    names_alone, _ = bones_of_the_biped_alone()
    body = add_biped()
    mugs = add_mirrored_mugs()
    select_only([body, *mugs], active=body)

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    assert [bone.name for bone in armature.data.bones] == names_alone
    out = capfd.readouterr().out
    for mug, bone in zip(mugs, ("hand.R", "hand.L")):
        assert f"'{mug.name}' held: bound wholly to bone '{bone}' (a rigid prop, left out of the skeleton)" in out
        assert_wholly_on(mug, armature, bone)
    assert_bound_wholly_to(mugs[0], armature, "hand.R")


def counted_readings(monkeypatch) -> list:
    """The vertex count of every body the prediction reads from now on (Auto-Rig's and held_at_hands' calls)."""
    from autorig_addon.blender.jobs import rig as rig_job
    from autorig_addon.core.rigging import held_at_hands

    readings = []
    for module in (rig_job, held_at_hands):
        counted = module.predict_votes
        monkeypatch.setattr(module, "predict_votes", lambda mesh, *args, counted=counted: (
            readings.append(mesh.vertex_count), counted(mesh, *args))[1])
    return readings


def test_the_body_read_to_tell_the_swords_is_not_read_again(clean_scene, monkeypatch):
    """Telling the swords held reads the body without them; that is the body
    rigged, so Auto-Rig uses that reading instead of a second prediction pass
    (the skeleton the same as read afresh)."""
    readings = counted_readings(monkeypatch)

    _, body, _, _ = auto_rigged_with_mirrored_swords(readings)

    assert readings == [len(body.data.vertices)]  # one reading, of the body alone


def test_planning_reads_the_body_for_the_swords_in_a_task_of_its_own(clean_scene, monkeypatch):
    """Planning only reads Blender's objects; the landmark network reading
    the body to tell the swords held is a task of the steps, which the
    operators run in their worker (progress, Esc) like the prediction:
    before, it ran while the operator started, without either."""
    readings = counted_readings(monkeypatch)
    body = add_biped()
    sword, offhand = add_mirrored_swords()
    steps = plan_rig_steps([body, sword, offhand], bpy.context.evaluated_depsgraph_get(), "Biped",
                           skin=SkinSettings())

    task = next(steps)
    assert readings == []  # nothing read yet: the reading is the task
    reported = []
    answer = task(lambda fraction, message: reported.append((fraction, message)))
    assert readings == [len(body.data.vertices)]
    assert reported and all(message.startswith(f"{HANDS_READING_LABEL}: ") for _, message in reported)
    fractions = [fraction for fraction, _ in reported]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    with pytest.raises(StopIteration) as stop:
        steps.send(answer)
    plan = stop.value.value
    assert [obj.name for obj, _ in plan.held] == [sword.name, offhand.name]
    assert plan.meshes == [body]


def test_esc_while_the_hands_are_read_stops_the_run_with_the_scene_as_it_was(clean_scene):
    """Esc during that reading: the worker's progress callback raises Cancelled inside the landmark network's
    reading (as the operators' worker does at its next report); the run stops there, nothing is built and
    the scene is as it was."""
    body = add_biped()
    sword, offhand = add_mirrored_swords()
    before = scene_state([body, sword, offhand])
    reported = []

    def escape(fraction, message):
        reported.append(message)
        if message.startswith(HANDS_READING_LABEL) and "network" in message:
            raise Cancelled()

    steps = planned_rig_steps(bpy.context, plan_rig_steps([body, sword, offhand],
                                                          bpy.context.evaluated_depsgraph_get(), "Biped",
                                                          skin=SkinSettings()))
    with pytest.raises(Cancelled):
        run_steps(steps, escape)
    assert any("network" in message for message in reported)
    assert armatures() == []
    assert scene_state([body, sword, offhand]) == before


@pytest.mark.parametrize("held", ["swords", "mugs"])
def test_a_run_that_reads_the_hands_fills_one_progress_bar(clean_scene, monkeypatch, held):
    """Reading what the hands hold, then rigging and binding: the bar fills once, never starting again from
    empty. The reading takes the first HANDS_READING_SHARE of it, labelled; the rig's prediction and skin
    the rest. With swords the rig uses that reading; held mugs leave another body to read (the bar went
    0 to 1 twice before)."""
    readings = counted_readings(monkeypatch)
    body = add_biped()
    objects = [body, *(add_mirrored_swords() if held == "swords" else add_mirrored_mugs())]
    reported = []
    steps = planned_rig_steps(bpy.context, plan_rig_steps(objects, bpy.context.evaluated_depsgraph_get(), "Biped",
                                                          skin=SkinSettings()))
    run_steps(steps, lambda fraction, message: reported.append((fraction, message)))

    assert len(readings) == (1 if held == "swords" else 2)
    fractions = [fraction for fraction, _ in reported]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    reading = [fraction for fraction, message in reported if message.startswith(HANDS_READING_LABEL)]
    assert reading and max(reading) == pytest.approx(HANDS_READING_SHARE)
    rest = [fraction for fraction, message in reported if not message.startswith(HANDS_READING_LABEL)]
    assert rest and min(rest) >= HANDS_READING_SHARE


def test_a_held_sword_already_bound_is_refused_before_the_hands_are_read(clean_scene, monkeypatch):
    """Auto-Rig binds what the hands hold with the body, so a sword already bound to another armature is
    refused (naming it), and before the slow reading that tells it held: no body is read."""
    readings = counted_readings(monkeypatch)
    body = add_biped()
    sword, offhand = add_mirrored_swords()
    old = make_armature("Old")
    modifier = sword.modifiers.new("Armature", "ARMATURE")
    modifier.object = old
    select_only([body, sword, offhand], active=body)
    before = scene_state([body, sword, offhand, old])

    with pytest.raises(RuntimeError, match=re.escape(
            "'Sword' is already bound to the armature 'Old': turn on Replace Binding")):
        bpy.ops.autorig.auto_rig()
    assert readings == []
    assert scene_state([body, sword, offhand, old]) == before


def test_a_character_of_several_objects_holding_nothing_reads_no_body_to_tell_it(clean_scene, monkeypatch):
    """A body and a ground plane under it: planning's task finds no candidate and reads no body."""
    readings = counted_readings(monkeypatch)
    body = add_biped()
    ground = box_mesh((-1.0, -1.0, -0.01), (1.0, 1.0, 0.0), 0.5)
    plane = mesh_object("Ground", ground.vertices, ground.triangles)
    bpy.context.view_layer.update()
    steps = plan_rig_steps([body, plane], bpy.context.evaluated_depsgraph_get(), "Biped")

    task = next(steps)
    assert task(None) == ((), None)
    assert readings == []


def test_a_single_mesh_is_planned_without_a_task(clean_scene, monkeypatch):
    """A character of one object has nothing of its own to hold: planning yields no task and reads no body."""
    readings = counted_readings(monkeypatch)
    body = add_biped()

    with pytest.raises(StopIteration) as stop:
        next(plan_rig_steps([body], bpy.context.evaluated_depsgraph_get(), "Biped"))
    assert stop.value.value.meshes == [body]
    assert readings == []


def test_a_body_with_a_small_thick_part_of_its_own_is_read_once(clean_scene, monkeypatch):
    """A top hat (a box 10 cm across, 17 cm tall) on the head is a thick candidate
    (core.rigging.held_at_hands.thick_candidates): it stays in the body read to tell what the hands hold,
    is not held, and that reading is the body rigged: one reading, the hat skinned to the head."""
    readings = counted_readings(monkeypatch)
    body = add_biped()
    box = box_mesh((-0.05, -0.05, 0.95), (0.05, 0.05, 1.12), 0.01)
    assert [(candidate.object_index, candidate.thin) for candidate in
            hand_candidates(procedural_biped_with(("Hat", box)))] == [(1, False)]
    hat = mesh_object("Hat", box.vertices, box.triangles)
    bpy.context.view_layer.update()
    select_only([body, hat], active=body)

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    assert readings == [len(body.data.vertices) + len(hat.data.vertices)]
    (armature,) = armatures()
    skeleton = convert.read_skeleton(armature)
    assert group_weights(hat, skeleton.names)[:, skeleton.names.index("head")].mean() > 0.9


def biped_with_flat_ears() -> tuple:
    """(body, [left ear, right ear]) selected: two flat ears standing on the
    biped's head (a rabbit's, 17 cm tall, 2 cm thick), mirror images."""
    body = add_biped()
    ears = []
    for name, side in (("Ear.L", 1.0), ("Ear.R", -1.0)):
        ear = box_mesh((0.03, -0.01, 0.98), (0.07, 0.01, 1.15), 0.02)
        triangles = ear.triangles if side > 0 else ear.triangles[:, ::-1]
        ears.append(mesh_object(name, ear.vertices * [side, 1.0, 1.0], triangles))
    bpy.context.view_layer.update()
    select_only([body, *ears], active=body)
    return body, ears


def test_a_body_rigged_with_thin_parts_told_its_own_is_read_again(clean_scene, monkeypatch):
    """Ears that stay the body's (test below) were left out of the body read
    to tell them: the body rigged differs from it, so it is read afresh."""
    readings = counted_readings(monkeypatch)
    body, ears = biped_with_flat_ears()

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    ear_vertices = sum(len(ear.data.vertices) for ear in ears)
    assert readings == [len(body.data.vertices), len(body.data.vertices) + ear_vertices]


def test_thin_twins_touching_the_head_are_skinned_with_the_body(clean_scene, capfd):
    """Two flat ears standing on the head (a rabbit's, 17 cm tall, 2 cm
    thick), mirror images, thin and sticking out as the swords are: they
    touch the body far from its wrists, so they stay part of the body and are
    skinned with it."""
    body, ears = biped_with_flat_ears()

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    assert "held" not in capfd.readouterr().out
    skeleton = convert.read_skeleton(armature)
    for ear in ears:
        weights = group_weights(ear, skeleton.names)
        np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-5)
        assert weights[:, skeleton.names.index("head")].mean() > 0.5
