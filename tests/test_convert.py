"""Blender <-> array conversion (autorig_addon.blender.convert), real bpy."""

import math

import bpy
import numpy as np
import pytest
from mathutils import Euler, Vector

from autorig_addon.blender import convert
from autorig_addon.core.errors import InputError
from autorig_addon.core.types import Weights
from blender_fixtures import (
    LOWER_BONE,
    UPPER_BONE,
    add_weights,
    bind,
    box_geometry,
    build_rig_scene,
    group_weights,
    local_positions,
    make_armature,
    mesh_object,
)

TRANSFORM_LOCATION = (1.0, -2.0, 0.5)
TRANSFORM_ROTATION = (0.3, -0.7, 1.1)
TRANSFORM_SCALE = (2.0, 1.0, 0.5)


def transformed_box(name="Box", scale=TRANSFORM_SCALE):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    obj = mesh_object(name, vertices, faces)
    obj.location = TRANSFORM_LOCATION
    obj.rotation_euler = Euler(TRANSFORM_ROTATION)
    obj.scale = scale
    bpy.context.view_layer.update()
    return obj


def world_positions(obj):
    matrix = obj.matrix_world
    return np.array([list(matrix @ Vector(co)) for co in local_positions(obj)])


def signed_volume(vertices, triangles):
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


def test_read_mesh_is_world_space_triangulated_in_vertex_order(clean_scene):
    box = transformed_box()
    mesh = convert.read_mesh(box)
    np.testing.assert_allclose(mesh.vertices, world_positions(box), atol=1e-5)
    assert mesh.triangles.shape == (12, 3)
    # Each quad is cut into two triangles that keep the quad's polygon index.
    np.testing.assert_array_equal(np.bincount(mesh.triangle_polygons), np.full(6, 2))
    assert mesh.object_names == ("Box",)
    # Outward winding survives the transform: the volume is positive and equals
    # the box volume times the scale determinant.
    assert signed_volume(mesh.vertices, mesh.triangles) == pytest.approx(1.0 * 2.0 * 1.0 * 0.5, rel=1e-5)


def test_read_mesh_keeps_outward_winding_under_mirroring(clean_scene):
    box = transformed_box(scale=(-1.0, 1.0, 1.0))
    mesh = convert.read_mesh(box)
    assert signed_volume(mesh.vertices, mesh.triangles) == pytest.approx(1.0, rel=1e-5)


def test_read_mesh_concatenates_objects_with_offsets(clean_scene):
    first = transformed_box("First")
    vertices, faces = box_geometry((5.0, 0.0, 0.0), 0.25)
    second = mesh_object("Second", vertices, faces)
    bpy.context.view_layer.update()
    mesh = convert.read_mesh([first, second])
    assert mesh.object_names == ("First", "Second")
    np.testing.assert_array_equal(mesh.object_offsets, [0, 8, 16])
    np.testing.assert_allclose(mesh.vertices[mesh.object_slice(1)], vertices, atol=1e-6)
    assert mesh.triangles[12:].min() == 8 and mesh.triangles[:12].max() == 7


def test_read_mesh_uses_deformed_geometry_when_vertex_count_is_kept(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    displace = box.modifiers.new("Lift", "DISPLACE")
    displace.direction = "Z"
    displace.mid_level = 0.0
    displace.strength = 0.25  # no texture: every vertex moves by strength * (1 - mid_level)
    bpy.context.view_layer.update()
    np.testing.assert_allclose(convert.read_mesh(box).vertices, vertices + [0.0, 0.0, 0.25], atol=1e-6)

    subdivision = box.modifiers.new("Smooth", "SUBSURF")
    subdivision.levels = 1
    box.modifiers.remove(displace)
    bpy.context.view_layer.update()
    mesh = convert.read_mesh(box)
    # Subdivision adds vertices, so the undeformed original is read to keep 1:1 indices.
    assert mesh.vertex_count == 8
    np.testing.assert_allclose(mesh.vertices, vertices, atol=1e-6)


def test_read_mesh_rejects_non_meshes_and_faceless_meshes(clean_scene):
    armature = make_armature()
    with pytest.raises(InputError, match="'Armature' is not a mesh \\(its type is Armature\\)"):
        convert.read_mesh(armature)
    wire = mesh_object("Wire", [(0, 0, 0), (1, 0, 0), (1, 1, 0)], [], edges=[(0, 1), (1, 2)])
    with pytest.raises(InputError, match="'Wire' has no faces"):
        convert.read_mesh(wire)


def test_read_skeleton_world_space_parents_first(clean_scene):
    armature = make_armature(deform_upper=False)
    armature.location = (0.5, 0.0, 1.0)
    armature.scale = (2.0, 2.0, 2.0)
    bpy.context.view_layer.update()
    skeleton = convert.read_skeleton(armature)
    assert skeleton.names == (LOWER_BONE, UPPER_BONE)
    np.testing.assert_array_equal(skeleton.parents, [-1, 0])
    np.testing.assert_allclose(skeleton.joints, [[0.5, 0.0, 1.0], [0.5, 0.0, 3.0]], atol=1e-6)
    np.testing.assert_allclose(skeleton.tails, [[0.5, 0.0, 3.0], [0.5, 0.0, 5.0]], atol=1e-6)
    np.testing.assert_array_equal(skeleton.deform, [True, False])


def test_read_skeleton_orders_parents_before_children(clean_scene):
    data = bpy.data.armatures.new("Chain")
    armature = bpy.data.objects.new("Chain", data)
    bpy.context.scene.collection.objects.link(armature)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    # Created children first, so storage order need not be parents first.
    tip = data.edit_bones.new("Tip")
    tip.head, tip.tail = (0, 0, 2), (0, 0, 3)
    middle = data.edit_bones.new("Middle")
    middle.head, middle.tail = (0, 0, 1), (0, 0, 2)
    root = data.edit_bones.new("Root")
    root.head, root.tail = (0, 0, 0), (0, 0, 1)
    tip.parent, middle.parent = middle, root
    bpy.ops.object.mode_set(mode="OBJECT")
    skeleton = convert.read_skeleton(armature)
    assert skeleton.names == ("Root", "Middle", "Tip")
    np.testing.assert_array_equal(skeleton.parents, [-1, 0, 1])
    np.testing.assert_allclose(skeleton.joints[:, 2], [0.0, 1.0, 2.0], atol=1e-6)


def test_find_armature_from_modifier_or_parent(clean_scene):
    rig = build_rig_scene()
    assert convert.find_armature(rig.body) == rig.armature
    rig.body.modifiers.clear()
    assert convert.find_armature(rig.body) == rig.armature  # still the parent
    with pytest.raises(InputError, match="'Sleeve' is not bound to an armature"):
        convert.find_armature(rig.sleeve)


def test_read_weights_matches_groups_and_fills_missing_with_zero(clean_scene):
    rig = build_rig_scene()
    weights = convert.read_weights(rig.body, [UPPER_BONE, "Missing", LOWER_BONE])
    assert weights.bone_names == (UPPER_BONE, "Missing", LOWER_BONE)
    z = local_positions(rig.body)[:, 2]
    expected_upper = np.clip((z - 0.8) / 0.4, 0.0, 1.0)
    np.testing.assert_allclose(weights.matrix[:, 0], expected_upper, atol=1e-6)
    np.testing.assert_array_equal(weights.matrix[:, 1], 0.0)
    np.testing.assert_allclose(weights.matrix[:, 2], 1.0 - expected_upper, atol=1e-6)


def random_weights(vertex_count, names, seed=0):
    rng = np.random.default_rng(seed)
    matrix = rng.random((vertex_count, len(names)))
    matrix[rng.random(matrix.shape) < 0.3] = 0.0
    return Weights(matrix, names)


def test_write_weights_round_trip_preserves_other_groups_and_skips_zeros(clean_scene):
    rig = build_rig_scene()
    sleeve = rig.sleeve
    keep = sleeve.vertex_groups.new(name="Keep")
    keep.add([0, 1, 2], 0.75, "REPLACE")
    stale = sleeve.vertex_groups.new(name=LOWER_BONE)
    stale.add(list(range(len(sleeve.data.vertices))), 0.1, "REPLACE")
    weights = random_weights(len(sleeve.data.vertices), (LOWER_BONE, UPPER_BONE))

    convert.write_weights(sleeve, weights, rig.armature)

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
    convert.write_weights(box, weights, armature)
    assert [group.name for group in box.vertex_groups] == [LOWER_BONE]


def test_write_weights_replace_all_keeps_only_listed_groups(clean_scene):
    rig = build_rig_scene()
    for name in ("Pin", "AutoRig Inpaint"):
        rig.sleeve.vertex_groups.new(name=name).add([0], 1.0, "REPLACE")
    weights = random_weights(len(rig.sleeve.data.vertices), (LOWER_BONE, UPPER_BONE))
    convert.write_weights(rig.sleeve, weights, rig.armature, replace_all=True, keep_groups=["AutoRig Inpaint"])
    assert sorted(group.name for group in rig.sleeve.vertex_groups) == ["AutoRig Inpaint", LOWER_BONE, UPPER_BONE]


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

    convert.write_weights(sleeve, weights, rig.armature)
    convert.write_weights(sleeve, weights, rig.armature)
    bpy.context.view_layer.update()

    armature_modifiers = [m for m in sleeve.modifiers if m.type == "ARMATURE"]
    assert len(armature_modifiers) == 1 and armature_modifiers[0].object == rig.armature
    assert sleeve.modifiers[0].type == "ARMATURE"  # deforms before the subdivision
    assert sleeve.parent == rig.armature
    np.testing.assert_allclose(np.array(sleeve.matrix_world), world_before, atol=1e-6)


def test_write_weights_restores_everything_when_it_fails(clean_scene, monkeypatch):
    rig = build_rig_scene()
    sleeve = rig.sleeve
    sleeve.vertex_groups.new(name=UPPER_BONE).add([0, 5], 0.4, "REPLACE")
    sleeve.vertex_groups.new(name="Pin").add([1], 1.0, "REPLACE")
    before = group_weights(sleeve, [UPPER_BONE, "Pin", LOWER_BONE])

    def broken_binding(obj, armature_obj):
        obj.modifiers.new("Half", "ARMATURE")
        raise RuntimeError("disk full")

    monkeypatch.setattr(convert, "ensure_armature_binding", broken_binding)
    weights = random_weights(len(sleeve.data.vertices), (LOWER_BONE, UPPER_BONE))
    with pytest.raises(RuntimeError, match="disk full"):
        convert.write_weights(sleeve, weights, rig.armature)

    assert [group.name for group in sleeve.vertex_groups] == [UPPER_BONE, "Pin"]
    np.testing.assert_allclose(group_weights(sleeve, [UPPER_BONE, "Pin", LOWER_BONE]), before)
    assert len(sleeve.modifiers) == 0 and sleeve.parent is None


def test_write_weights_rejects_wrong_row_count(clean_scene):
    rig = build_rig_scene()
    with pytest.raises(InputError, match="has 552 vertices but the weights have 3 rows"):
        convert.write_weights(rig.sleeve, Weights(np.ones((3, 1)), (LOWER_BONE,)), rig.armature)


def test_status_attribute_values_and_colours(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    status = np.array([0, 1, 2, 3, 4, 5, 0, 2], dtype=np.int8)
    convert.write_status_attribute(box, status)
    convert.write_status_attribute(box, status)  # rewriting replaces, never duplicates
    np.testing.assert_array_equal(convert.read_status_attribute(box), status)
    colours = box.data.color_attributes[convert.STATUS_COLOR_ATTRIBUTE]
    assert colours.data_type == "FLOAT_COLOR" and colours.domain == "POINT"
    values = np.empty(8 * 4, dtype=np.float32)
    colours.data.foreach_get("color", values)
    values = values.reshape(8, 4)
    assert values[0, 1] > 0.5 and values[0, 0] < 0.2  # copied: green
    assert values[2, 0] > 0.5 and values[2, 1] < 0.2  # inpainted: red
    assert values[4, 2] > 0.5 and values[4, 0] < 0.2  # protected: blue
    assert box.data.color_attributes.active_color_name == convert.STATUS_COLOR_ATTRIBUTE
    assert sum(a.name == convert.STATUS_ATTRIBUTE for a in box.data.attributes) == 1


def test_snapshot_restores_status_attributes(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    first = np.arange(8) % 6
    convert.write_status_attribute(box, first)
    snapshot = convert.ObjectSnapshot.capture(box)
    convert.write_status_attribute(box, np.zeros(8, dtype=int))
    snapshot.restore()
    np.testing.assert_array_equal(convert.read_status_attribute(box), first)


def test_read_weights_of_a_bound_mesh_after_write(clean_scene):
    armature = make_armature()
    vertices, faces = box_geometry((0.0, 0.0, 1.0), 0.2)
    box = mesh_object("Box", vertices, faces)
    add_weights(box, [LOWER_BONE], np.ones((8, 1)))
    bind(box, armature)
    bpy.context.view_layer.update()
    assert convert.find_armature(box) == armature
    np.testing.assert_array_equal(convert.read_weights(box, [LOWER_BONE, UPPER_BONE]).matrix, [[1.0, 0.0]] * 8)


def test_read_mesh_gives_the_rest_shape_of_a_posed_skinned_mesh(clean_scene):
    import bpy
    from mathutils import Quaternion

    from autorig_addon.blender.convert import read_mesh
    from blender_fixtures import build_rig_scene, local_positions

    scene = build_rig_scene(with_button=False)
    rest = local_positions(scene.body) @ np.array(scene.body.matrix_world)[:3, :3].T + np.array(scene.body.matrix_world)[:3, 3]
    bone = scene.armature.pose.bones["Upper"]
    bone.rotation_mode = "QUATERNION"
    bone.rotation_quaternion = Quaternion((1, 0, 0), 1.0)
    bpy.context.view_layer.update()
    mesh = read_mesh([scene.body], bpy.context.evaluated_depsgraph_get())
    np.testing.assert_allclose(mesh.vertices, rest, atol=1e-5)
    assert scene.armature.data.pose_position == "POSE"  # restored
    assert bone.rotation_quaternion.angle > 0.9


def test_rebinding_to_another_armature_leaves_one_modifier_and_failure_restores_both(clean_scene):
    from blender_fixtures import build_rig_scene, make_armature

    scene = build_rig_scene(with_button=False)
    other = make_armature("Other")
    extra = scene.body.modifiers.new("Second", "ARMATURE")
    extra.object = scene.armature
    before = [(m.name, m.object.name) for m in scene.body.modifiers]
    snapshot = convert.ObjectSnapshot.capture(scene.body)
    convert.ensure_armature_binding(scene.body, other)
    assert [(m.type, m.object.name) for m in scene.body.modifiers] == [("ARMATURE", "Other")]
    snapshot.restore()
    assert [(m.name, m.object.name) for m in scene.body.modifiers] == before
