"""Rigging the shape the user sees, and binding so that posing deforms it
(issue 17, section 1): Mirror and Simple Deform modifiers, unapplied
non-uniform scale, a flat shape, modifiers the rig cannot follow
(autorig_addon.blender.modifier_stack and the rig and skin jobs, with real bpy)."""

import re

import bpy
import numpy as np
import pytest
from mathutils import Matrix, Vector

from autorig_addon.blender import convert
from autorig_addon.core.procedural import generate_character
from blender_fixtures import (
    BODY_HEIGHT,
    BODY_RADIUS,
    LOWER_BONE,
    UPPER_BONE,
    bind,
    cylinder_geometry,
    evaluated_world_vertices,
    group_weights,
    make_armature,
    mesh_object,
    pose_bone_turned,
    scene_state,
    select_only,
)

pytestmark = pytest.mark.all_blenders

#: The pose every test checks: one bone turned about its own X axis.
TURN_DEGREES = 30.0
#: A vertex moved by the pose lies this close to where turning it about the
#: bone's head in world space puts it (a share of how far it moved).
POSE_TOLERANCE = 1e-4


def biped_geometry(half: bool = False):
    """The procedural biped's vertices and triangles; ``half``: only its +X
    half (the plane's vertices included), as modelled for a Mirror modifier."""
    character = generate_character(0, "biped")
    vertices, triangles = character.mesh.vertices, character.mesh.triangles
    if half:
        kept = vertices[:, 0] >= -1e-9
        new_index = np.cumsum(kept) - 1
        triangles = new_index[triangles[kept[triangles].all(axis=1)]]
        vertices = vertices[kept]
    return vertices, triangles


def add_biped(name="Biped", half=False):
    obj = mesh_object(name, *biped_geometry(half))
    bpy.context.view_layer.update()
    select_only([obj], active=obj)
    return obj


def the_armature():
    (armature,) = [obj for obj in bpy.data.objects if obj.type == "ARMATURE"]
    return armature


def modifier_types(obj):
    return [modifier.type for modifier in obj.modifiers]


def received_weights(obj, names) -> np.ndarray:
    """(n, k) weights of the named groups on the vertices the Armature
    modifier receives (a Mirror's copies included), each row summing to 1
    where it has any: what posing uses."""
    place = modifier_types(obj).index("ARMATURE")
    later = [modifier for modifier in list(obj.modifiers)[place:] if modifier.show_viewport]
    for modifier in later:
        modifier.show_viewport = False
    bpy.context.view_layer.update()
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        columns = {obj.vertex_groups[name].index: k for k, name in enumerate(names) if name in obj.vertex_groups}
        weights = np.zeros((len(mesh.vertices), len(names)))
        for vertex in mesh.vertices:
            for element in vertex.groups:
                if element.group in columns:
                    weights[vertex.index, columns[element.group]] = element.weight
    finally:
        evaluated.to_mesh_clear()
        for modifier in later:
            modifier.show_viewport = True
        bpy.context.view_layer.update()
    totals = weights.sum(axis=1, keepdims=True)
    return np.divide(weights, totals, out=np.zeros_like(weights), where=totals > 0)


def pose_error(obj, armature, bone_name: str) -> tuple[float, int]:
    """Turn ``bone_name`` by :data:`TURN_DEGREES`; the largest distance of a
    vertex that follows only that bone and its children from where the turn
    about the bone's head in world space puts it, as a share of how far it
    moved, and how many such vertices there are. The armature is at rest
    again afterwards."""
    bone = armature.data.bones[bone_name]
    to_world = armature.matrix_world
    head = np.array(to_world @ bone.head_local)
    axis = np.array((to_world.to_3x3() @ bone.matrix_local.to_3x3()) @ Vector((1.0, 0.0, 0.0)))
    turn = np.array(Matrix.Rotation(np.radians(TURN_DEGREES), 3, Vector(axis / np.linalg.norm(axis))))
    turning = [bone_name] + [child.name for child in bone.children_recursive]
    rest = evaluated_world_vertices(obj)
    bones = [each.name for each in armature.data.bones]
    shares = received_weights(obj, bones)[:, [bones.index(name) for name in turning]]
    following = shares.sum(axis=1) > 1.0 - 1e-6
    pose_bone_turned(armature, bone_name, TURN_DEGREES)
    posed = evaluated_world_vertices(obj)
    pose_bone_turned(armature, bone_name, 0.0)
    expected = head + (rest[following] - head) @ turn.T
    moved = np.linalg.norm(expected - rest[following], axis=1)
    return float((np.linalg.norm(posed[following] - expected, axis=1) / moved).max()), int(following.sum())


def test_a_half_character_with_a_mirror_modifier_is_rigged_whole_and_poses_both_sides(clean_scene, capfd):
    """Blender's Ctrl+P, and this add-on before, put the Armature modifier
    before the Mirror: only the modelled half was read, and every pose of
    it was mirrored onto the other side."""
    body = add_biped(half=True)
    own = len(body.data.vertices)
    body.modifiers.new("Mirror", "MIRROR")
    body.modifiers.new("Subdivision", "SUBSURF")
    capfd.readouterr()

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    assert "'Biped': the Armature modifier goes after 'Mirror'" in capfd.readouterr().out
    armature = the_armature()
    assert modifier_types(body) == ["MIRROR", "ARMATURE", "SUBSURF"]
    assert len(body.data.vertices) == own
    # One skeleton for the whole body: each side's hand on its own side, mirror images of each other.
    left, right = (np.array(armature.data.bones[name].head_local) for name in ("hand.L", "hand.R"))
    assert left[0] * right[0] < 0
    np.testing.assert_allclose(left * [-1, 1, 1], right, atol=1e-3)
    body.modifiers["Subdivision"].show_viewport = False  # the cage's vertices are measured
    for side in ("L", "R"):
        error, count = pose_error(body, armature, f"upper_arm.{side}")
        assert count > 10 and error < POSE_TOLERANCE, side


def test_a_mirror_that_keeps_the_vertex_groups_is_refused_and_the_scene_unchanged(clean_scene):
    body = add_biped(half=True)
    body.modifiers.new("Mirror", "MIRROR").use_mirror_vertex_groups = False
    before = scene_state([body])

    with pytest.raises(RuntimeError, match=re.escape(
            "'Biped': the vertices its modifier 'Mirror' adds would follow the wrong bones (their weights for "
            "'shoulder.L'")) as refused:
        bpy.ops.autorig.auto_rig()

    assert str(refused.value).strip().endswith(
        "turn on the Vertex Groups option of 'Mirror' (under Data), or apply it first (Ctrl+A).")
    assert scene_state([body]) == before and len(bpy.data.armatures) == 0


def test_a_mirror_that_cuts_the_mesh_is_refused(clean_scene):
    body = add_biped()
    body.modifiers.new("Mirror", "MIRROR").use_bisect_axis[0] = True
    before = scene_state([body])

    with pytest.raises(RuntimeError, match=re.escape(
            "'Biped': the modifier 'Mirror' before the Armature modifier's place changes the mesh's own vertices (a "
            "Mirror's Bisect cuts them), so weights could not be written back to them: apply 'Mirror' first "
            "(Ctrl+A).")):
        bpy.ops.autorig.auto_rig()
    assert scene_state([body]) == before and len(bpy.data.armatures) == 0


def test_a_twisted_character_is_posed_as_shown(clean_scene):
    """The bones are fitted to the twisted shape; with the Armature modifier
    first, a 30 degree turn moved the hand a quarter of the way."""
    body = add_biped()
    twist = body.modifiers.new("Twist", "SIMPLE_DEFORM")
    twist.deform_method, twist.deform_axis, twist.angle = "TWIST", "Z", np.radians(45.0)
    bpy.context.view_layer.update()

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    armature = the_armature()
    assert modifier_types(body) == ["SIMPLE_DEFORM", "ARMATURE"]
    for side in ("L", "R"):
        error, count = pose_error(body, armature, f"upper_arm.{side}")
        assert count > 10 and error < POSE_TOLERANCE, side


def test_an_unapplied_non_uniform_scale_is_rigged_and_posed_in_world_space(clean_scene):
    """The armature is built in world space with no transform of its own:
    the Armature modifier carries the mesh's scale into it, so a turn of a
    bone is a turn of what the user sees."""
    body = add_biped()
    body.scale = (1.3, 1.0, 0.6)
    bpy.context.view_layer.update()

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    armature = the_armature()
    world = evaluated_world_vertices(body)
    joints = convert.read_skeleton(armature).joints
    assert (joints >= world.min(axis=0)).all() and (joints <= world.max(axis=0)).all()
    # The hips sit at the scaled height: the skeleton was fitted to the shape shown, not to the mesh data.
    hips = np.array(armature.data.bones["spine"].head_local)
    assert hips[2] < 0.7 * generate_character(0, "biped").mesh.vertices[:, 2].max()
    for bone in ("upper_arm.L", "forearm.R"):
        error, count = pose_error(body, armature, bone)
        assert count > 10 and error < POSE_TOLERANCE, bone


def test_a_character_squashed_flat_by_its_scale_is_refused(clean_scene):
    """A 1.9 cm pancake got a free-form rig of 15 bones."""
    body = add_biped()
    body.scale = (1.0, 1.0, 0.019)
    bpy.context.view_layer.update()
    before = scene_state([body])

    for operator in (bpy.ops.autorig.predict_skeleton, bpy.ops.autorig.auto_rig):
        with pytest.raises(RuntimeError, match=re.escape(
                "'Biped' is flat: 0.0176 thick and 0.275 by 0.604 across (its thickness is 6% of its width): a "
                "skeleton is predicted for a body with some depth. 'Biped' has the object scale (1, 1, 0.019), which "
                "squashes it: give it the scale the character should have (Object properties > Transform), then rig "
                "it. Nothing was built.")):
            operator()
        assert scene_state([body]) == before and len(bpy.data.armatures) == 0


def test_an_array_after_the_armature_is_refused_for_prediction(clean_scene):
    """The skeleton would be fitted to one of the copies the user sees."""
    body = add_biped()
    body.modifiers.new("Array", "ARRAY").count = 3
    bpy.context.view_layer.update()
    before = scene_state([body])

    with pytest.raises(RuntimeError, match=re.escape(
            "'Biped': its modifier 'Array' changes the shape a lot after the place where the Armature modifier "
            "deforms it (before 'Array'), so the skeleton would be fitted to another shape than the one shown: apply "
            "'Array' first (Ctrl+A).")):
        bpy.ops.autorig.predict_skeleton()
    assert scene_state([body]) == before and len(bpy.data.armatures) == 0


def tube(name="Tube"):
    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, BODY_HEIGHT, 24, 20, capped=True)
    obj = mesh_object(name, vertices, faces)
    bpy.context.view_layer.update()
    return obj


GEOMETRIC = {"skin_method": "GEOMETRIC", "skin_resolution": 32}


def test_skin_weights_the_cage_before_a_solidify_and_an_array(clean_scene):
    """Modifiers that build on the surface follow the Armature modifier, as in Blender's own rigs."""
    armature = make_armature()
    cage = tube()
    for kind in ("SOLIDIFY", "ARRAY"):
        cage.modifiers.new(kind.title(), kind)
    select_only([armature, cage], active=armature)

    assert bpy.ops.autorig.skin_weights(**GEOMETRIC) == {"FINISHED"}

    assert modifier_types(cage) == ["ARMATURE", "SOLIDIFY", "ARRAY"]
    z = np.array([vertex.co.z for vertex in cage.data.vertices])
    weights = group_weights(cage, [LOWER_BONE, UPPER_BONE])
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-5)
    assert weights[z < 0.3, 0].min() > 0.9 and weights[z > 1.7, 1].min() > 0.9


def test_skin_keeps_the_place_the_user_gave_the_armature_modifier(clean_scene):
    """An Armature modifier before a Simple Deform (a bend on top of the
    animation) stays there; the weights fit the shape it receives, unbent."""
    armature = make_armature()
    body = tube()
    bind(body, armature)
    bend = body.modifiers.new("Bend", "SIMPLE_DEFORM")
    bend.deform_method, bend.angle = "BEND", np.radians(90.0)
    select_only([armature, body], active=armature)

    assert bpy.ops.autorig.skin_weights(**GEOMETRIC) == {"FINISHED"}

    assert modifier_types(body) == ["ARMATURE", "SIMPLE_DEFORM"]
    z = np.array([vertex.co.z for vertex in body.data.vertices])
    weights = group_weights(body, [LOWER_BONE, UPPER_BONE])
    assert weights[z < 0.3, 0].min() > 0.9 and weights[z > 1.7, 1].min() > 0.9


def test_skin_weights_the_subdivided_shape_when_the_users_armature_modifier_follows_it(clean_scene):
    """Blender's Ctrl+P appends the Armature modifier after a Subdivision
    Surface: the weights are computed on the subdivided shape it receives
    and written on the mesh's own vertices, which the subdivision blends."""
    armature = make_armature()
    body = tube()
    body.modifiers.new("Subdivision", "SUBSURF")
    bind(body, armature)
    select_only([armature, body], active=armature)

    assert bpy.ops.autorig.skin_weights(**GEOMETRIC) == {"FINISHED"}

    assert modifier_types(body) == ["SUBSURF", "ARMATURE"]
    z = np.array([vertex.co.z for vertex in body.data.vertices])
    weights = group_weights(body, [LOWER_BONE, UPPER_BONE])
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-5)
    assert weights[z < 0.3, 0].min() > 0.9 and weights[z > 1.7, 1].min() > 0.9


def test_a_shape_made_by_a_skin_modifier_is_refused_naming_it(clean_scene):
    """The Armature modifier deforms the edges before the Skin modifier gives them a surface."""
    wire = mesh_object("Wire", [[0, 0, 0], [0, 0, 0.5], [0, 0, 1.0], [0.3, 0, 0.7]], [], edges=[(0, 1), (1, 2), (1, 3)])
    wire.modifiers.new("Skin", "SKIN")
    bpy.context.view_layer.update()
    select_only([wire], active=wire)
    before = scene_state([wire])

    with pytest.raises(RuntimeError, match=re.escape(
            "'Wire' has no faces before its modifier 'Skin', where the Armature modifier deforms it: it is only "
            "vertices or edges there. Apply 'Skin' first (Ctrl+A).")):
        bpy.ops.autorig.auto_rig()
    assert scene_state([wire]) == before and len(bpy.data.armatures) == 0
