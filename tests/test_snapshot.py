"""Undoing a failed write (autorig_addon.blender.snapshot), real bpy."""

import numpy as np
import pytest

from autorig_addon.blender import snapshot, status_attribute, weight_writer
from autorig_addon.core.types import Weights
from blender_fixtures import (
    LOWER_BONE,
    UPPER_BONE,
    box_geometry,
    build_rig_scene,
    group_weights,
    make_armature,
    mesh_object,
    scene_state,
)


def test_restored_on_failure_undoes_a_half_done_write(clean_scene, monkeypatch):
    rig = build_rig_scene()
    sleeve = rig.sleeve
    sleeve.vertex_groups.new(name=UPPER_BONE).add([0, 5], 0.4, "REPLACE")
    sleeve.vertex_groups.new(name="Pin").add([1], 1.0, "REPLACE")
    before = group_weights(sleeve, [UPPER_BONE, "Pin", LOWER_BONE])

    def broken_binding(obj, armature_obj, world=None):
        obj.modifiers.new("Half", "ARMATURE")
        raise RuntimeError("disk full")

    # The groups are written, then the binding fails half-way.
    monkeypatch.setattr(weight_writer, "ensure_armature_binding", broken_binding)
    weights = Weights(np.full((len(sleeve.data.vertices), 2), 0.5), (LOWER_BONE, UPPER_BONE))
    with pytest.raises(RuntimeError, match="disk full"):
        with snapshot.restored_on_failure([sleeve]):
            weight_writer.write_weights(sleeve, weights, rig.armature)

    assert [group.name for group in sleeve.vertex_groups] == [UPPER_BONE, "Pin"]
    np.testing.assert_allclose(group_weights(sleeve, [UPPER_BONE, "Pin", LOWER_BONE]), before)
    assert len(sleeve.modifiers) == 0 and sleeve.parent is None


def test_restored_on_failure_restores_every_object_and_keeps_successes(clean_scene):
    rig = build_rig_scene()
    before = scene_state([rig.body, rig.sleeve])
    body_weights = Weights(np.ones((len(rig.body.data.vertices), 1)), (LOWER_BONE,))
    with pytest.raises(ValueError, match="second write failed"):
        with snapshot.restored_on_failure([rig.body, rig.sleeve]):
            weight_writer.write_weights(rig.body, body_weights, rig.armature, replace_all=True)
            raise ValueError("second write failed")
    assert scene_state([rig.body, rig.sleeve]) == before

    with snapshot.restored_on_failure([rig.body]):
        weight_writer.write_weights(rig.body, body_weights, rig.armature, replace_all=True)
    assert [group.name for group in rig.body.vertex_groups] == [LOWER_BONE]


def test_snapshot_rebuilds_removed_armature_modifiers_with_their_settings(clean_scene):
    scene = build_rig_scene(with_button=False)
    body = scene.body
    body.modifiers.new("Smooth", "SUBSURF")
    extra = body.modifiers.new("Second", "ARMATURE")
    extra.object = scene.armature
    extra.use_deform_preserve_volume = True
    body.vertex_groups[LOWER_BONE].lock_weight = True
    body.vertex_groups.active_index = 1
    before = [(m.name, m.type) for m in body.modifiers]
    taken = snapshot.ObjectSnapshot.capture(body)
    weight_writer.ensure_armature_binding(body, make_armature("Other"))
    body.vertex_groups.clear()
    taken.restore()
    assert [(m.name, m.type) for m in body.modifiers] == before
    assert [m.object.name for m in body.modifiers if m.type == "ARMATURE"] == ["Armature", "Armature"]
    assert body.modifiers["Second"].use_deform_preserve_volume
    assert body.parent == scene.armature
    assert [(g.name, g.lock_weight) for g in body.vertex_groups] == [(LOWER_BONE, True), (UPPER_BONE, False)]
    assert body.vertex_groups.active_index == 1


def test_snapshot_restores_status_attributes_and_the_active_colour(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    box.data.color_attributes.new("Paint", "BYTE_COLOR", "CORNER")
    box.data.color_attributes.active_color_name = "Paint"
    first = np.arange(8) % 6
    status_attribute.write_status_attribute(box, first)
    taken = snapshot.ObjectSnapshot.capture(box)
    status_attribute.write_status_attribute(box, np.zeros(8, dtype=int))
    taken.restore()
    np.testing.assert_array_equal(status_attribute.read_status_attribute(box), first)
    assert box.data.color_attributes.active_color_name == status_attribute.STATUS_COLOR_ATTRIBUTE

    # A mesh that had no status gets none back.
    plain = mesh_object("Plain", vertices, faces)
    plain.data.color_attributes.new("Paint", "BYTE_COLOR", "CORNER")
    plain.data.color_attributes.active_color_name = "Paint"
    taken = snapshot.ObjectSnapshot.capture(plain)
    status_attribute.write_status_attribute(plain, first)
    taken.restore()
    assert status_attribute.read_status_attribute(plain) is None
    assert status_attribute.STATUS_COLOR_ATTRIBUTE not in plain.data.color_attributes
    assert plain.data.color_attributes.active_color_name == "Paint"
