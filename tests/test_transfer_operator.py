"""The weight transfer operators end to end on the reference scene, real bpy.

Weights are checked against the body's known linear blend (the sleeve's
rings line up in height with the body's, so copied weights are exact);
every refusal is checked for its exact message and an unchanged scene.
"""

import re

import bpy
import numpy as np
import pytest

from autorig_addon.blender import convert, status_attribute
from autorig_addon.blender.jobs import transfer as transfer_job
from autorig_addon.blender.operators.transfer import scene_defaults
from autorig_addon.blender.ui.properties import TRANSFER_OPTION_NAMES
from autorig_addon.core.errors import Cancelled, InputError
from autorig_addon.core.transfer.options import DEFAULT_MASK_GROUP
from autorig_addon.core.transfer.transfer import VertexStatus
from blender_fixtures import (
    BLEND_END,
    BLEND_START,
    COPY_TOLERANCE,
    LOWER_BONE,
    UPPER_BONE,
    RecordingWindowManager,
    RecordingWorkspace,
    build_rig_scene,
    cylinder_geometry,
    expected_body_weights,
    local_positions,
    mesh_object,
    scene_state,
    select_only,
)

pytestmark = pytest.mark.all_blenders

BONES = [LOWER_BONE, UPPER_BONE]
#: The operator's report for the reference sleeve: 544 tube vertices copied,
#: the 8 of the button (a part with no match) inpainted.
SLEEVE_REPORT = "Sleeve: 544 copied, 8 inpainted (1%), 8 on parts with no match"


@pytest.fixture
def rig(clean_scene):
    return build_rig_scene()


def sleeve_weights(rig):
    return convert.read_weights(rig.sleeve, BONES).matrix


def tube(rig):
    """Indices of the sleeve's tube vertices (the button excluded)."""
    return np.arange(rig.sleeve_ring_vertex_count)


def button(rig):
    """Indices of the button's vertices."""
    return np.arange(rig.sleeve_ring_vertex_count, len(rig.sleeve.data.vertices))


def tube_heights(rig):
    return local_positions(rig.sleeve)[tube(rig), 2]


def one_hot(weights):
    """Each row wholly to its largest bone."""
    return np.eye(weights.shape[1])[weights.argmax(axis=1)]


def test_transfer_selected_sleeve_matches_body_weights(rig, capfd):
    select_only([rig.body, rig.sleeve], active=rig.body)
    capfd.readouterr()
    assert bpy.ops.autorig.transfer_weights() == {"FINISHED"}
    assert f"Info: {SLEEVE_REPORT}" in "".join(capfd.readouterr())

    weights = sleeve_weights(rig)
    # The sleeve sits 0.03 off the body, within the match distance: the
    # linear blend is copied (exactly, as the rings line up in height).
    np.testing.assert_allclose(weights[tube(rig)], expected_body_weights(tube_heights(rig)), atol=COPY_TOLERANCE)
    status = status_attribute.read_status_attribute(rig.sleeve)
    assert np.all(status[tube(rig)] == VertexStatus.COPIED)
    # The button floats 0.17 off the body: a part with no match, moving with
    # its closest body point (z = 0.4, all Lower).
    assert np.all(status[button(rig)] == VertexStatus.UNMATCHED_PART)
    np.testing.assert_allclose(weights[button(rig)], [[1.0, 0.0]] * len(button(rig)), atol=1e-6)

    assert rig.sleeve.parent == rig.armature
    assert [m.object for m in rig.sleeve.modifiers if m.type == "ARMATURE"] == [rig.armature]
    assert rig.sleeve.data.color_attributes.active_color_name == status_attribute.STATUS_COLOR_ATTRIBUTE


def test_transfer_by_name_without_selection(rig):
    select_only([], active=None)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", max_influences=1) == {"FINISHED"}
    weights = sleeve_weights(rig)
    expected = expected_body_weights(tube_heights(rig))
    # One bone per vertex: the larger one (rings at z = 1.0 are a tie, either bone is right).
    decided = np.abs(expected[:, 0] - 0.5) > 1e-6
    assert (~decided).sum() == 32
    np.testing.assert_allclose(weights[tube(rig)][decided], one_hot(expected[decided]), atol=1e-6)
    np.testing.assert_allclose(weights[tube(rig)][~decided].max(axis=1), 1.0, atol=1e-6)
    np.testing.assert_array_equal(np.count_nonzero(weights, axis=1), 1)


def test_scene_settings_become_operator_defaults(rig):
    settings = bpy.context.scene.autorig
    settings.source = rig.body
    settings.target = rig.sleeve
    settings.max_influences = 1
    settings.smoothing_iterations = 3
    select_only([], active=None)
    values = scene_defaults(bpy.context, lambda name: name == "smoothing_iterations")
    expected = {name: getattr(settings, name) for name in TRANSFER_OPTION_NAMES if name != "smoothing_iterations"}
    assert values == {**expected, "source": "Body", "targets": "Sleeve"}
    assert values["mask_group"] == DEFAULT_MASK_GROUP
    assert bpy.ops.autorig.transfer_weights(**values) == {"FINISHED"}
    np.testing.assert_array_equal(np.count_nonzero(sleeve_weights(rig), axis=1), 1)


# --------------------------------------------------------------------------- refusals leave the scene unchanged


def assert_refused_unchanged(rig, message, objects=None, **operator_arguments):
    """The operator refuses with exactly ``message`` and changes nothing."""
    objects = objects or [rig.body, rig.sleeve, rig.armature]
    before = scene_state(objects)
    with pytest.raises(RuntimeError, match=f"^Error: {re.escape(message)}\n$"):
        bpy.ops.autorig.transfer_weights(**operator_arguments)
    assert scene_state(objects) == before


def test_source_without_armature_is_refused(rig):
    rig.body.modifiers.clear()
    rig.body.parent = None
    assert_refused_unchanged(
        rig, "'Body' is not bound to an armature: give it an Armature modifier or parent it to the armature "
        "(Ctrl+P > With Empty Groups) first.", source="Body", targets="Sleeve",
    )


def test_faceless_target_fails_before_any_target_is_written(rig):
    wire = mesh_object("Wire", [(0.35, 0, 0.5), (0.35, 0, 1.0)], [], edges=[(0, 1)])
    bpy.context.view_layer.update()
    # Sleeve comes first and would succeed: it must stay unweighted too.
    assert_refused_unchanged(
        rig, "'Wire' has no faces: it is only vertices or edges. Add faces to it (Edit Mode > Face > Fill) "
        "or pick a mesh with a surface.", [rig.body, rig.sleeve, rig.armature, wire], source="Body",
        targets="Sleeve,Wire",
    )


def test_objects_far_apart_are_refused(rig):
    rig.sleeve.location = (50.0, 0.0, 0.0)
    bpy.context.view_layer.update()
    assert_refused_unchanged(
        rig, "'Sleeve' does not overlap the source 'Body': move the garment onto the body (or apply the object "
        "transforms) before transferring.", source="Body", targets="Sleeve",
    )


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"source": "Body", "targets": "Body"},
         "'Body' is both the source and a target: pick a different mesh to weight."),
        ({"source": "Body,Sleeve", "targets": "Sleeve"},
         "Several sources were given (Body, Sleeve): transfer from one body at a time, or join the body meshes into "
         "one object first."),
        ({"source": "Nobody", "targets": "Sleeve"},
         "There is no object named 'Nobody'. Mesh objects here: Body, Sleeve."),
        ({"source": "Armature", "targets": "Sleeve"},
         "The source 'Armature' is not a mesh (its type is Armature): pick a mesh object."),
        ({"source": "Body", "targets": "Sleeve", "bones": "Spine"},
         "Spine: not deform bones of 'Armature'. Deform bones: Lower, Upper."),
        ({"source": "Body", "targets": ""},
         "No target: select the meshes to weight together with the source, or pass them by name "
         "(bpy.ops.autorig.transfer_weights(targets='Shirt,Trousers', ...))."),
    ],
)
def test_bad_input_is_refused_with_its_reason(rig, arguments, message):
    select_only([rig.body], active=rig.body)
    assert_refused_unchanged(rig, message, **arguments)


def test_source_without_bone_weights_is_refused(rig):
    rig.body.vertex_groups.clear()
    rig.body.vertex_groups.new(name="Unrelated").add([0], 1.0, "REPLACE")
    assert_refused_unchanged(
        rig, "'Body' has no weights for the deform bones of 'Armature': its vertex groups must be named after the "
        "bones. Skin it first.", source="Body", targets="Sleeve",
    )


def test_ambiguous_or_missing_source_is_refused(rig):
    select_only([], active=None)
    assert_refused_unchanged(
        rig, "No source: make the skinned body the active object or pass it by name "
        "(bpy.ops.autorig.transfer_weights(source='Body', ...)).",
    )
    bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve")
    select_only([rig.body, rig.sleeve], active=None)
    assert_refused_unchanged(
        rig, "Several selected meshes are skinned (Body, Sleeve): make the body the active object or pass it by "
        "name (bpy.ops.autorig.transfer_weights(source='Body', ...)).",
    )


def test_edit_mode_target_is_refused(rig):
    select_only([rig.sleeve], active=rig.sleeve)
    bpy.ops.object.mode_set(mode="EDIT")
    before = scene_state([rig.body, rig.sleeve, rig.armature])
    # The operator is unavailable, and Blender says why.
    with pytest.raises(RuntimeError, match=re.escape(
            "Operator bpy.ops.autorig.transfer_weights.poll() Transfer Weights needs Object, Pose or Weight Paint "
            "Mode: leave Edit Mode first")):
        bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve")
    # Called from Python with another object active, the plan refuses the target by name.
    bpy.context.view_layer.objects.active = rig.body
    with pytest.raises(InputError, match=re.escape(
            "'Sleeve' is in Edit Mode: switch to Object Mode so its edits are saved, then transfer.")):
        transfer_job.plan_transfer(rig.body, [rig.sleeve], transfer_job.TransferSettings(),
                                         bpy.context.evaluated_depsgraph_get())
    bpy.context.view_layer.objects.active = rig.sleeve
    assert scene_state([rig.body, rig.sleeve, rig.armature]) == before
    bpy.ops.object.mode_set(mode="OBJECT")
    assert len(rig.sleeve.vertex_groups) == 0


def test_cancelling_changes_nothing(rig, monkeypatch, capfd):
    def cancelled(plan, depsgraph, progress=None):
        raise Cancelled()

    monkeypatch.setattr(transfer_job, "compute_transfer", cancelled)
    before = scene_state([rig.body, rig.sleeve, rig.armature])
    capfd.readouterr()
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"CANCELLED"}
    assert "Warning: Weight transfer cancelled; nothing was changed." in "".join(capfd.readouterr())
    assert scene_state([rig.body, rig.sleeve, rig.armature]) == before


def test_a_failed_write_restores_every_target(rig, monkeypatch):
    vertices, faces = cylinder_geometry(0.35, 0.3, 0.6, 16, 3, capped=False)
    cuff = mesh_object("Cuff", vertices, faces)
    bpy.context.view_layer.update()
    written = []

    def fail_on_second(obj, status):
        written.append(obj.name)
        if len(written) == 2:
            raise OSError("disk full")

    monkeypatch.setattr(transfer_job, "write_status_attribute", fail_on_second)
    objects = [rig.body, rig.sleeve, rig.armature, cuff]
    before = scene_state(objects)
    # Not an input error: a failure of the environment propagates, after the restore.
    with pytest.raises(RuntimeError, match="OSError: disk full"):
        bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve,Cuff")
    assert written == ["Sleeve", "Cuff"]
    assert scene_state(objects) == before


# --------------------------------------------------------------------------- options


def test_create_mask_operator_adds_group_and_enters_weight_paint(rig, capfd):
    select_only([rig.sleeve], active=rig.sleeve)
    rig.sleeve.vertex_groups.new(name="Other")
    capfd.readouterr()
    assert bpy.ops.autorig.create_transfer_mask() == {"FINISHED"}
    assert ("Info: Paint 'AutoRig Inpaint' on 'Sleeve': painted vertices (weight 0.5 or more) will be inpainted."
            in "".join(capfd.readouterr()))
    assert rig.sleeve.vertex_groups.active.name == DEFAULT_MASK_GROUP == "AutoRig Inpaint"
    assert rig.sleeve.mode == "WEIGHT_PAINT"
    assert bpy.ops.autorig.create_transfer_mask() == {"FINISHED"}  # no duplicate group
    assert [group.name for group in rig.sleeve.vertex_groups] == ["Other", DEFAULT_MASK_GROUP]


def test_create_mask_without_a_group_name_is_refused(rig):
    bpy.context.scene.autorig.mask_group = "  "
    select_only([rig.sleeve], active=rig.sleeve)
    with pytest.raises(RuntimeError, match=r"^Error: No mask group name: set Inpaint Mask in the AutoRig panel\.\n$"):
        bpy.ops.autorig.create_transfer_mask()
    assert len(rig.sleeve.vertex_groups) == 0 and rig.sleeve.mode == "OBJECT"


def test_masked_band_is_inpainted_smoothly(rig):
    z = local_positions(rig.sleeve)[:, 2]
    band = tube(rig)[(z[tube(rig)] > BLEND_START - 0.05) & (z[tube(rig)] < BLEND_END + 0.05)]
    rig.sleeve.vertex_groups.new(name=DEFAULT_MASK_GROUP).add(band.tolist(), 1.0, "REPLACE")
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}

    status = status_attribute.read_status_attribute(rig.sleeve)
    assert np.all(status[band] == VertexStatus.MASKED)
    weights = sleeve_weights(rig)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)
    # Ring by ring up the band, the Lower weight falls from near 1 to near 0
    # through 0.5 at the middle (the smooth fill between the copied ends).
    heights = np.unique(np.round(z[band], 4))
    ring_lower = np.array([weights[band[np.isclose(z[band], h)], 0].mean() for h in heights])
    assert np.all(np.diff(ring_lower) < 0)
    assert ring_lower[0] > 0.85 and ring_lower[-1] < 0.15
    assert ring_lower[len(heights) // 2] == pytest.approx(0.5, abs=0.02)
    # Outside the band the weights are copied exactly.
    outside = np.setdiff1d(tube(rig), band)
    np.testing.assert_allclose(weights[outside], expected_body_weights(z[outside]), atol=COPY_TOLERANCE)
    # The mask group is not a bone: it survives the transfer.
    assert rig.sleeve.vertex_groups.get(DEFAULT_MASK_GROUP) is not None


def preweight_sleeve_upper(rig):
    group = rig.sleeve.vertex_groups.new(name=UPPER_BONE)
    group.add(list(range(len(rig.sleeve.data.vertices))), 1.0, "REPLACE")


def test_protected_vertices_keep_their_weights(rig):
    preweight_sleeve_upper(rig)
    z = local_positions(rig.sleeve)[:, 2]
    protected = tube(rig)[z[tube(rig)] < 0.5]
    rig.sleeve.vertex_groups.new(name="Keep").add(protected.tolist(), 1.0, "REPLACE")
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", protect_group="Keep") == {"FINISHED"}
    weights = sleeve_weights(rig)
    np.testing.assert_allclose(weights[protected], [[0.0, 1.0]] * len(protected), atol=1e-6)
    assert np.all(status_attribute.read_status_attribute(rig.sleeve)[protected] == VertexStatus.PROTECTED)
    # Away from the protected rings the body's weights are copied.
    free = tube(rig)[z[tube(rig)] > 0.55]
    np.testing.assert_allclose(weights[free], expected_body_weights(z[free]), atol=COPY_TOLERANCE)


def test_mix_blends_with_existing_weights(rig):
    preweight_sleeve_upper(rig)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", replace_mode="MIX",
                                            mix_factor=0.25) == {"FINISHED"}
    # existing (0, 1) * 0.75 + transferred (body weights) * 0.25, everywhere on the tube
    expected = 0.75 * np.array([0.0, 1.0]) + 0.25 * expected_body_weights(tube_heights(rig))
    np.testing.assert_allclose(sleeve_weights(rig)[tube(rig)], expected, atol=1e-3)


def test_replace_keeps_unrelated_groups_and_replace_all_removes_them(rig):
    rig.sleeve.vertex_groups.new(name="Pin").add([0, 1], 1.0, "REPLACE")
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", replace_mode="REPLACE") == {"FINISHED"}
    assert sorted(g.name for g in rig.sleeve.vertex_groups) == [LOWER_BONE, "Pin", UPPER_BONE]
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", replace_mode="REPLACE_ALL") == {"FINISHED"}
    assert sorted(g.name for g in rig.sleeve.vertex_groups) == [LOWER_BONE, UPPER_BONE]
    np.testing.assert_allclose(sleeve_weights(rig)[tube(rig)], expected_body_weights(tube_heights(rig)),
                               atol=COPY_TOLERANCE)


def test_bone_subset_only_changes_chosen_bones(rig):
    preweight_sleeve_upper(rig)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", bones=LOWER_BONE) == {"FINISHED"}
    # Lower takes the body's Lower weight, Upper keeps its existing 1, rows renormalised.
    lower = expected_body_weights(tube_heights(rig))[:, 0]
    expected = np.column_stack([lower, np.ones_like(lower)]) / (1.0 + lower)[:, None]
    np.testing.assert_allclose(sleeve_weights(rig)[tube(rig)], expected, atol=COPY_TOLERANCE)


def test_selected_pose_bones_subset(rig):
    preweight_sleeve_upper(rig)
    for pose_bone in rig.armature.pose.bones:
        selected = pose_bone.name == LOWER_BONE
        if hasattr(pose_bone, "select"):
            pose_bone.select = selected
        else:
            pose_bone.bone.select = selected
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", bone_subset="SELECTED") == {"FINISHED"}
    z = tube_heights(rig)
    lower_end = z < BLEND_START - 0.05
    np.testing.assert_allclose(sleeve_weights(rig)[tube(rig)][lower_end], [[0.5, 0.5]] * int(lower_end.sum()),
                               atol=1e-6)


def test_running_again_with_new_options_replaces_cleanly(rig):
    """What the Adjust Last Operation panel does: the same transfer again, new options."""
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", max_influences=1) == {"FINISHED"}
    assert [m.type for m in rig.sleeve.modifiers].count("ARMATURE") == 1
    assert sorted(g.name for g in rig.sleeve.vertex_groups) == BONES
    np.testing.assert_array_equal(np.count_nonzero(sleeve_weights(rig), axis=1), 1)


def test_blender_progress_reports_and_always_cleans_up():
    from types import SimpleNamespace

    from autorig_addon.blender.progress import PROGRESS_STEPS, blender_progress
    from autorig_addon.core.errors import Cancelled

    context = SimpleNamespace(window_manager=RecordingWindowManager(), workspace=RecordingWorkspace())
    echoed = []
    with pytest.raises(Cancelled):
        with blender_progress(context, "Transfer weights", echo=lambda f, m: echoed.append((f, m))) as progress:
            progress(0.25, "Matching")
            raise Cancelled()
    assert context.window_manager.calls == [("begin", 0, PROGRESS_STEPS), ("update", PROGRESS_STEPS // 4), ("end",)]
    assert context.workspace.texts == ["Transfer weights: Matching (25%)", None]
    assert echoed == [(0.25, "Matching")]

    headless = SimpleNamespace(window_manager=None, workspace=None)
    with blender_progress(headless, "Transfer weights") as progress:
        progress(1.0, "Done")  # nothing to show it on: must simply not fail


class RecordingLayout:
    """Stands in for bpy.types.UILayout: records what a panel draws and
    checks every property it names exists."""

    def __init__(self, log):
        self.log = log
        self.use_property_split = self.use_property_decorate = self.active = False

    def column(self, align=False):
        return RecordingLayout(self.log)

    row = column

    def prop(self, data, name, **_):
        assert hasattr(data, name), name
        self.log.append(("prop", name))

    def prop_search(self, data, name, search_data, search_name, **_):
        assert hasattr(data, name) and hasattr(search_data, search_name), name
        self.log.append(("prop", name))

    def operator(self, idname, **_):
        self.log.append(("operator", idname))

    def label(self, text="", **_):
        self.log.append(("label", text))


def test_transfer_panel_draws_every_setting_and_the_buttons(rig):
    from types import SimpleNamespace

    from autorig_addon.blender.ui.panels import VIEW3D_PT_autorig_transfer
    from autorig_addon.blender.ui.properties import TRANSFER_OPTION_NAMES

    select_only([rig.body, rig.sleeve], active=rig.sleeve)
    bpy.context.scene.autorig.source = rig.body
    log = []
    layout = RecordingLayout(log)
    VIEW3D_PT_autorig_transfer.draw_settings(SimpleNamespace(), layout, bpy.context.scene.autorig, bpy.context)
    drawn = {name for kind, name in log if kind == "prop"}
    # Either the fraction or the absolute distance shows, never both.
    assert drawn == {"source", "target", *TRANSFER_OPTION_NAMES} - {"max_distance"}
    assert ("operator", "autorig.transfer_weights") in log and ("operator", "autorig.create_transfer_mask") in log
    assert ("label", "Targets: Sleeve") in log


def test_skin_panel_draws_every_skin_setting_and_the_button(rig):
    from types import SimpleNamespace

    from autorig_addon.blender.ui.panels import VIEW3D_PT_autorig_skin
    from autorig_addon.blender.ui.properties import SKIN_OPTION_NAMES

    select_only([rig.armature, rig.sleeve], active=rig.armature)
    log = []
    VIEW3D_PT_autorig_skin.draw_settings(SimpleNamespace(), RecordingLayout(log), bpy.context.scene.autorig,
                                         bpy.context)
    assert {name for kind, name in log if kind == "prop"} == set(SKIN_OPTION_NAMES)
    assert ("operator", "autorig.skin_weights") in log
    assert ("label", f"Sleeve to {rig.armature.name}") in log


# --------------------------------------------------------------------------- strays, non-finite positions, modes

#: Where a stray vertex lands: 10 km off the character.
FAR_AWAY = (10000.0, 0.0, 0.5)


def add_loose_vertex(obj, position=FAR_AWAY):
    """One more vertex in no face (a vertex left behind in Edit Mode)."""
    obj.data.vertices.add(1)
    obj.data.vertices[-1].co = position
    obj.data.update()
    bpy.context.view_layer.update()


def test_a_stray_vertex_on_the_target_leaves_the_other_weights_unchanged(rig, capfd):
    add_loose_vertex(rig.sleeve)
    capfd.readouterr()
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}
    assert (f"Info: {SLEEVE_REPORT}; 1 stray vertex far from the rest of the mesh left out of the transfer and "
            "weighted like the nearest kept vertex\n" in "".join(capfd.readouterr()))
    weights = sleeve_weights(rig)
    np.testing.assert_allclose(weights[tube(rig)], expected_body_weights(tube_heights(rig)), atol=COPY_TOLERANCE)
    # The stray follows its nearest sleeve vertex, at z = 0.5: all Lower.
    np.testing.assert_allclose(weights[-1], [1.0, 0.0], atol=1e-6)
    assert status_attribute.read_status_attribute(rig.sleeve)[-1] == VertexStatus.UNMATCHED_PART


def test_a_stray_vertex_on_the_source_changes_nothing(rig, capfd):
    add_loose_vertex(rig.body)
    rig.body.vertex_groups[LOWER_BONE].add([len(rig.body.data.vertices) - 1], 1.0, "REPLACE")
    capfd.readouterr()
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}
    assert (f"Info: {SLEEVE_REPORT}; source 'Body': 1 stray vertex far from the rest of the mesh left out of the "
            "matching: no weight is copied from it\n" in "".join(capfd.readouterr()))
    # The source's stray keeps its own weight.
    stray = len(rig.body.data.vertices) - 1
    np.testing.assert_allclose(convert.read_weights(rig.body, BONES).matrix[stray], [1.0, 0.0])
    np.testing.assert_allclose(sleeve_weights(rig)[tube(rig)], expected_body_weights(tube_heights(rig)),
                               atol=COPY_TOLERANCE)


@pytest.mark.parametrize("which", ["Body", "Sleeve"])
@pytest.mark.parametrize("value", [float("inf"), float("nan")])
def test_a_non_finite_vertex_is_refused_naming_its_object(rig, which, value):
    bpy.data.objects[which].data.vertices[3].co.z = value  # Blender stores inf as the float32 maximum
    bpy.context.view_layer.update()
    assert_refused_unchanged(
        rig, f"'{which}' has a vertex at an infinite or undefined (NaN) position (index 3): move or delete it in "
        "Edit Mode first.", source="Body", targets="Sleeve",
    )


def test_transfer_works_in_weight_paint_and_pose_mode(rig):
    select_only([rig.sleeve], active=rig.sleeve)
    bpy.ops.object.mode_set(mode="WEIGHT_PAINT")
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}
    assert rig.sleeve.mode == "WEIGHT_PAINT"
    np.testing.assert_allclose(sleeve_weights(rig)[tube(rig)], expected_body_weights(tube_heights(rig)),
                               atol=COPY_TOLERANCE)
    bpy.ops.object.mode_set(mode="OBJECT")
    rig.sleeve.vertex_groups.clear()
    # The armature in Pose Mode and posed: weights still come from the rest shape.
    select_only([rig.armature], active=rig.armature)
    bpy.ops.object.mode_set(mode="POSE")
    rig.armature.pose.bones[UPPER_BONE].rotation_quaternion = (0.7071068, 0.7071068, 0.0, 0.0)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}
    np.testing.assert_allclose(sleeve_weights(rig)[tube(rig)], expected_body_weights(tube_heights(rig)),
                               atol=COPY_TOLERANCE)
    bpy.ops.object.mode_set(mode="OBJECT")


def test_a_bone_subset_that_leaves_vertices_empty_is_refused(rig):
    """Only Upper on a sleeve with no weights: the lower end (all Lower on
    the body) would get no weight at all."""
    z = tube_heights(rig)
    # The tube's lower end, plus the button, inpainted from the Lower part around it.
    empty = int(np.count_nonzero(expected_body_weights(z)[:, 1] == 0)) + len(button(rig))
    assert empty == 200
    assert_refused_unchanged(
        rig, f"{empty} vertices of 'Sleeve' get no weight from the chosen bones: "
        "transfer all bones or select the bones that cover them.",
        source="Body", targets="Sleeve", bones=UPPER_BONE)


def test_a_bone_subset_keeps_existing_weights_where_it_gives_none(rig):
    # Lower end: all Lower on the body, existing all Upper: replacing Upper alone
    # would leave nothing; the existing Upper weight stays.
    preweight_sleeve_upper(rig)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", bones=UPPER_BONE) == {"FINISHED"}
    z = tube_heights(rig)
    expected = expected_body_weights(z)
    weights = sleeve_weights(rig)[tube(rig)]
    lower_only = expected[:, 1] == 0
    np.testing.assert_allclose(weights[lower_only], [[0.0, 1.0]] * int(lower_only.sum()), atol=1e-6)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)
