"""Writing weights into vertex groups and binding to the armature
(autorig_addon.blender.weight_writer), real bpy."""

import math
import re

import bpy
import numpy as np
import pytest
from mathutils import Euler

from autorig_addon.blender import convert, weight_writer
from autorig_addon.core.errors import InputError
from autorig_addon.core.types import Weights
from blender_fixtures import (
    LOWER_BONE,
    UPPER_BONE,
    box_geometry,
    build_rig_scene,
    group_weights,
    make_armature,
    mesh_object,
)


def random_weights(vertex_count, names, seed=0):
    rng = np.random.default_rng(seed)
    matrix = rng.random((vertex_count, len(names)))
    matrix[rng.random(matrix.shape) < 0.3] = 0.0
    return Weights(matrix, names)


def member_weights(obj, name):
    """{vertex index: weight} of the members of group ``name``, read element by element."""
    index = obj.vertex_groups[name].index
    return {v.index: e.weight for v in obj.data.vertices for e in v.groups if e.group == index}


def test_fill_groups_stores_exact_weights_and_keeps_order_lock_and_active(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    first = box.vertex_groups.new(name="First")
    first.add([0, 1], 0.5, "REPLACE")
    first.lock_weight = True
    box.vertex_groups.new(name="Mask").add([7], 1.0, "REPLACE")
    box.vertex_groups.active_index = 1
    box.data.color_attributes.new("Paint", "FLOAT_COLOR", "POINT")
    box.data.attributes.active = box.data.attributes["Paint"]
    attributes_before = sorted(attribute.name for attribute in box.data.attributes)
    third = np.float32(1.0) / np.float32(3.0)
    weight_writer.fill_groups(box, {
        "New": np.array([0.0, 0.25, 0.0, 1e-7, 0.0, 0.0, -0.5, 2.0]),
        "First": np.array([third, 0, 0, 0, 0, 0, 0.75, 0]),
    })
    # Refilled in place (first, still locked), new groups appended, the active group unchanged.
    assert [group.name for group in box.vertex_groups] == ["First", "Mask", "New"]
    assert box.vertex_groups["First"].lock_weight and not box.vertex_groups["New"].lock_weight
    assert box.vertex_groups.active.name == "Mask"
    # Exactly the float32 values; zero and negative weights are not members.
    assert member_weights(box, "First") == {0: third, 6: 0.75}
    assert member_weights(box, "New") == {1: 0.25, 3: np.float32(1e-7), 7: 2.0}
    assert member_weights(box, "Mask") == {7: 1.0}
    # No temporary attribute is left, and the active attribute is the same.
    assert sorted(attribute.name for attribute in box.data.attributes) == attributes_before
    assert box.data.attributes.active.name == "Paint"


def test_fill_groups_moves_a_refilled_group_back_between_others(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    for name in ("A", "B", "C", "D"):
        box.vertex_groups.new(name=name).add([0], 0.5, "REPLACE")
    weight_writer.fill_groups(box, {"B": np.full(8, 0.25), "A": np.zeros(8)})
    assert [group.name for group in box.vertex_groups] == ["A", "B", "C", "D"]
    assert member_weights(box, "A") == {}
    assert member_weights(box, "B") == {i: 0.25 for i in range(8)}
    assert member_weights(box, "C") == {0: 0.5}


def test_write_weights_round_trip_preserves_other_groups_and_skips_zeros(clean_scene):
    rig = build_rig_scene()
    sleeve = rig.sleeve
    keep = sleeve.vertex_groups.new(name="Keep")
    keep.add([0, 1, 2], 0.75, "REPLACE")
    stale = sleeve.vertex_groups.new(name=LOWER_BONE)
    stale.add(list(range(len(sleeve.data.vertices))), 0.1, "REPLACE")
    weights = random_weights(len(sleeve.data.vertices), (LOWER_BONE, UPPER_BONE))

    weight_writer.write_weights(sleeve, weights, rig.armature)

    read_back = convert.read_weights(sleeve, weights.bone_names).matrix
    np.testing.assert_allclose(read_back, weights.matrix, atol=1e-6)
    lower_index = sleeve.vertex_groups[LOWER_BONE].index
    members = sum(any(g.group == lower_index for g in v.groups) for v in sleeve.data.vertices)
    assert members == np.count_nonzero(weights.matrix[:, 0])  # zeros (and the stale 0.1) are gone
    np.testing.assert_allclose(group_weights(sleeve, ["Keep"])[:3, 0], 0.75)
    assert group_weights(sleeve, ["Keep"])[3:].sum() == 0.0


def test_write_weights_never_writes_non_deform_or_unknown_bones(clean_scene):
    armature = make_armature(deform_upper=False)
    vertices, faces = box_geometry((0.0, 0.0, 0.5), 0.3)
    box = mesh_object("Box", vertices, faces)
    weights = Weights(np.full((8, 3), 1.0 / 3.0), (LOWER_BONE, UPPER_BONE, "NotABone"))
    weight_writer.write_weights(box, weights, armature)
    assert [group.name for group in box.vertex_groups] == [LOWER_BONE]
    np.testing.assert_allclose(group_weights(box, [LOWER_BONE])[:, 0], 1.0 / 3.0, atol=1e-7)


def test_write_weights_replace_all_keeps_only_listed_groups(clean_scene):
    rig = build_rig_scene()
    for name in ("Pin", "AutoRig Inpaint"):
        rig.sleeve.vertex_groups.new(name=name).add([0], 1.0, "REPLACE")
    weights = random_weights(len(rig.sleeve.data.vertices), (LOWER_BONE, UPPER_BONE))
    weight_writer.write_weights(rig.sleeve, weights, rig.armature, replace_all=True, keep_groups=["AutoRig Inpaint"])
    assert sorted(group.name for group in rig.sleeve.vertex_groups) == ["AutoRig Inpaint", LOWER_BONE, UPPER_BONE]
    assert group_weights(rig.sleeve, ["AutoRig Inpaint"])[0, 0] == 1.0


def test_write_weights_binds_once_and_keeps_world_transform(clean_scene):
    rig = build_rig_scene()
    rig.armature.location = (0.0, 1.0, 0.0)
    rig.armature.rotation_euler = Euler((0.0, 0.0, math.radians(30)))
    sleeve = rig.sleeve
    sleeve.location = (0.2, 0.1, -0.3)
    sleeve.scale = (1.5, 1.5, 1.5)
    sleeve.modifiers.new("Smooth", "SUBSURF")
    bpy.context.view_layer.update()
    world_before = np.array(sleeve.matrix_world)
    weights = random_weights(len(sleeve.data.vertices), (LOWER_BONE, UPPER_BONE))

    weight_writer.write_weights(sleeve, weights, rig.armature)
    weight_writer.write_weights(sleeve, weights, rig.armature)
    bpy.context.view_layer.update()

    armature_modifiers = [m for m in sleeve.modifiers if m.type == "ARMATURE"]
    assert [(m.name, m.object) for m in armature_modifiers] == [(weight_writer.ARMATURE_MODIFIER_NAME, rig.armature)]
    assert sleeve.modifiers[0].type == "ARMATURE"  # deforms before the subdivision
    assert sleeve.parent == rig.armature
    np.testing.assert_allclose(np.array(sleeve.matrix_world), world_before, atol=1e-6)


def test_rebinding_retargets_one_modifier_and_removes_the_others(clean_scene):
    scene = build_rig_scene(with_button=False)
    other = make_armature("Other")
    extra = scene.body.modifiers.new("Second", "ARMATURE")
    extra.object = scene.armature
    weight_writer.ensure_armature_binding(scene.body, other)
    assert [(m.name, m.type, m.object.name) for m in scene.body.modifiers] == [("Armature", "ARMATURE", "Other")]
    assert scene.body.parent == other


def test_write_weights_refuses_bad_input_before_changing_anything(clean_scene):
    rig = build_rig_scene()
    groups_before = [group.name for group in rig.sleeve.vertex_groups]
    with pytest.raises(InputError, match=re.escape(
            "'Sleeve' has 552 vertices but the weights have 3 rows; "
            "the mesh changed since the weights were computed.")):
        weight_writer.write_weights(rig.sleeve, Weights(np.ones((3, 1)), (LOWER_BONE,)), rig.armature)
    with pytest.raises(InputError, match=re.escape(
            "The target 'Armature' is not a mesh (its type is Armature): pick a mesh object.")):
        weight_writer.write_weights(rig.armature, Weights(np.ones((3, 1)), (LOWER_BONE,)), rig.armature)
    with pytest.raises(InputError, match="^'Body' is not an armature object.$"):
        weight_writer.write_weights(rig.sleeve, Weights(np.ones((552, 1)), (LOWER_BONE,)), rig.body)
    assert [group.name for group in rig.sleeve.vertex_groups] == groups_before
    assert len(rig.sleeve.modifiers) == 0 and rig.sleeve.parent is None


def test_binding_replaces_a_bone_parent_keeping_the_world_transform(clean_scene):
    from blender_fixtures import evaluated_world_vertices, parent_to_bone

    rig = build_rig_scene()
    parent_to_bone(rig.sleeve, rig.armature, UPPER_BONE)
    before = evaluated_world_vertices(rig.sleeve)
    weights = random_weights(len(rig.sleeve.data.vertices), (LOWER_BONE, UPPER_BONE))
    weight_writer.write_weights(rig.sleeve, weights, rig.armature)
    bpy.context.view_layer.update()
    # Carried by the Armature modifier only: never also by the bone.
    assert (rig.sleeve.parent, rig.sleeve.parent_type, rig.sleeve.parent_bone) == (rig.armature, "OBJECT", "")
    np.testing.assert_allclose(evaluated_world_vertices(rig.sleeve), before, atol=1e-6)


def test_fill_groups_in_reverse_order_keeps_weights_order_lock_and_active(clean_scene):
    """Existing groups in the reverse of the written order: every group is
    rebuilt in place, kept ones with their exact weights."""
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    names = ["D", "Keep", "C", "B", "A"]
    for number, name in enumerate(names):
        box.vertex_groups.new(name=name).add([number], 0.125 * (number + 1), "REPLACE")
    box.vertex_groups["Keep"].lock_weight = True
    box.vertex_groups["C"].lock_weight = True
    box.vertex_groups.active_index = box.vertex_groups["Keep"].index
    third = float(np.float32(1.0) / np.float32(3.0))
    weight_writer.fill_groups(box, {name: np.full(8, third) for name in ("A", "B", "C", "D")})
    assert [group.name for group in box.vertex_groups] == names
    assert [group.lock_weight for group in box.vertex_groups] == [False, True, True, False, False]
    assert box.vertex_groups.active.name == "Keep"
    assert member_weights(box, "Keep") == {1: 0.25}
    for name in ("A", "B", "C", "D"):
        assert member_weights(box, name) == {i: third for i in range(8)}
    assert not any(a.name.startswith("autorig_group_") for a in box.data.attributes)


def test_a_failed_conversion_leaves_no_temporary_attribute(clean_scene, monkeypatch):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    attributes_before = sorted(attribute.name for attribute in box.data.attributes)

    class FailingGeometryOps:
        @staticmethod
        def attribute_convert(**_):
            raise RuntimeError("Error: conversion failed\n")

    monkeypatch.setattr(weight_writer.bpy.ops, "geometry", FailingGeometryOps)
    with pytest.raises(RuntimeError, match="conversion failed"):
        weight_writer.fill_groups(box, {"A": np.full(8, 0.5)})
    assert sorted(attribute.name for attribute in box.data.attributes) == attributes_before
