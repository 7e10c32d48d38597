"""How meshes follow armatures (autorig_addon.blender.armature_binding), real
bpy: the one rule and each question read off it, for every way a mesh can
follow an armature, built as a user builds it."""

import bpy
import numpy as np
import pytest

from autorig_addon.blender import convert
from autorig_addon.blender.armature_binding import (
    ArmatureBinding,
    armature_bindings,
    bone_parent,
    bound_armature,
    deforms,
    is_unbound,
    objects_at_rest,
    pose_position,
    posing_armatures,
    remove_armature,
    unbind,
)
from blender_fixtures import (
    LOWER_BONE,
    UPPER_BONE,
    add_weights,
    bind,
    box_geometry,
    evaluated_world_vertices,
    make_armature,
    mesh_object,
    parent_to_bone,
    pose_bone_turned,
)

#: A box around the top of the Upper bone (which runs from z = 1 to 2).
BOX_CENTER, BOX_HALF_SIZE = (0.0, 0.0, 1.8), 0.1


def box(name="Box"):
    vertices, faces = box_geometry(BOX_CENTER, BOX_HALF_SIZE)
    obj = mesh_object(name, vertices, faces)
    bpy.context.view_layer.update()
    return obj


def parented(obj, armature, parent_type):
    obj.parent = armature
    obj.parent_type = parent_type
    bpy.context.view_layer.update()
    return obj


def test_each_way_of_following_an_armature_answers_every_question(clean_scene):
    armature = make_armature()
    skinned = box("Skinned")
    bind(skinned, armature)  # Armature modifier and Object parent, as Ctrl+P > With Empty Groups makes
    old_style = parented(box("OldStyle"), armature, "ARMATURE")
    child = parented(box("Child"), armature, "OBJECT")
    prop = box("Prop")
    parent_to_bone(prop, armature, UPPER_BONE)
    loose = box("Loose")

    assert armature_bindings(skinned) == [ArmatureBinding(armature, True), ArmatureBinding(armature, False)]
    assert armature_bindings(old_style) == [ArmatureBinding(armature, True)]
    assert armature_bindings(child) == [ArmatureBinding(armature, False)]
    assert armature_bindings(prop) == [ArmatureBinding(armature, False, UPPER_BONE)]
    assert armature_bindings(loose) == []
    # name: (bound to, deformed by it, carried by bone, weighted by a run that picks meshes itself)
    expected = {"Skinned": (armature, True, None, False), "OldStyle": (armature, True, None, False),
                "Child": (armature, False, None, False), "Prop": (armature, False, UPPER_BONE, True),
                "Loose": (None, False, None, True)}
    for obj in (skinned, old_style, child, prop, loose):
        assert (bound_armature(obj), deforms(armature, obj), bone_parent(obj), is_unbound(obj)) == expected[obj.name]
    # Only what the armature's pose moves is put at rest while read.
    assert posing_armatures([skinned, old_style, child, prop, loose, None]) == [armature]
    assert posing_armatures([child, loose]) == []


def test_the_first_armature_modifier_decides_which_armature_a_mesh_is_bound_to(clean_scene):
    first, second = make_armature("First"), make_armature("Second")
    obj = box()
    for armature in (first, second):
        obj.modifiers.new(armature.name, "ARMATURE").object = armature
    obj.parent = second
    assert bound_armature(obj) == first
    assert deforms(first, obj) and deforms(second, obj)


def test_pose_position_shows_rest_inside_and_restores_each_setting(clean_scene):
    posed, at_rest = make_armature("Posed"), make_armature("AtRest")
    at_rest.data.pose_position = "REST"
    skinned = box()
    add_weights(skinned, [UPPER_BONE], np.ones((8, 1)))
    bind(skinned, posed)
    pose_bone_turned(posed, UPPER_BONE, 90.0)
    rest_vertices = np.array([tuple(v.co) for v in skinned.data.vertices])
    assert np.abs(evaluated_world_vertices(skinned) - rest_vertices).max() > 0.1  # posed, it moves
    assert np.abs(convert.read_mesh([skinned]).vertices - rest_vertices).max() < 1e-5  # read at rest
    with objects_at_rest([skinned]):
        assert posed.data.pose_position == "REST"
    with pose_position([posed, at_rest], "POSE"):
        assert (posed.data.pose_position, at_rest.data.pose_position) == ("POSE", "POSE")
    assert (posed.data.pose_position, at_rest.data.pose_position) == ("POSE", "REST")


def test_unbind_keeps_the_world_place_and_the_other_groups(clean_scene):
    armature = make_armature()
    armature.location = (1.0, 0.0, 0.0)
    skinned = box()
    add_weights(skinned, [LOWER_BONE, UPPER_BONE, "Mask"], np.ones((8, 3)))
    bind(skinned, armature)
    bpy.context.view_layer.update()
    world = np.array(skinned.matrix_world)
    unbind(skinned)
    bpy.context.view_layer.update()
    assert armature_bindings(skinned) == [] and skinned.parent is None
    assert [group.name for group in skinned.vertex_groups] == ["Mask"]
    np.testing.assert_allclose(np.array(skinned.matrix_world), world, atol=1e-6)


@pytest.mark.parametrize("shared", [False, True])
def test_remove_armature_keeps_data_another_object_uses(clean_scene, shared):
    armature = make_armature()
    data_name = armature.data.name
    other = bpy.data.objects.new("Other", armature.data) if shared else None
    remove_armature(armature)
    assert "Armature" not in bpy.data.objects
    assert (data_name in bpy.data.armatures) == shared
    if other is not None:
        assert other.data.name == data_name
