"""The artist's own vertex groups that share a bone's name (issue 17, section
3): Auto-Rig and Skin keep them under a new name, say so, and undo it on
failure (autorig_addon.blender.artist_groups, with real bpy)."""

import re

import bpy
import numpy as np
import pytest

from autorig_addon.blender.jobs import skin
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.skinning.options import SkinningOptions
from blender_fixtures import (
    BODY_HEIGHT,
    BODY_RADIUS,
    LOWER_BONE,
    UPPER_BONE,
    add_weights,
    bind,
    cylinder_geometry,
    expected_body_weights,
    group_weights,
    make_armature,
    mesh_object,
    scene_state,
    select_only,
)

pytestmark = pytest.mark.all_blenders

#: Vertices of the artist's groups and the weights painted on them.
ARTIST_VERTICES = np.arange(0, 120, 10)
SPINE_MASK_WEIGHT, THIGH_MASK_WEIGHT = 0.25, 0.5


def biped(name="Biped"):
    character = generate_character(0, "biped")
    obj = mesh_object(name, character.mesh.vertices, character.mesh.triangles)
    bpy.context.view_layer.update()
    select_only([obj], active=obj)
    return obj


def paint(obj, name, weight, vertices=ARTIST_VERTICES):
    """A vertex group ``name`` holding ``weight`` on ``vertices``, as painted."""
    group = obj.vertex_groups.new(name=name)
    group.add([int(index) for index in vertices], weight, "REPLACE")
    return group


def painted(obj, vertices, weight) -> np.ndarray:
    column = np.zeros(len(obj.data.vertices))
    column[vertices] = weight
    return column


def shape_key_on_group(obj, group_name):
    """A shape key whose influence is limited to a vertex group (the artist's use of it)."""
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Breathe")
    key.vertex_group = group_name
    return key


def test_auto_rig_keeps_the_artists_groups_that_share_bone_names(clean_scene, capfd):
    reference = biped("Reference")
    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}
    (reference_rig,) = [obj for obj in bpy.data.objects if obj.type == "ARMATURE"]
    bones = [bone.name for bone in reference_rig.data.bones]
    predicted = group_weights(reference, bones)
    for obj in (reference_rig, reference):
        bpy.data.objects.remove(obj)

    body = biped("Body")
    paint(body, "spine", SPINE_MASK_WEIGHT)
    paint(body, "thigh.L", THIGH_MASK_WEIGHT, ARTIST_VERTICES + 5)
    paint(body, "Mask", 1.0)
    key = shape_key_on_group(body, "spine")
    capfd.readouterr()

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    assert ("'Body': its own vertex groups 'spine', 'thigh.L' shared the new bones' names: kept, renamed "
            "'spine.artist', 'thigh.L.artist'") in capfd.readouterr().out
    np.testing.assert_array_equal(group_weights(body, ["spine.artist"])[:, 0],
                                  painted(body, ARTIST_VERTICES, SPINE_MASK_WEIGHT))
    np.testing.assert_array_equal(group_weights(body, ["thigh.L.artist"])[:, 0],
                                  painted(body, ARTIST_VERTICES + 5, THIGH_MASK_WEIGHT))
    np.testing.assert_array_equal(group_weights(body, ["Mask"])[:, 0], painted(body, ARTIST_VERTICES, 1.0))
    # The bones' groups hold the skin the same mesh gets without the artist's groups.
    np.testing.assert_allclose(group_weights(body, bones), predicted, atol=1e-6)
    assert group_weights(body, ["spine"])[:, 0].max() > 0.5  # the skin, not the 0.25 mask
    # What used the artist's group by name follows it.
    assert key.vertex_group == "spine.artist"


def unbound_tube(name="Tube"):
    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, BODY_HEIGHT, 24, 20, capped=True)
    tube = mesh_object(name, vertices, faces)
    bpy.context.view_layer.update()
    return tube


GEOMETRIC = {"skin_method": "GEOMETRIC", "skin_resolution": 32}


def test_skin_keeps_an_unrelated_group_named_like_a_bone_and_avoids_taken_names(clean_scene, capfd):
    armature = make_armature()
    tube = unbound_tube()
    paint(tube, LOWER_BONE, SPINE_MASK_WEIGHT)
    paint(tube, f"{LOWER_BONE}.artist", 1.0, ARTIST_VERTICES + 1)  # kept from an earlier run: taken
    select_only([armature, tube], active=armature)
    capfd.readouterr()

    assert bpy.ops.autorig.skin_weights(**GEOMETRIC) == {"FINISHED"}

    kept = f"{LOWER_BONE}.artist.001"
    assert (f"'Tube': its own vertex group '{LOWER_BONE}' shared the new bones' names: kept, renamed '{kept}'"
            in capfd.readouterr().out)
    np.testing.assert_array_equal(group_weights(tube, [kept])[:, 0],
                                  painted(tube, ARTIST_VERTICES, SPINE_MASK_WEIGHT))
    np.testing.assert_array_equal(group_weights(tube, [f"{LOWER_BONE}.artist"])[:, 0],
                                  painted(tube, ARTIST_VERTICES + 1, 1.0))
    weights = group_weights(tube, [LOWER_BONE, UPPER_BONE])
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-5)
    z = np.array([vertex.co.z for vertex in tube.data.vertices])
    assert weights[z < 0.3, 0].min() > 0.9


def test_skin_replaces_the_groups_of_the_armature_the_mesh_is_bound_to(clean_scene, capfd):
    """Skinning again to the armature a mesh follows rightly replaces its groups: nothing is renamed."""
    armature = make_armature()
    tube = unbound_tube()
    add_weights(tube, [LOWER_BONE, UPPER_BONE], np.full((len(tube.data.vertices), 2), 0.5))
    bind(tube, armature)
    select_only([armature, tube], active=armature)
    capfd.readouterr()

    assert bpy.ops.autorig.skin_weights(**GEOMETRIC) == {"FINISHED"}

    assert [group.name for group in tube.vertex_groups] == [LOWER_BONE, UPPER_BONE]
    assert "kept, renamed" not in capfd.readouterr().out
    z = np.array([vertex.co.z for vertex in tube.data.vertices])
    np.testing.assert_allclose(group_weights(tube, [LOWER_BONE, UPPER_BONE])[z < 0.3, 0], 1.0, atol=0.1)


def test_replace_all_groups_renames_nothing(clean_scene):
    armature = make_armature()
    tube = unbound_tube()
    paint(tube, LOWER_BONE, SPINE_MASK_WEIGHT)
    select_only([armature, tube], active=armature)

    assert bpy.ops.autorig.skin_weights(skin_replace_all=True, **GEOMETRIC) == {"FINISHED"}

    assert sorted(group.name for group in tube.vertex_groups) == [LOWER_BONE, UPPER_BONE]


def test_a_failed_write_gives_the_artists_group_back_its_name_and_users(clean_scene, monkeypatch):
    armature = make_armature()
    tube = unbound_tube()
    paint(tube, LOWER_BONE, SPINE_MASK_WEIGHT)
    key = shape_key_on_group(tube, LOWER_BONE)
    displace = tube.modifiers.new("Bump", "DISPLACE")
    displace.vertex_group = LOWER_BONE
    bpy.context.view_layer.update()
    plan = skin.plan_skin(armature, [tube], skin.SkinSettings(SkinningOptions(method="geometric", resolution=24)),
                          bpy.context.evaluated_depsgraph_get())
    assert plan.renames == [{LOWER_BONE: f"{LOWER_BONE}.artist"}]
    weights = skin.compute_skin(plan)
    before = scene_state([armature, tube])

    real_write = skin.write_weights

    def write_fails(obj, *args, **kwargs):
        # Fails once the bone's group has taken the artist's group's old name.
        real_write(obj, *args, **kwargs)
        assert displace.vertex_group == f"{LOWER_BONE}.artist" and obj.vertex_groups.get(LOWER_BONE) is not None
        raise RuntimeError("disk full")

    monkeypatch.setattr(skin, "write_weights", write_fails)
    with pytest.raises(RuntimeError, match=re.escape("disk full")):
        skin.write_skin(plan, weights)

    assert scene_state([armature, tube]) == before
    assert key.vertex_group == LOWER_BONE and displace.vertex_group == LOWER_BONE
    np.testing.assert_array_equal(group_weights(tube, [LOWER_BONE])[:, 0],
                                  painted(tube, ARTIST_VERTICES, SPINE_MASK_WEIGHT))


def test_a_skinned_body_keeps_its_groups_when_skinned_again(clean_scene):
    """The reference scene's body, bound to its armature with known weights: its groups are the binding's."""
    armature = make_armature()
    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, BODY_HEIGHT, 24, 20, capped=True)
    body = mesh_object("Body", vertices, faces)
    add_weights(body, [LOWER_BONE, UPPER_BONE], expected_body_weights(vertices[:, 2]))
    bind(body, armature)
    bpy.context.view_layer.update()
    plan = skin.plan_skin(armature, [body], skin.SkinSettings(SkinningOptions(method="geometric", resolution=24)),
                          bpy.context.evaluated_depsgraph_get())
    assert plan.renames == [{}] and "renamed" not in plan.summary
