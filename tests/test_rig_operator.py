"""Predict Skeleton and Auto-Rig (autorig_addon.blender.operators.rig and
the job behind them, autorig_addon.blender.jobs.rig) on a procedural biped,
with real bpy."""

import re
import time
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from autorig_addon.blender import convert
from autorig_addon.blender.jobs import rig
from autorig_addon.blender.jobs.rig import PREDICTED_PROPERTY, RigSettings, plan_rig, rig_steps, run_steps
from autorig_addon.blender.jobs.skin import SkinSettings
from autorig_addon.blender.operators.rig import _RigOperator
from autorig_addon.core.errors import Cancelled
from autorig_addon.core.geometry.outward_faces import inward_faces_note
from autorig_addon.core.rigging import predict
from blender_fixtures import (
    BIPED_SEED,
    RecordingWindowManager,
    RecordingWorkspace,
    add_biped,
    armatures,
    group_weights,
    make_armature,
    mesh_object,
    parent_to_bone,
    scene_state,
    select_only,
)
from geometry_fixtures import triangle_and_flat_triangles

pytestmark = pytest.mark.all_blenders

# The biped (blender_fixtures.add_biped): 1,866 vertices, 29 bones in its own rig.
#: A bone tail may stick out of the mesh's bounding box by this share of its
#: diagonal (a leaf's tail is extrapolated from its chain); heads may not.
BOX_SLACK = 0.05
#: Two levels of detail around the default (a smaller bandwidth gives more joints).
FINE_BANDWIDTH, COARSE_BANDWIDTH = 0.75 * predict.DEFAULT_BANDWIDTH, 4 * predict.DEFAULT_BANDWIDTH


@pytest.fixture
def biped(clean_scene):
    obj = add_biped()
    select_only([obj], active=obj)
    return obj


def outside_box(points, vertices) -> np.ndarray:
    """(k,) how far each point lies outside the vertices' bounding box, share of its diagonal (0 inside)."""
    low, high = vertices.min(0), vertices.max(0)
    outside = np.maximum(low - points, 0) + np.maximum(points - high, 0)
    return np.linalg.norm(outside, axis=1) / np.linalg.norm(high - low)


def bone_count_at(bandwidth: float) -> int:
    bpy.context.scene.autorig.rig_bandwidth = bandwidth
    (armature,) = armatures()
    return len(armature.data.bones)


def test_predict_skeleton_builds_one_armature_inside_the_mesh(biped):
    mesh_before = scene_state([biped])
    mesh_before.pop("objects")

    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}

    (armature,) = armatures()
    names = [bone.name for bone in armature.data.bones]
    assert armature.name == "Biped_rig" and len(names) >= 5 and len(set(names)) == len(names)
    assert all(bone.use_deform for bone in armature.data.bones)
    assert armature[PREDICTED_PROPERTY] in rig._PREDICTIONS
    assert outside_box(convert.read_skeleton(armature).joints, convert.read_mesh([biped]).vertices).max() == 0.0
    # The armature is active beside the still selected mesh, ready for Skin.
    assert bpy.context.view_layer.objects.active == armature and biped.select_get()
    state = scene_state([biped])
    state.pop("objects")
    assert state == mesh_before


def test_predicted_bone_tails_stay_near_the_mesh(biped):
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    (armature,) = armatures()
    assert outside_box(convert.read_skeleton(armature).tails, convert.read_mesh([biped]).vertices).max() <= BOX_SLACK


def test_predict_skeleton_is_one_undo_step(biped):
    bpy.ops.ed.undo_push(message="before")
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    # Background runs push no undo step of their own; Blender pushes this one after the operator.
    bpy.ops.ed.undo_push(message="Predict Skeleton")
    assert len(armatures()) == 1
    bpy.ops.ed.undo()
    assert armatures() == [] and sorted(bpy.data.objects.keys()) == ["Biped"]
    assert len(bpy.data.armatures) == 0


def test_bandwidth_reclusters_the_same_armature_live(biped):
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    (armature,) = armatures()
    pointer = armature.as_pointer()

    fine = bone_count_at(FINE_BANDWIDTH)
    coarse = bone_count_at(COARSE_BANDWIDTH)

    assert coarse <= fine and fine > 1
    assert armatures()[0].as_pointer() == pointer and len(bpy.data.armatures) == 1
    # The rebuilt bones are the core's skeleton at that bandwidth.
    votes = rig._prediction_of(armature).votes
    expected = predict.skeleton_from_votes(votes, bandwidth=COARSE_BANDWIDTH)
    built = convert.read_skeleton(armature)
    # Blender lists sibling bones in its own order: compare bone by bone.
    assert sorted(built.names) == sorted(expected.names)
    order = [built.names.index(name) for name in expected.names]
    np.testing.assert_allclose(built.joints[order], expected.joints, atol=1e-5)
    assert rig.live_note(bpy.context) == ("Live: the settings update 'Biped_rig'", "ARMATURE_DATA")


def test_a_known_rig_stays_live_and_gives_way_to_a_standard_biped_for_engine_names(biped, monkeypatch):
    # The biped's own procedural twin is the only known rig: Predict Skeleton gives its rig.
    from autorig_addon.core.dataset.sample import CharacterSample
    from autorig_addon.core.procedural import generate_character
    from autorig_addon.core.rigging import rig_library

    character = generate_character(BIPED_SEED, "biped")
    twin = CharacterSample.from_character("procedural/biped_twin", "biped", character.mesh, character.skeleton,
                                          character.weights)
    monkeypatch.setattr(rig_library, "shipped_library", lambda: rig_library.build_rig_library([twin]))
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    (armature,) = armatures()
    artist = sorted(character.skeleton.deform_subset().names)
    assert sorted(bone.name for bone in armature.data.bones) == artist
    # Mixamo's names need the standard biped: the live armature becomes one, and the known rig again without them.
    bpy.context.scene.autorig.rig_names = "MIXAMO"
    assert "mixamorig:Hips" in armature.data.bones and len(armature.data.bones) == 22
    bpy.context.scene.autorig.rig_names = "RIGIFY"
    assert sorted(bone.name for bone in armature.data.bones) == artist
    assert armatures() == [armature]


@pytest.mark.parametrize("bandwidth", [predict.MIN_BANDWIDTH, predict.MAX_BANDWIDTH])
def test_the_bandwidth_slider_accepts_its_own_ends(biped, bandwidth):
    """Blender stores the ends in float32 (0.2 reads back 0.20000000298), a hair outside the core's bounds."""
    assert bpy.ops.autorig.predict_skeleton(rig_bandwidth=bandwidth) == {"FINISHED"}
    (armature,) = armatures()
    votes = rig._prediction_of(armature).votes
    assert len(armature.data.bones) == predict.skeleton_from_votes(votes, bandwidth=bandwidth).bone_count

    bpy.context.scene.autorig.rig_bandwidth = predict.DEFAULT_BANDWIDTH
    bone_count_at(bandwidth)  # the panel's slider dragged to the end
    assert rig.live_note(bpy.context) == ("Live: the settings update 'Biped_rig'", "ARMATURE_DATA")
    assert len(armature.data.bones) == predict.skeleton_from_votes(votes, bandwidth=bandwidth).bone_count


def test_a_linked_duplicate_keeps_the_armature_out_of_live_updates(biped):
    """Rebuilding would replace the bones both objects share: the duplicate
    (and the mesh bound to it) would lose its armature."""
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    armature = bpy.data.objects["Biped_rig"]
    select_only([armature], active=armature)
    bpy.ops.object.duplicate(linked=True)
    duplicate = bpy.context.active_object
    cape = mesh_object("Cape", [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]], [[0, 1, 2]])
    cape.modifiers.new("Armature", "ARMATURE").object = duplicate
    select_only([armature], active=armature)
    bones_before = convert.read_skeleton(armature)

    bpy.context.scene.autorig.rig_bandwidth = COARSE_BANDWIDTH

    assert bpy.data.objects.get(duplicate.name) == duplicate and duplicate.data == armature.data
    assert cape.modifiers["Armature"].object == duplicate
    after = convert.read_skeleton(armature)
    assert after.names == bones_before.names
    np.testing.assert_array_equal(after.joints, bones_before.joints)
    assert rig.live_note(bpy.context) == (
        f"'Biped_rig' shares its bones with '{duplicate.name}' (a linked duplicate): the settings apply at the next "
        "Predict Skeleton", "INFO")


def test_a_prop_on_a_predicted_bone_keeps_the_armature_out_of_live_updates(biped):
    """A rebuild moves or removes the bone the prop hangs on: it would jump."""
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    armature = bpy.data.objects["Biped_rig"]
    lantern = bpy.data.objects.new("Lantern", None)  # an empty: no mesh, so never "bound"
    bpy.context.scene.collection.objects.link(lantern)
    lantern.location = (0.1, -0.1, 0.5)
    bpy.context.view_layer.update()
    root_bone = convert.read_skeleton(armature).names[0]
    parent_to_bone(lantern, armature, root_bone)
    place_before = np.array(lantern.matrix_world)
    bones_before = convert.read_skeleton(armature)

    bpy.context.scene.autorig.rig_bandwidth = COARSE_BANDWIDTH
    bpy.context.view_layer.update()

    assert convert.read_skeleton(armature).names == bones_before.names
    np.testing.assert_allclose(np.array(lantern.matrix_world), place_before, atol=1e-6)
    assert lantern.parent == armature and lantern.parent_bone == root_bone
    assert rig.live_note(bpy.context) == (
        "'Biped_rig' carries 'Lantern' on its bones: the settings apply at the next Predict Skeleton", "INFO")


def test_edited_armature_is_left_alone(biped):
    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}
    (armature,) = armatures()
    bpy.ops.object.mode_set(mode="EDIT")
    bone = armature.data.edit_bones[0]
    bone.tail = bone.tail + (bone.tail - bone.head) * 0.5
    bpy.ops.object.mode_set(mode="OBJECT")
    edited = convert.read_skeleton(armature)

    bpy.context.scene.autorig.rig_bandwidth = predict.MAX_BANDWIDTH

    after = convert.read_skeleton(armature)
    assert after.names == edited.names
    np.testing.assert_array_equal(after.tails, edited.tails)
    assert rig.live_note(bpy.context) == (
        "'Biped_rig' was edited: the settings apply at the next Predict Skeleton", "INFO")


def test_auto_rig_binds_every_vertex(biped):
    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    bones = [bone.name for bone in armature.data.bones]
    # A bone no vertex follows gets no group (the skin writer's rule); no other group is made.
    assert {group.name for group in biped.vertex_groups} <= set(bones) and len(biped.vertex_groups) >= 2
    np.testing.assert_allclose(group_weights(biped, bones).sum(axis=1), 1.0, atol=1e-5)
    assert [(m.type, m.object) for m in biped.modifiers] == [("ARMATURE", armature)]
    assert biped.parent == armature
    # Bound, the armature no longer follows the settings.
    assert rig.live_note(bpy.context)[0] == ("'Biped_rig' is bound to meshes: the settings apply at the next "
                                             "Predict Skeleton")


def test_flipped_normals_auto_rig_as_the_mesh_wound_right(biped, capfd):
    """Faces flipped in Blender (Mesh > Normals > Flip, or a negative scale
    applied) give the skeleton and the weights of the same mesh unflipped;
    the report says so and the mesh keeps its faces as they were."""
    flipped = add_biped("Flipped")
    flipped.data.flip_normals()
    flipped_faces = [tuple(polygon.vertices) for polygon in flipped.data.polygons]
    assert flipped_faces != [tuple(polygon.vertices) for polygon in biped.data.polygons]
    rigs = {}
    for obj in (biped, flipped):
        select_only([obj], active=obj)
        assert bpy.ops.autorig.auto_rig() == {"FINISHED"}
        skeleton = convert.read_skeleton(bpy.data.objects[f"{obj.name}_rig"])
        rigs[obj.name] = skeleton, group_weights(obj, skeleton.names)

    (skeleton, weights), (flipped_skeleton, flipped_weights) = rigs["Biped"], rigs["Flipped"]
    assert flipped_skeleton.names == skeleton.names
    np.testing.assert_allclose(flipped_skeleton.joints, skeleton.joints, atol=1e-6, rtol=0)
    np.testing.assert_allclose(flipped_weights, weights, atol=1e-6, rtol=0)
    report = capfd.readouterr().out
    for reader in ("the skeleton prediction", "the skinning"):  # every face is a triangle
        assert report.count(inward_faces_note(len(biped.data.polygons), reader)) == 1
    assert [tuple(polygon.vertices) for polygon in flipped.data.polygons] == flipped_faces


def test_nothing_selected_is_refused_and_scene_unchanged(biped):
    select_only([], active=None)
    before = scene_state([biped])
    for operator in (bpy.ops.autorig.predict_skeleton, bpy.ops.autorig.auto_rig):
        with pytest.raises(RuntimeError, match=re.escape("Select the mesh(es) of the character to rig.")):
            operator()
    assert scene_state([biped]) == before and len(bpy.data.armatures) == 0


def test_mesh_without_faces_is_refused_and_scene_unchanged(clean_scene):
    points = mesh_object("Points", [[0, 0, 0.5], [0, 0, 1.5], [0.1, 0, 1.0]], [])
    bpy.context.view_layer.update()
    select_only([points], active=points)
    before = scene_state([points])
    with pytest.raises(RuntimeError, match=re.escape(
            "'Points' has no faces: it is only vertices or edges. "
            "Add faces to it (Edit Mode > Face > Fill) or pick a mesh with a surface.")):
        bpy.ops.autorig.predict_skeleton()
    assert scene_state([points]) == before and len(bpy.data.armatures) == 0


def test_a_triangle_padded_with_flat_faces_is_refused_and_scene_unchanged(clean_scene):
    """One real triangle plus 16 without area passed the 16-face minimum and was rigged."""
    mesh = triangle_and_flat_triangles(predict.MIN_FACES)
    padded = mesh_object("Padded", mesh.vertices, mesh.triangles)
    bpy.context.view_layer.update()
    assert len(padded.data.polygons) == 17
    select_only([padded], active=padded)
    before = scene_state([padded])
    for operator in (bpy.ops.autorig.predict_skeleton, bpy.ops.autorig.auto_rig):
        with pytest.raises(RuntimeError, match=re.escape(
                "The mesh has 1 faces with an area (16 more have none: remove them with Mesh > Clean Up > "
                "Degenerate Dissolve); predicting a skeleton needs a character surface of at least 16.")):
            operator()
        assert scene_state([padded]) == before and len(bpy.data.armatures) == 0


def test_auto_rig_refuses_a_bound_mesh_unless_replace(biped, capfd):
    old = make_armature("Old")
    modifier = biped.modifiers.new("Armature", "ARMATURE")
    modifier.object = old
    biped.vertex_groups.new(name="Lower")
    biped.vertex_groups.new(name="Mask")
    select_only([biped], active=biped)
    before = scene_state([biped, old])

    with pytest.raises(RuntimeError, match=re.escape(
            "'Biped' is already bound to the armature 'Old': turn on Replace Binding to bind it to the new skeleton "
            "instead, or remove its Armature modifier first.")):
        bpy.ops.autorig.auto_rig()
    assert scene_state([biped, old]) == before

    assert bpy.ops.autorig.auto_rig(rig_replace=True) == {"FINISHED"}
    new = bpy.data.objects["Biped_rig"]
    assert [(m.type, m.object) for m in biped.modifiers] == [("ARMATURE", new)]
    groups = {group.name for group in biped.vertex_groups}
    assert "Lower" not in groups and "Mask" in groups  # the old bones' groups go, the artist's stay
    # Nothing else follows the old armature: it goes, its data with it.
    assert bpy.data.objects.get("Old") is None and len(bpy.data.armatures) == 1
    assert "the old armature 'Old' was removed (no other object follows it)." in capfd.readouterr().out


def test_replace_binding_keeps_an_old_armature_another_mesh_follows(biped, capfd):
    old = make_armature("Old")
    for obj in (biped, mesh_object("Boots", [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]], [[0, 1, 2]])):
        obj.modifiers.new("Armature", "ARMATURE").object = old
    select_only([biped], active=biped)
    old_bones = [bone.name for bone in old.data.bones]

    assert bpy.ops.autorig.auto_rig(rig_replace=True) == {"FINISHED"}

    assert [(m.type, m.object) for m in biped.modifiers] == [("ARMATURE", bpy.data.objects["Biped_rig"])]
    assert bpy.data.objects.get("Old") == old and [bone.name for bone in old.data.bones] == old_bones
    assert bpy.data.objects["Boots"].modifiers["Armature"].object == old
    assert "the old armature 'Old' stays: 'Boots' still follow it." in capfd.readouterr().out


def test_cancel_while_skinning_leaves_nothing(biped):
    """Esc during the skin weights (the second task) removes the armature built before them."""
    before = scene_state([biped])
    plan = plan_rig([biped], bpy.context.evaluated_depsgraph_get(), "Biped", RigSettings(), skin=SkinSettings())

    def progress(fraction, message):
        if fraction > rig.PREDICTION_SHARE:
            raise Cancelled("Rigging cancelled.")

    with pytest.raises(Cancelled):
        run_steps(rig_steps(bpy.context, plan), progress)
    assert scene_state([biped]) == before and len(bpy.data.armatures) == 0


# --------------------------------------------------------------------------- the modal run (worker thread, Esc)


class RigOperatorStandIn:
    """The modal machinery of the rig operators without Blender's operator
    object: reports recorded, a timer already added."""

    modal = _RigOperator.modal
    cancel = _RigOperator.cancel
    _advance = _RigOperator._advance
    _end_modal = _RigOperator._end_modal
    _fail = _RigOperator._fail
    _finish = _RigOperator._finish

    def __init__(self, steps):
        self._steps, self._job, self._timer = steps, None, "timer"
        self.reports = []

    def report(self, kind, message):
        self.reports.append((kind, message))


def ui_context():
    return SimpleNamespace(window_manager=RecordingWindowManager(), workspace=RecordingWorkspace(),
                           view_layer=bpy.context.view_layer)


def tick_until_done(operator, context, limit_seconds=120.0):
    started = time.perf_counter()
    while time.perf_counter() - started < limit_seconds:
        outcome = operator.modal(context, SimpleNamespace(type="TIMER"))
        if outcome != {"RUNNING_MODAL"}:
            return outcome
        time.sleep(0.01)
    raise AssertionError("the modal run did not end")


def test_modal_run_predicts_in_a_worker_and_ends_cleanly(biped):
    plan = plan_rig([biped], bpy.context.evaluated_depsgraph_get(), "Biped")
    operator, context = RigOperatorStandIn(rig_steps(bpy.context, plan)), ui_context()
    assert operator._advance(context, None, None) is None  # the prediction runs in a worker thread

    assert tick_until_done(operator, context) == {"FINISHED"}

    (armature,) = armatures()
    assert operator.reports[0][1].startswith(f"Predicted 'Biped_rig' with {len(armature.data.bones)} bones")
    assert context.window_manager.calls[-2:] == [("remove_timer", "timer"), ("end",)]
    assert context.workspace.texts[-1] is None and context.workspace.texts[0].startswith("Auto-Rig: ")


def test_esc_stops_the_worker_and_leaves_nothing(biped, monkeypatch):
    def endless_votes(mesh, progress):
        for _ in range(10000):  # until cancelled (at most about 10 s)
            progress(0.5, "Voting")
            time.sleep(0.001)
        raise AssertionError("never cancelled")

    monkeypatch.setattr(rig, "predict_votes", endless_votes)
    before = scene_state([biped])
    plan = plan_rig([biped], bpy.context.evaluated_depsgraph_get(), "Biped", skin=SkinSettings())
    operator, context = RigOperatorStandIn(rig_steps(bpy.context, plan)), ui_context()
    operator._advance(context, None, None)

    assert operator.modal(context, SimpleNamespace(type="ESC")) == {"RUNNING_MODAL"}
    assert tick_until_done(operator, context) == {"CANCELLED"}

    assert operator.reports == [({"WARNING"}, "Rigging cancelled; nothing was changed.")]
    assert scene_state([biped]) == before and len(bpy.data.armatures) == 0
    assert context.window_manager.calls[-2:] == [("remove_timer", "timer"), ("end",)]


def test_a_character_lying_on_its_back_by_its_object_rotation_is_rigged_standing_in_its_own_frame(clean_scene):
    # As a Y-up import can leave it: the mesh upright in its own data, the object turned -90 degrees about X, so
    # in the scene the character lies on its back with its head toward +Y.
    obj = add_biped()
    obj.rotation_euler = (-np.pi / 2, 0.0, 0.0)
    bpy.context.view_layer.update()
    select_only([obj], active=obj)

    assert bpy.ops.autorig.predict_skeleton() == {"FINISHED"}

    (armature,) = armatures()
    skeleton = convert.read_skeleton(armature)
    joint = {name: skeleton.joints[k] for k, name in enumerate(skeleton.names)}
    up, left = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])  # the character's own, in the scene
    assert (joint["head"] - joint["spine"]) @ up > 0.2
    assert (joint["thigh.L"] - joint["thigh.R"]) @ left > 0.05
    assert (joint["upper_arm.L"] - joint["upper_arm.R"]) @ left > 0.1
    assert outside_box(skeleton.joints, convert.read_mesh([obj]).vertices).max() == 0.0


def add_fingered_biped(name="Biped"):
    """The procedural biped with four box fingers and a thumb on each hand (``test_fingers``)."""
    from test_fingers import procedural_biped_with_box_fingers

    mesh = procedural_biped_with_box_fingers()
    obj = mesh_object(name, mesh.vertices, mesh.triangles)
    bpy.context.view_layer.update()
    select_only([obj], active=obj)
    return obj


def test_the_fingers_switch_off_gives_the_22_bones_and_on_weighted_finger_bones(clean_scene):
    obj = add_fingered_biped()
    assert bpy.ops.autorig.predict_skeleton(rig_template="BIPED", rig_fingers=False) == {"FINISHED"}
    (armature,) = armatures()
    assert len(armature.data.bones) == 22
    assert not any(bone.name.startswith(("thumb", "f_")) for bone in armature.data.bones)
    bpy.data.objects.remove(armature)
    bpy.context.view_layer.update()
    select_only([obj], active=obj)

    assert bpy.ops.autorig.auto_rig(rig_template="BIPED", rig_fingers=True, skin_method="GEOMETRIC") == {"FINISHED"}
    (armature,) = armatures()
    names = [bone.name for bone in armature.data.bones]
    fingers = [name for name in names if name.startswith(("thumb", "f_"))]
    assert len(names) == 22 + 30 and len(fingers) == 30
    assert all(armature.data.bones[name].parent.name.startswith(("hand", "thumb", "f_")) for name in fingers)
    # The fingers carry weight: the box fingers' vertices (the mesh's last 2 x 5 x 8) past the palm follow them
    # (the mitten hand under them does too).
    weights = group_weights(obj, fingers).sum(axis=1)
    assert (weights[-80:] > 0.5).sum() >= 30, np.sort(weights[-80:])
    for side in (".L", ".R"):
        assert sum(group.name in fingers and group.name.endswith(side) for group in obj.vertex_groups) >= 5
