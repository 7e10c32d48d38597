"""The Skin operator and the ``skin`` subcommand on a generated 2-bone cylinder."""


import numpy as np
import pytest

from blender_fixtures import (
    BODY_HEIGHT,
    BODY_RADIUS,
    LOWER_BONE,
    UPPER_BONE,
    cylinder_geometry,
    group_weights,
    make_armature,
    mesh_object,
    scene_state,
    select_only,
)


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
    assert bpy.ops.autorig.skin_weights(skin_distance=distance, skin_resolution=40) == {"FINISHED"}
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
    with pytest.raises(RuntimeError, match="far from the mesh"):
        bpy.ops.autorig.skin_weights()
    assert scene_state([armature, tube]) == before


def test_mesh_without_faces_is_refused_and_scene_unchanged(clean_scene):
    import bpy

    armature = make_armature()
    points = mesh_object("Points", [[0, 0, 0.5], [0, 0, 1.5], [0.1, 0, 1.0]], [])
    bpy.context.view_layer.update()
    select_only([armature, points], active=armature)
    before = scene_state([armature, points])
    with pytest.raises(RuntimeError, match="no faces"):
        bpy.ops.autorig.skin_weights()
    assert scene_state([armature, points]) == before


def test_zero_length_deform_bone_is_refused(clean_scene):
    import bpy

    armature = make_armature()
    tube = unbound_cylinder()
    # Blender refuses zero-length bones itself, so shrink one below the tolerance instead.
    select_only([armature], active=armature)
    bpy.ops.object.mode_set(mode="EDIT")
    armature.data.edit_bones[UPPER_BONE].tail = (0.0, 0.0, 1.0 + 1e-5)
    bpy.ops.object.mode_set(mode="OBJECT")
    select_only([armature, tube], active=armature)
    before = scene_state([armature, tube])
    with pytest.raises(RuntimeError, match="zero length"):
        bpy.ops.autorig.skin_weights()
    assert scene_state([armature, tube]) == before


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
