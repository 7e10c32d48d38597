"""Standard skeletons as an animator uses them: Rigify's control rig generated, bound and posed; engine bone
names given, renamed and driven by an animation keyed on them."""

import bpy
import numpy as np
import pytest
from mathutils import Euler, Matrix, Vector

from autorig_addon.blender import convert
from autorig_addon.blender.armature_builder import build_armature
from autorig_addon.blender.jobs.rig import RigSettings, plan_rig, rig_steps, run_steps
from autorig_addon.blender.jobs.skin import SkinSettings
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.predict import predict_votes, skeleton_from_votes
from autorig_addon.core.skinning.options import SkinningOptions
from autorig_addon.core.types import Skeleton
from blender_fixtures import evaluated_world_vertices, mesh_object, select_only

#: The procedural biped of the rig tests (1.0 tall, arms out, facing -Y).
BIPED_SEED = 0

pytestmark = pytest.mark.all_blenders



def auto_rig_biped(settings: RigSettings, rigify: bool = False):
    """The procedural biped auto-rigged with geometric skin."""
    character = generate_character(BIPED_SEED, "biped")
    obj = mesh_object("Biped", character.mesh.vertices, character.mesh.triangles)
    bpy.context.view_layer.update()
    select_only([obj], active=obj)
    plan = plan_rig([obj], bpy.context.evaluated_depsgraph_get(), "Biped", settings,
                    skin=SkinSettings(SkinningOptions(method="geometric")), rigify=rigify)
    return obj, run_steps(rig_steps(bpy.context, plan, remember=False))


@pytest.fixture
def rigified(clean_scene):
    """The procedural biped auto-rigged with the biped template and Rigify's control rig."""
    return auto_rig_biped(RigSettings(template="biped"), rigify=True)


def world_head(rig, bone: str) -> np.ndarray:
    return np.array(rig.matrix_world @ rig.pose.bones[bone].head)


def test_the_control_rig_replaces_the_skeleton_and_the_mesh_follows_its_def_bones(rigified):
    obj, result = rigified
    rig = result.armature
    armatures = sorted(o.name for o in bpy.data.objects if o.type == "ARMATURE")
    # One rig by the character's name, and the hidden metarig it was generated from.
    assert armatures == ["Biped_rig", "Biped_rig_metarig"] and rig.name == "Biped_rig"
    assert bpy.data.objects["Biped_rig_metarig"].hide_get()
    deforming = {bone.name for bone in rig.data.bones if bone.use_deform}
    assert {"DEF-upper_arm.L", "DEF-forearm.L", "DEF-hand.L", "DEF-thigh.L", "DEF-shin.L", "DEF-foot.L",
            "DEF-spine", "DEF-spine.006"} <= deforming
    assert all(name.startswith("DEF-") for name in deforming)
    modifiers = [m for m in obj.modifiers if m.type == "ARMATURE"]
    assert len(modifiers) == 1 and modifiers[0].object == rig
    assert {group.name for group in obj.vertex_groups} <= deforming
    assert any(note.startswith("Rigify biped control rig generated") for note in result.notes)


def test_moving_the_ik_hand_control_moves_the_forearm_and_the_hand(rigified):
    obj, result = rigified
    rig = result.armature
    before = {name: world_head(rig, name) for name in ("DEF-upper_arm.L", "DEF-forearm.L", "DEF-hand.L")}
    rest_vertices = evaluated_world_vertices(obj)
    assert rig.pose.bones["upper_arm_parent.L"]["IK_FK"] == 0.0  # the arm follows its IK control
    # Bring the hand 0.15 toward the body and 0.1 up: the elbow must bend, the shoulder stay.
    target = rig.pose.bones["hand_ik.L"]
    rest_target = np.array(rig.matrix_world @ target.head)
    move = np.array([-0.15, 0.0, 0.1])
    target.matrix = Matrix.Translation(Vector(move)) @ target.matrix  # armature space
    bpy.context.view_layer.update()
    np.testing.assert_allclose(np.array(rig.matrix_world @ target.head), rest_target + move, atol=1e-4)
    np.testing.assert_allclose(world_head(rig, "DEF-hand.L"), before["DEF-hand.L"] + move, atol=0.01)
    assert np.linalg.norm(world_head(rig, "DEF-forearm.L") - before["DEF-forearm.L"]) > 0.01
    np.testing.assert_allclose(world_head(rig, "DEF-upper_arm.L"), before["DEF-upper_arm.L"], atol=1e-5)
    before_hand = before["DEF-hand.L"]
    # The mesh around the left hand followed; the right side stayed.
    moved = np.linalg.norm(evaluated_world_vertices(obj) - rest_vertices, axis=1)
    hand = rest_vertices[:, 0] > before_hand[0]  # past the left wrist: the hand
    assert hand.sum() > 10 and np.median(moved[hand]) > 0.1
    assert moved[rest_vertices[:, 0] < -0.1].max() < 1e-6


def test_bending_the_fk_knee_bends_the_shin_not_the_thigh(rigified):
    obj, result = rigified
    rig = result.armature
    rig.pose.bones["thigh_parent.L"]["IK_FK"] = 1.0  # FK
    thigh, knee, ankle = (world_head(rig, name) for name in ("DEF-thigh.L", "DEF-shin.L", "DEF-foot.L"))
    shin = rig.pose.bones["shin_fk.L"]
    shin.rotation_mode = "XYZ"
    shin.rotation_euler = Euler((np.radians(70.0), 0.0, 0.0))
    bpy.context.view_layer.update()
    np.testing.assert_allclose(world_head(rig, "DEF-thigh.L"), thigh, atol=1e-5)
    np.testing.assert_allclose(world_head(rig, "DEF-shin.L"), knee, atol=1e-4)
    # The ankle swings about the knee: same distance, moved by 2 sin(35 degrees) of it.
    new_ankle = world_head(rig, "DEF-foot.L")
    radius = np.linalg.norm(ankle - knee)
    assert np.linalg.norm(new_ankle - knee) == pytest.approx(radius, rel=1e-3)
    assert np.linalg.norm(new_ankle - ankle) == pytest.approx(2 * np.sin(np.radians(35.0)) * radius, rel=1e-2)


def test_an_animation_keyed_on_mixamo_names_poses_a_skeleton_named_for_mixamo(clean_scene):
    obj, result = auto_rig_biped(RigSettings(template="biped", names="mixamo"))
    armature = result.armature
    bones = {bone.name for bone in armature.data.bones}
    assert {"mixamorig:Hips", "mixamorig:LeftForeArm", "mixamorig:RightUpLeg", "mixamorig:Head"} <= bones
    assert "mixamorig:LeftForeArm" in obj.vertex_groups
    # An action as a Mixamo clip keys it: by bone name, nothing else.
    action = bpy.data.actions.new("wave")
    rest = evaluated_world_vertices(obj)
    armature.animation_data_create().action = action
    path = 'pose.bones["mixamorig:LeftForeArm"].rotation_quaternion'
    turn = Euler((0.0, 0.0, np.radians(90.0))).to_quaternion()
    for index, value in enumerate(turn):
        curve = _fcurve(action, armature, path, index)
        curve.keyframe_points.insert(1, 1.0 if index == 0 else 0.0)
        curve.keyframe_points.insert(10, value)
    bpy.context.scene.frame_set(10)
    moved = np.linalg.norm(evaluated_world_vertices(obj) - rest, axis=1)
    elbow = world_head(armature, "mixamorig:LeftForeArm")
    past_elbow = rest[:, 0] > elbow[0] + 0.05
    assert past_elbow.sum() > 10 and np.median(moved[past_elbow]) > 0.05
    assert moved[rest[:, 0] < -0.1].max() < 1e-6  # the right arm stays


def _fcurve(action, armature, path, index):
    """An F-curve of ``action`` for ``armature`` (layered actions since 4.4, else the older ``fcurves``)."""
    if hasattr(action, "fcurve_ensure_for_datablock"):
        return action.fcurve_ensure_for_datablock(armature, path, index=index)
    return action.fcurves.new(path, index=index)


def test_renaming_goes_through_every_preset_and_back_with_the_vertex_groups(clean_scene):
    obj, result = auto_rig_biped(RigSettings(template="biped"))
    armature = result.armature
    rigify_names = sorted(bone.name for bone in armature.data.bones)
    weights_before = {group.name: group.index for group in obj.vertex_groups}
    for preset in ("vrm", "unreal", "mixamo", "unity", "rigify"):
        select_only([armature], active=armature)
        assert bpy.ops.autorig.rename_bones(preset=preset) == {"FINISHED"}
        names = {bone.name for bone in armature.data.bones}
        assert {group.name for group in obj.vertex_groups} <= names, preset
    assert sorted(bone.name for bone in armature.data.bones) == rigify_names
    assert {group.name: group.index for group in obj.vertex_groups} == weights_before
    # VRM's "spine" is Rigify's spine.001: the rename went through without Blender numbering a clash.
    bpy.ops.autorig.rename_bones(preset="vrm")
    assert "hips" in armature.data.bones and "spine" in armature.data.bones and "spine.001" not in armature.data.bones


def test_a_skeleton_that_is_not_a_standard_biped_is_not_renamed(clean_scene):
    skeleton = Skeleton(np.array([[0.0, 0.0, 0.5], [0.1, 0.0, 0.5], [-0.1, 0.0, 0.5]]), np.array([-1, 0, 0]),
                        ("root", "limb.L", "limb.R"))
    armature = build_armature(skeleton, "Creature_rig")
    select_only([armature], active=armature)
    with pytest.raises(RuntimeError, match="Only a standard biped skeleton can take engine bone names"):
        bpy.ops.autorig.rename_bones(preset="mixamo")
    assert [bone.name for bone in armature.data.bones] == ["root", "limb.L", "limb.R"]


def test_generate_rigify_rig_from_the_operator_is_one_undo_step(clean_scene):
    character = generate_character(BIPED_SEED, "biped")
    obj = mesh_object("Biped", character.mesh.vertices, character.mesh.triangles)
    bpy.context.view_layer.update()
    select_only([obj], active=obj)
    bpy.ops.ed.undo_push(message="before")
    assert bpy.ops.autorig.auto_rig(rig_template="BIPED", rig_rigify=True, skin_method="GEOMETRIC") == {"FINISHED"}
    # Background runs push no undo step of their own; Blender pushes this one after the operator.
    bpy.ops.ed.undo_push(message="Auto-Rig")
    rig = bpy.data.objects["Biped_rig"]
    assert "DEF-forearm.L" in rig.data.bones and bpy.data.objects["Biped"].modifiers[0].object == rig
    bpy.ops.ed.undo()
    assert sorted(o.name for o in bpy.data.objects if o.type == "ARMATURE") == []
    assert len(bpy.data.objects["Biped"].modifiers) == 0 and len(bpy.data.objects["Biped"].vertex_groups) == 0


FINGERS = ("thumb", "f_index", "f_middle", "f_ring", "f_pinky")


def test_a_biped_with_fingers_gets_rigify_fingers_on_its_knuckles_that_curl_toward_the_palm(clean_scene):
    from test_fingers import procedural_biped_with_box_fingers

    mesh = procedural_biped_with_box_fingers()
    obj = mesh_object("Biped", mesh.vertices, mesh.triangles)
    bpy.context.view_layer.update()
    # Our prediction from the mesh as Blender holds it (single precision), as Auto-Rig reads it.
    predicted = skeleton_from_votes(predict_votes(convert.read_mesh([obj])), template="biped")
    joints = dict(zip(predicted.names, predicted.joints))
    tails = dict(zip(predicted.names, predicted.tails))
    select_only([obj], active=obj)
    plan = plan_rig([obj], bpy.context.evaluated_depsgraph_get(), "Biped", RigSettings(template="biped"),
                    skin=SkinSettings(SkinningOptions(method="geometric")), rigify=True)
    rig = run_steps(rig_steps(bpy.context, plan, remember=False)).armature
    metarig = bpy.data.objects["Biped_rig_metarig"]
    assert metarig.pose.bones["palm.01.L"].rigify_type == "limbs.super_palm"
    assert metarig.pose.bones["f_index.01.L"].rigify_type == "limbs.super_finger"
    assert metarig.data.bones["f_index.02.L"].use_connect and not metarig.data.bones["f_index.01.L"].use_connect
    deforming = {bone.name for bone in rig.data.bones if bone.use_deform}
    for side in (".L", ".R"):
        assert {f"DEF-palm.{number:02d}{side}" for number in (1, 2, 3, 4)} <= deforming
        assert {f"DEF-{finger}.{joint:02d}{side}" for finger in FINGERS for joint in (1, 2, 3)} <= deforming
    # Rigify splits each DEF- finger bone in two; its first part starts on our knuckle.
    np.testing.assert_allclose(world_head(rig, "DEF-f_index.01.L"), joints["f_index.01.L"], atol=1e-3)
    groups = {group.name for group in obj.vertex_groups}
    assert groups <= deforming
    for side in (".L", ".R"):  # the fingers carry weight
        assert len({name for name in groups if name.startswith(("DEF-f_", "DEF-thumb")) and name.endswith(side)}) >= 5

    wrist = world_head(rig, "DEF-hand.L")
    tail_before = np.array(rig.matrix_world @ rig.pose.bones["DEF-f_index.03.L"].tail)
    rest = evaluated_world_vertices(obj)
    control = rig.pose.bones["f_index.01.L"]  # the finger's first FK control (its master: f_index.01_master.L)
    control.rotation_mode = "XYZ"
    control.rotation_euler = Euler((np.radians(45.0), 0.0, 0.0))
    bpy.context.view_layer.update()
    np.testing.assert_allclose(world_head(rig, "DEF-hand.L"), wrist, atol=1e-6)
    tail_after = np.array(rig.matrix_world @ rig.pose.bones["DEF-f_index.03.L"].tail)
    # The finger swings about its knuckle (0.4 of its length for 45 degrees), toward the palm: down.
    length = np.linalg.norm(tails["f_index.03.L"] - joints["f_index.01.L"])
    assert np.linalg.norm(tail_after - tail_before) > 0.4 * length
    assert tail_after[2] < tail_before[2] - 0.2 * length
    moved = np.linalg.norm(evaluated_world_vertices(obj) - rest, axis=1)
    # A fingertip's vertices: near its tip and nearer to it than to another finger's (the box fingers lie 6 mm apart).
    tips = np.array([tails[f"{finger}.03.L"] for finger in FINGERS])
    to_tips = np.linalg.norm(rest[:, None, :] - tips[None], axis=2)
    nearest_tip = np.argmin(to_tips, axis=1)
    near_tip = (to_tips[:, FINGERS.index("f_index")] < 0.3 * length) & (nearest_tip == FINGERS.index("f_index"))
    near_middle_tip = ((to_tips[:, FINGERS.index("f_middle")] < 0.3 * length)
                       & (nearest_tip == FINGERS.index("f_middle")))
    assert near_tip.sum() >= 4 and np.median(moved[near_tip]) > 0.3 * length
    assert np.median(moved[near_middle_tip]) < 0.05 * length
    assert moved[rest[:, 0] < -0.1].max() < 1e-6  # the right side stays
