"""Reading Blender objects into arrays (autorig_addon.blender.convert), real bpy."""

import re

import bpy
import numpy as np
import pytest
from mathutils import Euler, Quaternion, Vector

from autorig_addon.blender import convert
from autorig_addon.blender.armature_binding import find_armature
from autorig_addon.core.errors import InputError
from blender_fixtures import (
    LOWER_BONE,
    UPPER_BONE,
    add_weights,
    bind,
    box_geometry,
    build_rig_scene,
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
    # The second object's triangles are its own, shifted by the first's 8 vertices.
    np.testing.assert_array_equal(mesh.triangles[:12], convert.read_mesh(first).triangles)
    np.testing.assert_array_equal(mesh.triangles[12:], convert.read_mesh(second).triangles + 8)
    np.testing.assert_array_equal(mesh.triangle_polygons, np.tile(np.repeat(np.arange(6), 2), 2))


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


def test_read_mesh_rejects_non_meshes_faceless_meshes_and_nothing(clean_scene):
    armature = make_armature()
    with pytest.raises(InputError, match=re.escape(
            "The mesh 'Armature' is not a mesh (its type is Armature): pick a mesh object.")):
        convert.read_mesh(armature)
    wire = mesh_object("Wire", [(0, 0, 0), (1, 0, 0), (1, 1, 0)], [], edges=[(0, 1), (1, 2)])
    with pytest.raises(InputError, match=re.escape(
            "'Wire' has no faces: it is only vertices or edges. Add faces to it (Edit Mode > Face > Fill) "
            "or pick a mesh with a surface.")):
        convert.read_mesh(wire)
    with pytest.raises(InputError, match="^No mesh objects given.$"):
        convert.read_mesh([])


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
    # Created children first; the skeleton still comes parents first (the
    # reordering itself is tested on arrays in test_skeleton_hierarchy.py).
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


def test_read_skeleton_refuses_non_armatures_and_empty_armatures(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    with pytest.raises(InputError, match="^'Box' is not an armature object.$"):
        convert.read_skeleton(box)
    with pytest.raises(InputError, match="^None is not an armature object.$"):
        convert.read_skeleton(None)
    empty = bpy.data.objects.new("Empty Rig", bpy.data.armatures.new("Empty Rig"))
    bpy.context.scene.collection.objects.link(empty)
    with pytest.raises(InputError, match="^The armature 'Empty Rig' has no bones.$"):
        convert.read_skeleton(empty)


def test_deform_bone_names_lists_only_deforming_bones(clean_scene):
    assert convert.deform_bone_names(make_armature()) == (LOWER_BONE, UPPER_BONE)
    assert convert.deform_bone_names(make_armature("Half", deform_upper=False)) == (LOWER_BONE,)


def test_find_armature_from_modifier_or_parent(clean_scene):
    rig = build_rig_scene()
    assert find_armature(rig.body) == rig.armature
    rig.body.modifiers.clear()
    assert find_armature(rig.body) == rig.armature  # still the parent
    with pytest.raises(InputError, match=re.escape(
            "'Sleeve' is not bound to an armature: give it an Armature modifier "
            "or parent it to the armature (Ctrl+P > With Empty Groups) first.")):
        find_armature(rig.sleeve)


def test_read_weights_matches_groups_and_fills_missing_with_zero(clean_scene):
    rig = build_rig_scene()
    weights = convert.read_weights(rig.body, [UPPER_BONE, "Missing", LOWER_BONE])
    assert weights.bone_names == (UPPER_BONE, "Missing", LOWER_BONE)
    z = local_positions(rig.body)[:, 2]
    expected_upper = np.clip((z - 0.8) / 0.4, 0.0, 1.0)
    np.testing.assert_allclose(weights.matrix[:, 0], expected_upper, atol=1e-6)
    np.testing.assert_array_equal(weights.matrix[:, 1], 0.0)
    np.testing.assert_allclose(weights.matrix[:, 2], 1.0 - expected_upper, atol=1e-6)


def test_read_weights_refuses_a_non_mesh(clean_scene):
    with pytest.raises(InputError, match=re.escape("The object 'Armature' is not a mesh (its type is Armature)")):
        convert.read_weights(make_armature(), [LOWER_BONE])


def test_vertex_group_mask_thresholds_the_group(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    add_weights(box, ["Mask"], np.array([[0.2], [0.5], [1.0], [0], [0], [0], [0], [0.49]]))
    add_weights(box, ["Faint"], np.full((8, 1), 0.1))
    np.testing.assert_array_equal(convert.vertex_group_mask(box, "Mask", 0.5),
                                  [False, True, True, False, False, False, False, False])
    assert convert.vertex_group_mask(box, "Faint", 0.5) is None  # no member reaches the threshold
    assert convert.vertex_group_mask(box, "Missing", 0.5) is None
    assert convert.vertex_group_mask(box, "", 0.5) is None


def test_read_weights_of_a_bound_mesh_after_write(clean_scene):
    armature = make_armature()
    vertices, faces = box_geometry((0.0, 0.0, 1.0), 0.2)
    box = mesh_object("Box", vertices, faces)
    add_weights(box, [LOWER_BONE], np.ones((8, 1)))
    bind(box, armature)
    bpy.context.view_layer.update()
    assert find_armature(box) == armature
    np.testing.assert_array_equal(convert.read_weights(box, [LOWER_BONE, UPPER_BONE]).matrix, [[1.0, 0.0]] * 8)


def test_read_mesh_gives_the_rest_shape_of_a_posed_skinned_mesh(clean_scene):
    scene = build_rig_scene(with_button=False)
    world = np.array(scene.body.matrix_world)
    rest = local_positions(scene.body) @ world[:3, :3].T + world[:3, 3]
    bone = scene.armature.pose.bones["Upper"]
    bone.rotation_mode = "QUATERNION"
    bone.rotation_quaternion = Quaternion((1, 0, 0), 1.0)
    bpy.context.view_layer.update()
    mesh = convert.read_mesh([scene.body], bpy.context.evaluated_depsgraph_get())
    np.testing.assert_allclose(mesh.vertices, rest, atol=1e-5)
    assert scene.armature.data.pose_position == "POSE"  # restored
    assert bone.rotation_quaternion.angle == pytest.approx(1.0)  # the pose itself is untouched
