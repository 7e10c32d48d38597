"""The Skin operator and the ``skin`` subcommand on a generated 2-bone cylinder."""

import re
from types import SimpleNamespace

import numpy as np
import pytest

from autorig_addon.blender.jobs import skin
from autorig_addon.blender.jobs.skin import SkinJob
from autorig_addon.blender.operators.skin import AUTORIG_OT_skin_weights
from autorig_addon.blender.progress import PROGRESS_STEPS
from autorig_addon.core.errors import Cancelled
from autorig_addon.core.skinning.options import SkinningOptions
from blender_fixtures import (
    BODY_HEIGHT,
    BODY_RADIUS,
    LOWER_BONE,
    UPPER_BONE,
    RecordingWindowManager,
    RecordingWorkspace,
    cylinder_geometry,
    group_weights,
    local_positions,
    make_armature,
    mesh_object,
    scene_state,
    select_only,
)

pytestmark = pytest.mark.all_blenders


def unbound_cylinder(name="Tube"):
    import bpy

    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, BODY_HEIGHT, 24, 20, capped=True)
    tube = mesh_object(name, vertices, faces)
    bpy.context.view_layer.update()  # so the view layer lists it and it can be selected
    return tube


@pytest.fixture
def armature_and_tube(clean_scene):
    armature = make_armature()
    tube = unbound_cylinder()
    select_only([armature, tube], active=armature)
    return armature, tube


@pytest.mark.parametrize("distance", ["GEODESIC", "HOLLOW"])
def test_skin_operator_binds_ends_to_their_bones(armature_and_tube, distance):
    import bpy

    armature, tube = armature_and_tube
    assert bpy.ops.autorig.skin_weights(skin_method="GEOMETRIC", skin_distance=distance,
                                        skin_resolution=40) == {"FINISHED"}
    weights = group_weights(tube, [LOWER_BONE, UPPER_BONE])
    z = np.array([v.co.z for v in tube.data.vertices])
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-5)
    assert weights[z < 0.3, 0].min() > 0.9
    assert weights[z > 1.7, 1].min() > 0.9
    assert tube.parent == armature
    assert [m.type for m in tube.modifiers] == ["ARMATURE"]


def test_non_deform_bone_never_gets_a_group(clean_scene):
    import bpy

    armature = make_armature(deform_upper=False)
    tube = unbound_cylinder()
    select_only([armature, tube], active=armature)
    assert bpy.ops.autorig.skin_weights(skin_resolution=32) == {"FINISHED"}
    assert tube.vertex_groups.get(UPPER_BONE) is None
    np.testing.assert_allclose(group_weights(tube, [LOWER_BONE])[:, 0], 1.0, atol=1e-6)


def test_armature_far_from_mesh_is_refused_and_scene_unchanged(armature_and_tube):
    import bpy

    armature, tube = armature_and_tube
    armature.location = (20.0, 0.0, 0.0)
    bpy.context.view_layer.update()
    before = scene_state([armature, tube])
    with pytest.raises(RuntimeError, match=re.escape(
            "The armature 'Armature' lies far from the mesh: move it onto the character "
            "(or apply the object transforms) before skinning.")):
        bpy.ops.autorig.skin_weights()
    assert scene_state([armature, tube]) == before


def test_mesh_without_faces_is_refused_and_scene_unchanged(clean_scene):
    import bpy

    armature = make_armature()
    points = mesh_object("Points", [[0, 0, 0.5], [0, 0, 1.5], [0.1, 0, 1.0]], [])
    bpy.context.view_layer.update()
    select_only([armature, points], active=armature)
    before = scene_state([armature, points])
    with pytest.raises(RuntimeError, match=re.escape("'Points' has no faces: it is only vertices or edges.")):
        bpy.ops.autorig.skin_weights()
    assert scene_state([armature, points]) == before


def shrink_bone(armature, name, length=1e-5):
    """Shrink bone ``name`` to ``length`` along +Z, disconnecting its children
    first so their heads stay. (Blender deletes zero-length bones itself, so
    this is below the point-like tolerance instead.)"""
    import bpy

    select_only([armature], active=armature)
    bpy.ops.object.mode_set(mode="EDIT")
    for bone in armature.data.edit_bones:
        if bone.parent is not None and bone.parent.name == name:
            bone.use_connect = False
    bone = armature.data.edit_bones[name]
    bone.tail = (bone.head.x, bone.head.y, bone.head.z + length)
    bpy.ops.object.mode_set(mode="OBJECT")


def test_zero_length_deform_bone_without_child_is_refused_by_name(clean_scene):
    import bpy

    armature = make_armature()
    tube = unbound_cylinder()
    shrink_bone(armature, UPPER_BONE)
    select_only([armature, tube], active=armature)
    before = scene_state([armature, tube])
    with pytest.raises(RuntimeError, match=f"Deform bone '{UPPER_BONE}' has zero length and no child to point at"):
        bpy.ops.autorig.skin_weights()
    assert scene_state([armature, tube]) == before


def test_zero_length_bone_with_a_child_is_measured_to_the_child(clean_scene):
    import bpy

    from autorig_addon.blender.jobs.skin import SkinSettings, compute_skin, plan_skin

    armature = make_armature()
    tube = unbound_cylinder()
    shrink_bone(armature, LOWER_BONE)
    tails_before = [tuple(bone.tail_local) for bone in armature.data.bones]
    # The geometric method measures along the derived tail exactly (the networks see it only through features).
    plan = plan_skin(armature, [tube], SkinSettings(SkinningOptions(method="geometric", resolution=32)),
                     bpy.context.evaluated_depsgraph_get())
    assert plan.tail_decision.derived == (LOWER_BONE,)
    assert "bone tails derived from the joints" in plan.summary
    lower = plan.skeleton.names.index(LOWER_BONE)
    np.testing.assert_allclose(plan.skeleton.tails[lower], [0.0, 0.0, 1.0], atol=1e-6)
    weights = compute_skin(plan)
    z = plan.mesh.vertices[:, 2]
    assert weights.matrix[z < 0.3, 0].min() > 0.9 and weights.matrix[z > 1.7, 1].min() > 0.9
    # Only the arrays changed: the armature keeps its point-like bone.
    assert [tuple(bone.tail_local) for bone in armature.data.bones] == tails_before


def test_skin_command_reports_derived_tails(clean_scene, tmp_path):
    import json

    import bpy

    from autorig_addon.cli import main

    armature = make_armature()
    unbound_cylinder()
    shrink_bone(armature, LOWER_BONE)
    source = tmp_path / "rig.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source), copy=True)
    summary = tmp_path / "summary.json"
    assert main(["skin", str(source), "--out", str(tmp_path / "skinned.blend"), "--resolution", "32", "--quiet",
                 "--summary", str(summary)]) == 0
    (entry,) = json.loads(summary.read_text())["succeeded"]
    assert entry["tails"].startswith("bone tails derived from the joints for 1 point-like bone")
    assert f"'{LOWER_BONE}'" in entry["tails"]


def test_skin_command_writes_groups_into_the_output(clean_scene, tmp_path):
    import bpy

    from autorig_addon.cli import main

    make_armature()
    unbound_cylinder()
    source = tmp_path / "rig.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source), copy=True)
    out = tmp_path / "skinned.blend"
    assert main(["skin", str(source), "--out", str(out), "--resolution", "32", "--quiet"]) == 0
    bpy.ops.wm.open_mainfile(filepath=str(out))
    tube = bpy.data.objects["Tube"]
    weights = group_weights(tube, [LOWER_BONE, UPPER_BONE])
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-5)
    z = np.array([v.co.z for v in tube.data.vertices])
    assert weights[z < 0.3, 0].min() > 0.9


def test_write_skin_restores_every_mesh_when_a_later_write_fails(clean_scene, monkeypatch):
    import bpy

    armature = make_armature()
    first, second = unbound_cylinder("First"), unbound_cylinder("Second")
    plan = skin.plan_skin(armature, [first, second], skin.SkinSettings(SkinningOptions(resolution=24)),
                          bpy.context.evaluated_depsgraph_get())
    weights = skin.compute_skin(plan)
    before = scene_state([armature, first, second])
    real_write = skin.write_weights

    def second_write_fails(obj, *args, **kwargs):
        if obj == second:
            raise RuntimeError("disk full")
        real_write(obj, *args, **kwargs)

    monkeypatch.setattr(skin, "write_weights", second_write_fails)
    with pytest.raises(RuntimeError, match="disk full"):
        skin.write_skin(plan, weights)
    assert scene_state([armature, first, second]) == before


class SkinOperatorStandIn:
    """The Skin operator's own modal, cancel and cleanup code on a plain
    object: Blender creates operator instances only when it runs them."""

    modal = AUTORIG_OT_skin_weights.modal
    cancel = AUTORIG_OT_skin_weights.cancel
    _end_modal = AUTORIG_OT_skin_weights._end_modal

    def __init__(self, job, thread_alive=True):
        self._job = job
        self._timer = "timer"
        self._thread = SimpleNamespace(is_alive=lambda: thread_alive)
        self.reports = []

    def report(self, kind, message):
        self.reports.append((kind, message))


def ui_context():
    return SimpleNamespace(window_manager=RecordingWindowManager(), workspace=RecordingWorkspace())


def test_skin_job_reports_progress_and_stops_once_cancelled(monkeypatch):
    def fake_compute(plan, progress):
        progress(0.5, "Voxelizing")
        return "weights of " + plan

    monkeypatch.setattr(skin, "compute_skin", fake_compute)
    job = SkinJob("plan")
    job.run()
    assert (job.fraction, job.message, job.weights, job.error) == (0.5, "Voxelizing", "weights of plan", None)

    cancelled = SkinJob("plan", cancel=True)
    cancelled.run()
    assert cancelled.weights is None and cancelled.fraction == 0.0
    assert isinstance(cancelled.error, Cancelled) and str(cancelled.error) == "Skinning cancelled."


def test_cancel_removes_timer_progress_and_status_and_stops_the_worker():
    job = SkinJob("plan")
    operator, context = SkinOperatorStandIn(job), ui_context()
    operator.cancel(context)
    assert job.cancel  # the worker stops at its next progress report; its result is never read
    assert context.window_manager.calls == [("remove_timer", "timer"), ("end",)]
    assert context.workspace.texts == [None]
    operator.cancel(context)  # a second call must not remove the timer twice
    assert context.window_manager.calls == [("remove_timer", "timer"), ("end",)]
    assert operator.reports == []


def test_modal_shows_progress_then_ends_through_the_same_cleanup_on_esc():
    job = SkinJob("plan", fraction=0.25, message="Voxelizing")
    operator, context = SkinOperatorStandIn(job), ui_context()
    assert operator.modal(context, SimpleNamespace(type="ESC")) == {"RUNNING_MODAL"}
    assert job.cancel and context.window_manager.calls == []
    assert operator.modal(context, SimpleNamespace(type="TIMER")) == {"RUNNING_MODAL"}
    assert context.window_manager.calls == [("update", PROGRESS_STEPS // 4)]
    assert context.workspace.texts == ["Skin weights: Voxelizing (25%), Esc to cancel"]

    job.error = Cancelled("Skinning cancelled.")  # the worker saw the request and stopped
    operator._thread = SimpleNamespace(is_alive=lambda: False)
    assert operator.modal(context, SimpleNamespace(type="TIMER")) == {"CANCELLED"}
    assert context.window_manager.calls[-2:] == [("remove_timer", "timer"), ("end",)]
    assert context.workspace.texts[-1] is None
    assert operator.reports == [({"WARNING"}, "Skinning cancelled; nothing was changed.")]


# --------------------------------------------------------------------------- strays, non-finite positions, modes

#: Where the stray vertex lands: 10 km off the character.
FAR_AWAY = (10000.0, 0.0, 1.0)


def skinned_weights(armature, tube):
    """The geometric method's weights (its answers on the tube are known exactly)."""
    import bpy

    select_only([armature, tube], active=armature)
    assert bpy.ops.autorig.skin_weights(skin_method="GEOMETRIC", skin_resolution=40) == {"FINISHED"}
    return group_weights(tube, [LOWER_BONE, UPPER_BONE])


def tube_with_loose_vertex(name="Stray"):
    """The tube plus one vertex in no face, far away (a vertex left behind in Edit Mode)."""
    import bpy

    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, BODY_HEIGHT, 24, 20, capped=True)
    obj = mesh_object(name, np.vstack([vertices, [FAR_AWAY]]), faces)
    bpy.context.view_layer.update()
    return obj


def test_a_far_stray_vertex_leaves_the_other_weights_unchanged(clean_scene, capfd):
    armature = make_armature()
    clean = skinned_weights(armature, unbound_cylinder("Clean"))
    stray = tube_with_loose_vertex()
    capfd.readouterr()
    weights = skinned_weights(armature, stray)
    assert ("'Stray': 1 stray vertex far from the rest of the mesh left out of the distances and weighted like the "
            "nearest kept vertex." in "".join(capfd.readouterr()))
    np.testing.assert_allclose(weights[:-1], clean, atol=1e-9)
    # The stray follows the nearest vertex of the tube: on the joint ring (z = 1), half on each bone.
    nearest = np.argmin(np.linalg.norm(local_positions(stray)[:-1] - FAR_AWAY, axis=1))
    assert local_positions(stray)[nearest].tolist() == pytest.approx([BODY_RADIUS, 0.0, 1.0])
    np.testing.assert_array_equal(weights[-1], weights[nearest])
    np.testing.assert_allclose(weights[-1], [0.5, 0.5], atol=1e-6)


def test_a_vertex_dragged_far_away_leaves_the_other_weights_almost_unchanged(clean_scene):
    import bpy

    armature = make_armature()
    clean = skinned_weights(armature, unbound_cylinder("Clean"))
    dragged = unbound_cylinder("Dragged")
    top_centre = len(dragged.data.vertices) - 1
    dragged.data.vertices[top_centre].co = (0.0, 0.0, 10000.0)
    bpy.context.view_layer.update()
    weights = skinned_weights(armature, dragged)
    # Its cap triangles go with it, so the rest differs only near the top, and by little.
    np.testing.assert_allclose(weights[:top_centre], clean[:top_centre], atol=1e-3)
    # It follows rigidly one vertex of the top ring it is joined to.
    top_ring = np.arange(20 * 24, 21 * 24)
    assert any(np.array_equal(weights[top_centre], weights[index]) for index in top_ring)
    assert weights[top_centre, 1] > 0.99


@pytest.mark.parametrize("value", [float("inf"), float("nan")])
def test_non_finite_vertex_is_refused_naming_the_object(armature_and_tube, value):
    import bpy

    armature, tube = armature_and_tube
    tube.data.vertices[5].co.x = value  # Blender stores inf as the float32 maximum
    bpy.context.view_layer.update()
    before = scene_state([armature, tube])
    message = ("'Tube' has a vertex at an infinite or undefined (NaN) position (index 5): move or delete it in Edit "
               "Mode first.")
    with pytest.raises(RuntimeError, match=f"^Error: {re.escape(message)}\n$"):
        bpy.ops.autorig.skin_weights(skin_resolution=32)
    assert scene_state([armature, tube]) == before


def test_skinning_works_in_weight_paint_and_pose_mode_and_says_why_not_in_edit_mode(armature_and_tube):
    import bpy

    armature, tube = armature_and_tube
    # Weight Paint Mode on the mesh, the armature selected (how riggers paint).
    select_only([armature, tube], active=tube)
    bpy.ops.object.mode_set(mode="WEIGHT_PAINT")
    assert bpy.ops.autorig.skin_weights(skin_method="GEOMETRIC", skin_resolution=32) == {"FINISHED"}
    assert tube.mode == "WEIGHT_PAINT"
    in_weight_paint = group_weights(tube, [LOWER_BONE, UPPER_BONE])
    bpy.ops.object.mode_set(mode="OBJECT")
    # Pose Mode on the armature, posed: the rest shape is what is weighted.
    select_only([armature, tube], active=armature)
    bpy.ops.object.mode_set(mode="POSE")
    armature.pose.bones[UPPER_BONE].rotation_quaternion = (0.7071068, 0.7071068, 0.0, 0.0)
    assert bpy.ops.autorig.skin_weights(skin_method="GEOMETRIC", skin_resolution=32) == {"FINISHED"}
    np.testing.assert_allclose(group_weights(tube, [LOWER_BONE, UPPER_BONE]), in_weight_paint, atol=1e-6)
    z = np.array([v.co.z for v in tube.data.vertices])
    assert in_weight_paint[z < 0.3, 0].min() > 0.9 and in_weight_paint[z > 1.7, 1].min() > 0.9
    bpy.ops.object.mode_set(mode="OBJECT")
    # Edit Mode: unavailable, with the reason.
    select_only([armature, tube], active=tube)
    bpy.ops.object.mode_set(mode="EDIT")
    with pytest.raises(RuntimeError, match=re.escape(
            "Operator bpy.ops.autorig.skin_weights.poll() Skin Weights needs Object, Pose or Weight Paint Mode: "
            "leave Edit Mode first")):
        bpy.ops.autorig.skin_weights()
    bpy.ops.object.mode_set(mode="OBJECT")
