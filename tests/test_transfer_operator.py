"""The weight transfer operators end to end on the reference scene, real bpy."""

import bpy
import numpy as np
import pytest

from autorig_addon.blender import convert
from autorig_addon.blender.operators.transfer import scene_defaults
from autorig_addon.core.transfer.transfer import VertexStatus
from blender_fixtures import (
    BLEND_END,
    BLEND_START,
    LOWER_BONE,
    UPPER_BONE,
    build_rig_scene,
    expected_body_weights,
    local_positions,
    mesh_object,
    scene_state,
    select_only,
)

BONES = [LOWER_BONE, UPPER_BONE]


@pytest.fixture
def rig(clean_scene):
    return build_rig_scene()


def sleeve_weights(rig):
    return convert.read_weights(rig.sleeve, BONES).matrix


def tube(rig):
    """Indices of the sleeve's tube vertices (the button excluded)."""
    return np.arange(rig.sleeve_ring_vertex_count)


def test_transfer_selected_sleeve_matches_body_weights(rig):
    select_only([rig.body, rig.sleeve], active=rig.body)
    assert bpy.ops.autorig.transfer_weights() == {"FINISHED"}

    weights = sleeve_weights(rig)
    z = local_positions(rig.sleeve)[:, 2]
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)
    lower_end = tube(rig)[z[tube(rig)] < BLEND_START - 0.05]
    upper_end = tube(rig)[z[tube(rig)] > BLEND_END + 0.05]
    assert len(lower_end) > 100 and len(upper_end) > 100
    assert weights[lower_end, 0].min() > 0.999
    assert weights[upper_end, 1].min() > 0.999
    # The sleeve sits 0.03 off the body, within the match distance: the
    # linear blend is copied (exactly, as the rings line up in height).
    np.testing.assert_allclose(weights[tube(rig)], expected_body_weights(z[tube(rig)]), atol=1e-3)

    status = convert.read_status_attribute(rig.sleeve)
    assert np.all(status[tube(rig)] == VertexStatus.COPIED)
    # The button floats 0.17 off the body: a part with no match, moving with
    # its closest body point (z = 0.4, all Lower).
    button = np.arange(rig.sleeve_ring_vertex_count, len(status))
    assert np.all(status[button] == VertexStatus.UNMATCHED_PART)
    np.testing.assert_allclose(weights[button], [[1.0, 0.0]] * len(button), atol=1e-6)

    assert rig.sleeve.parent == rig.armature
    assert [m.object for m in rig.sleeve.modifiers if m.type == "ARMATURE"] == [rig.armature]
    assert rig.sleeve.data.color_attributes.active_color_name == convert.STATUS_COLOR_ATTRIBUTE


def test_transfer_by_name_without_selection(rig):
    select_only([], active=None)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", max_influences=1) == {"FINISHED"}
    weights = sleeve_weights(rig)
    assert np.count_nonzero(weights, axis=1).max() == 1
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)


def test_scene_settings_become_operator_defaults(rig):
    settings = bpy.context.scene.autorig
    settings.source = rig.body
    settings.target = rig.sleeve
    settings.max_influences = 1
    settings.smoothing_iterations = 3
    select_only([], active=None)
    values = scene_defaults(bpy.context, lambda name: name == "smoothing_iterations")
    assert values["source"] == "Body" and values["targets"] == "Sleeve"
    assert values["max_influences"] == 1 and "smoothing_iterations" not in values
    assert bpy.ops.autorig.transfer_weights(**values) == {"FINISHED"}
    assert np.count_nonzero(sleeve_weights(rig), axis=1).max() == 1


def assert_fails_unchanged(rig, match, objects=None, **operator_arguments):
    objects = objects or [rig.body, rig.sleeve, rig.armature]
    before = scene_state(objects)
    with pytest.raises(RuntimeError, match=match):
        bpy.ops.autorig.transfer_weights(**operator_arguments)
    assert scene_state(objects) == before


def test_source_without_armature_fails_and_changes_nothing(rig):
    rig.body.modifiers.clear()
    rig.body.parent = None
    assert_fails_unchanged(rig, "'Body' is not bound to an armature", source="Body", targets="Sleeve")


def test_faceless_target_fails_before_any_target_is_written(rig):
    wire = mesh_object("Wire", [(0.35, 0, 0.5), (0.35, 0, 1.0)], [], edges=[(0, 1)])
    bpy.context.view_layer.update()
    objects = [rig.body, rig.sleeve, rig.armature, wire]
    # Sleeve comes first and would succeed: it must stay unweighted too.
    assert_fails_unchanged(rig, "'Wire' has no faces", objects, source="Body", targets="Sleeve,Wire")


def test_objects_far_apart_fail_and_change_nothing(rig):
    rig.sleeve.location = (50.0, 0.0, 0.0)
    bpy.context.view_layer.update()
    assert_fails_unchanged(rig, "Sleeve.* does not overlap the source", source="Body", targets="Sleeve")


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"source": "Body", "targets": "Body"}, "both the source and a target"),
        ({"source": "Body,Sleeve", "targets": "Sleeve"}, "Several sources"),
        ({"source": "Nobody", "targets": "Sleeve"}, "no object named 'Nobody'"),
        ({"source": "Armature", "targets": "Sleeve"}, "not a mesh"),
        ({"source": "Body", "targets": "Sleeve", "bones": "Spine"}, "Spine: not deform bones"),
        ({"source": "Body", "targets": ""}, "No target"),
    ],
)
def test_bad_input_reports_clear_errors(rig, arguments, message):
    select_only([rig.body], active=rig.body)
    assert_fails_unchanged(rig, message, **arguments)


def test_source_without_bone_weights_fails(rig):
    rig.body.vertex_groups.clear()
    rig.body.vertex_groups.new(name="Unrelated").add([0], 1.0, "REPLACE")
    assert_fails_unchanged(rig, "no weights for the deform bones", source="Body", targets="Sleeve")


def test_several_skinned_meshes_selected_is_ambiguous(rig):
    bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve")
    select_only([rig.body, rig.sleeve], active=None)
    assert_fails_unchanged(rig, "Several selected meshes are skinned")


def test_edit_mode_target_is_refused(rig):
    select_only([rig.sleeve], active=rig.sleeve)
    bpy.ops.object.mode_set(mode="EDIT")
    with pytest.raises(RuntimeError, match="'Sleeve' is in Edit Mode"):
        bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve")
    bpy.ops.object.mode_set(mode="OBJECT")
    assert len(rig.sleeve.vertex_groups) == 0


def test_create_mask_operator_adds_group_and_enters_weight_paint(rig):
    select_only([rig.sleeve], active=rig.sleeve)
    rig.sleeve.vertex_groups.new(name="Other")
    assert bpy.ops.autorig.create_transfer_mask() == {"FINISHED"}
    assert rig.sleeve.vertex_groups.active.name == "AutoRig Inpaint"
    assert rig.sleeve.mode == "WEIGHT_PAINT"
    assert bpy.ops.autorig.create_transfer_mask() == {"FINISHED"}  # no duplicate group
    assert [group.name for group in rig.sleeve.vertex_groups] == ["Other", "AutoRig Inpaint"]


def test_masked_band_is_inpainted_smoothly(rig):
    z = local_positions(rig.sleeve)[:, 2]
    band = tube(rig)[(z[tube(rig)] > BLEND_START - 0.05) & (z[tube(rig)] < BLEND_END + 0.05)]
    rig.sleeve.vertex_groups.new(name="AutoRig Inpaint").add(band.tolist(), 1.0, "REPLACE")
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}

    status = convert.read_status_attribute(rig.sleeve)
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
    # The mask group is not a bone: it survives the transfer.
    assert rig.sleeve.vertex_groups.get("AutoRig Inpaint") is not None


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
    assert np.all(convert.read_status_attribute(rig.sleeve)[protected] == VertexStatus.PROTECTED)
    free_lower = tube(rig)[(z[tube(rig)] > 0.55) & (z[tube(rig)] < BLEND_START - 0.05)]
    assert weights[free_lower, 0].min() > 0.99


def test_mix_blends_with_existing_weights(rig):
    preweight_sleeve_upper(rig)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", replace_mode="MIX", mix_factor=0.25) == {"FINISHED"}
    weights = sleeve_weights(rig)
    z = local_positions(rig.sleeve)[:, 2]
    lower_end = tube(rig)[z[tube(rig)] < BLEND_START - 0.05]
    # existing (0, 1) * 0.75 + transferred (1, 0) * 0.25
    np.testing.assert_allclose(weights[lower_end], [[0.25, 0.75]] * len(lower_end), atol=1e-6)


def test_replace_keeps_unrelated_groups_and_replace_all_removes_them(rig):
    rig.sleeve.vertex_groups.new(name="Pin").add([0, 1], 1.0, "REPLACE")
    bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", replace_mode="REPLACE")
    assert sorted(g.name for g in rig.sleeve.vertex_groups) == [LOWER_BONE, "Pin", UPPER_BONE]
    bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", replace_mode="REPLACE_ALL")
    assert sorted(g.name for g in rig.sleeve.vertex_groups) == [LOWER_BONE, UPPER_BONE]


def test_bone_subset_only_changes_chosen_bones(rig):
    preweight_sleeve_upper(rig)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", bones=LOWER_BONE) == {"FINISHED"}
    weights = sleeve_weights(rig)
    z = local_positions(rig.sleeve)[:, 2]
    lower_end = tube(rig)[z[tube(rig)] < BLEND_START - 0.05]
    upper_end = tube(rig)[z[tube(rig)] > BLEND_END + 0.05]
    # Lower gains weight 1 where the body has it; Upper keeps its existing 1;
    # rows are renormalised.
    np.testing.assert_allclose(weights[lower_end], [[0.5, 0.5]] * len(lower_end), atol=1e-6)
    np.testing.assert_allclose(weights[upper_end], [[0.0, 1.0]] * len(upper_end), atol=1e-6)


def test_selected_pose_bones_subset(rig):
    preweight_sleeve_upper(rig)
    for pose_bone in rig.armature.pose.bones:
        selected = pose_bone.name == LOWER_BONE
        if hasattr(pose_bone, "select"):
            pose_bone.select = selected
        else:
            pose_bone.bone.select = selected
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", bone_subset="SELECTED") == {"FINISHED"}
    z = local_positions(rig.sleeve)[:, 2]
    lower_end = tube(rig)[z[tube(rig)] < BLEND_START - 0.05]
    np.testing.assert_allclose(sleeve_weights(rig)[lower_end], [[0.5, 0.5]] * len(lower_end), atol=1e-6)


def test_running_again_with_new_options_replaces_cleanly(rig):
    """What the Adjust Last Operation panel does: the same transfer again, new options."""
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", max_influences=1) == {"FINISHED"}
    assert [m.type for m in rig.sleeve.modifiers].count("ARMATURE") == 1
    assert np.count_nonzero(sleeve_weights(rig), axis=1).max() == 1


class RecordingWindowManager:
    def __init__(self):
        self.calls = []

    def progress_begin(self, low, high):
        self.calls.append(("begin", low, high))

    def progress_update(self, value):
        self.calls.append(("update", value))

    def progress_end(self):
        self.calls.append(("end",))


class RecordingWorkspace:
    def __init__(self):
        self.texts = []

    def status_text_set(self, text):
        self.texts.append(text)


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
    VIEW3D_PT_autorig_skin.draw_settings(SimpleNamespace(), RecordingLayout(log), bpy.context.scene.autorig, bpy.context)
    assert {name for kind, name in log if kind == "prop"} == set(SKIN_OPTION_NAMES)
    assert ("operator", "autorig.skin_weights") in log
    assert ("label", f"Sleeve to {rig.armature.name}") in log
