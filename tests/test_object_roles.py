"""What skinning and transfer do with objects that are not plain meshes to
weight (autorig_addon.blender.object_roles), real bpy: props parented to a
bone, bone shapes and other helpers, linked duplicates. Each scene is built
as a user builds it (Ctrl+P > Bone, Alt+D, a bone's custom shape)."""

import json
import re

import bpy
import numpy as np
import pytest

from autorig_addon.blender import object_roles, status_attribute
from autorig_addon.blender.jobs import transfer as transfer_job
from autorig_addon.blender.jobs.transfer import TransferSettings, run_transfer
from autorig_addon.blender.selection import unbound_meshes
from autorig_addon.core.errors import InputError
from blender_fixtures import (
    BODY_RADIUS,
    COPY_TOLERANCE,
    LOWER_BONE,
    UPPER_BONE,
    box_geometry,
    build_rig_scene,
    cylinder_geometry,
    evaluated_world_vertices,
    expected_body_weights,
    group_weights,
    make_armature,
    mesh_object,
    parent_to_bone,
    pose_bone_turned,
    scene_state,
    select_only,
)

pytestmark = pytest.mark.all_blenders

#: A helmet: a box around the top of the Upper bone.
HELMET_CENTER, HELMET_HALF_SIZE = (0.0, 0.0, 1.8), 0.35
#: How far the Upper bone is turned to compare the prop's motion, degrees.
TURN_DEGREES = 45.0


def helmet_on_upper_bone(armature):
    vertices, faces = box_geometry(HELMET_CENTER, HELMET_HALF_SIZE)
    helmet = mesh_object("Helmet", vertices, faces)
    bpy.context.view_layer.update()
    parent_to_bone(helmet, armature, UPPER_BONE)
    return helmet


def tube(name="Tube"):
    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, 2.0, 24, 20, capped=True)
    obj = mesh_object(name, vertices, faces)
    bpy.context.view_layer.update()
    return obj


def motion_with_bone_parent(armature, prop):
    """The prop's world vertices with the Upper bone turned, then the armature back at rest."""
    pose_bone_turned(armature, UPPER_BONE, TURN_DEGREES)
    moved = evaluated_world_vertices(prop)
    pose_bone_turned(armature, UPPER_BONE, 0.0)
    return moved


def assert_bound_wholly_to_upper(armature, prop, moved, rest):
    assert prop.parent == armature and prop.parent_type == "OBJECT" and prop.parent_bone == ""
    assert [(m.type, m.object) for m in prop.modifiers] == [("ARMATURE", armature)]
    assert [group.name for group in prop.vertex_groups] == [UPPER_BONE]
    np.testing.assert_array_equal(group_weights(prop, [UPPER_BONE])[:, 0], 1.0)
    # At rest where it was; posed, it moves exactly as with the bone parent (not twice).
    np.testing.assert_allclose(evaluated_world_vertices(prop), rest, atol=1e-5)
    pose_bone_turned(armature, UPPER_BONE, TURN_DEGREES)
    np.testing.assert_allclose(evaluated_world_vertices(prop), moved, atol=1e-5)


@pytest.mark.parametrize("posed_while_skinning", [False, True])
def test_skinning_a_selected_prop_on_a_bone_binds_it_wholly_to_that_bone(clean_scene, capfd, posed_while_skinning):
    armature = make_armature()
    body = tube()
    helmet = helmet_on_upper_bone(armature)
    rest = evaluated_world_vertices(helmet)
    moved = motion_with_bone_parent(armature, helmet)
    assert np.abs(moved - rest).max() > 0.3  # the turn moves the helmet visibly
    if posed_while_skinning:
        pose_bone_turned(armature, UPPER_BONE, TURN_DEGREES)
    select_only([armature, body, helmet], active=armature)
    capfd.readouterr()
    assert bpy.ops.autorig.skin_weights(skin_method="GEOMETRIC", skin_resolution=32) == {"FINISHED"}
    assert ("Info: Skinned 1 mesh(es) to 2 deform bones of 'Armature' with Geometric; 'Helmet' bound wholly to bone "
            "'Upper' (it was parented to that bone)." in "".join(capfd.readouterr()))
    pose_bone_turned(armature, UPPER_BONE, 0.0)
    assert_bound_wholly_to_upper(armature, helmet, moved, rest)


def test_transfer_onto_a_named_prop_on_a_bone_binds_it_wholly_to_that_bone(clean_scene, capfd):
    rig = build_rig_scene(with_button=False)
    helmet = helmet_on_upper_bone(rig.armature)
    rest = evaluated_world_vertices(helmet)
    moved = motion_with_bone_parent(rig.armature, helmet)
    capfd.readouterr()
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve,Helmet") == {"FINISHED"}
    assert "Helmet: bound wholly to bone 'Upper' (it was parented to that bone)" in "".join(capfd.readouterr())
    assert status_attribute.STATUS_ATTRIBUTE_NAMES[0] not in helmet.data.attributes  # not transferred: no status
    assert_bound_wholly_to_upper(rig.armature, helmet, moved, rest)


def test_a_prop_on_a_bone_that_does_not_deform_stays_rigid(clean_scene, capfd):
    armature = make_armature(deform_upper=False)
    body = tube()
    helmet = helmet_on_upper_bone(armature)
    before = scene_state([helmet])
    select_only([armature, body, helmet], active=armature)
    capfd.readouterr()
    assert bpy.ops.autorig.skin_weights(skin_resolution=32) == {"FINISHED"}
    assert "'Helmet' left rigid, parented to bone 'Upper' (it does not deform)." in "".join(capfd.readouterr())
    assert scene_state([helmet]) == before


def test_a_prop_on_a_bone_of_another_armature_is_refused(clean_scene):
    armature = make_armature()
    other = make_armature("Other")
    body = tube()
    helmet = helmet_on_upper_bone(other)
    select_only([armature, body, helmet], active=armature)
    before = scene_state([armature, other, body, helmet])
    with pytest.raises(RuntimeError, match=re.escape(
            "'Helmet' is parented to bone 'Upper' of 'Other', not of 'Armature': clear its parent "
            "(Alt+P > Clear and Keep Transformation) to weight it to 'Armature'.")):
        bpy.ops.autorig.skin_weights(skin_resolution=32)
    assert scene_state([armature, other, body, helmet]) == before


def bone_shape(armature):
    """A sphere-like mesh shown as the Lower bone's custom shape (what the glTF importer adds)."""
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 1.0)
    shape = mesh_object("Icosphere", vertices, faces)
    armature.pose.bones[LOWER_BONE].custom_shape = shape
    return shape


def hidden_helpers():
    """A mesh hidden from render and one in a collection hidden from render."""
    vertices, faces = box_geometry((0.0, 0.0, 1.0), 0.5)
    cage = mesh_object("Cage", vertices, faces)
    cage.hide_render = True
    collection = bpy.data.collections.new("Helpers")
    bpy.context.scene.collection.children.link(collection)
    collection.hide_render = True
    vertices, faces = box_geometry((0.0, 0.0, 1.5), 0.2)
    widget = mesh_object("Widget", vertices, faces)
    bpy.context.scene.collection.objects.unlink(widget)
    collection.objects.link(widget)
    return [cage, widget]


def test_skin_command_skips_helpers_and_leaves_props_on_bones_rigid(clean_scene, tmp_path):
    from autorig_addon.cli import main

    armature = make_armature()
    tube()
    helmet_on_upper_bone(armature)
    bone_shape(armature)
    hidden_helpers()
    source = tmp_path / "rig.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source), copy=True)
    summary = tmp_path / "summary.json"
    out = tmp_path / "skinned.blend"
    assert main(["skin", str(source), "--out", str(out), "--resolution", "32", "--quiet", "--summary",
                 str(summary)]) == 0
    (entry,) = json.loads(summary.read_text())["succeeded"]
    assert entry["meshes"] == ["Tube"]
    assert entry["notes"] == ["'Helmet' left rigid, parented to bone 'Upper'"]
    bpy.ops.wm.open_mainfile(filepath=str(out))
    for name in ("Helmet", "Icosphere", "Cage", "Widget"):
        obj = bpy.data.objects[name]
        assert not obj.vertex_groups and not obj.modifiers, name
    assert bpy.data.objects["Helmet"].parent_type == "BONE"
    assert bpy.data.objects["Tube"].vertex_groups.keys() == [LOWER_BONE, UPPER_BONE]


def test_default_targets_skip_helpers_and_leave_props_on_bones_rigid(clean_scene):
    rig = build_rig_scene(with_button=False)
    helmet = helmet_on_upper_bone(rig.armature)
    helpers = [bone_shape(rig.armature), *hidden_helpers()]
    untouched = [helmet, *helpers]
    before = scene_state(untouched)
    outcomes = run_transfer(rig.body, unbound_meshes(rig.body), TransferSettings(),
                            bpy.context.evaluated_depsgraph_get(),
                            named=False)
    assert {outcome.target.name: outcome.summary for outcome in outcomes} == {
        "Sleeve": "544 copied, 0 inpainted (0%)", "Helmet": "left rigid, parented to bone 'Upper'"}
    assert scene_state(untouched) == before
    np.testing.assert_allclose(group_weights(rig.sleeve, [LOWER_BONE, UPPER_BONE]),
                               expected_body_weights(np.array([v.co.z for v in rig.sleeve.data.vertices])),
                               atol=COPY_TOLERANCE)


def test_default_targets_with_only_props_and_helpers_is_refused_unchanged(clean_scene):
    """A KayKit file: every mesh is skinned or carried by a bone, plus the importer's bone shape."""
    rig = build_rig_scene(with_button=False)
    bpy.data.objects.remove(rig.sleeve)
    helmet = helmet_on_upper_bone(rig.armature)
    shape = bone_shape(rig.armature)
    before = scene_state([rig.body, helmet, shape])
    with pytest.raises(InputError, match=re.escape(
            "Nothing to weight: 'Helmet' (bone 'Upper') is left rigid on its bone. Name the meshes to weight them.")):
        run_transfer(rig.body, unbound_meshes(rig.body), TransferSettings(), bpy.context.evaluated_depsgraph_get(),
                     named=False)
    assert scene_state([rig.body, helmet, shape]) == before


def test_default_targets_that_are_all_helpers_are_refused(clean_scene):
    rig = build_rig_scene(with_button=False)
    bpy.data.objects.remove(rig.sleeve)
    shape = bone_shape(rig.armature)
    before = scene_state([rig.body, shape])
    with pytest.raises(InputError, match=re.escape(
            "Nothing to weight: the other meshes are helpers (bone shapes, hidden from render). "
            "Name the meshes to weight them.")):
        run_transfer(rig.body, unbound_meshes(rig.body), TransferSettings(), bpy.context.evaluated_depsgraph_get(),
                     named=False)
    assert scene_state([rig.body, shape]) == before


def test_transfer_command_on_a_kaykit_like_file_says_what_it_left_and_changes_nothing(clean_scene, tmp_path):
    """Skinned body, helmet on the head bone, the importer's bone shape, no --target."""
    from autorig_addon.cli import main

    rig = build_rig_scene(with_button=False)
    bpy.data.objects.remove(rig.sleeve)
    helmet_on_upper_bone(rig.armature)
    bone_shape(rig.armature)
    source = tmp_path / "kaykit.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source), copy=True)
    summary = tmp_path / "summary.json"
    out = tmp_path / "out.blend"
    assert main(["transfer", str(source), "--source", "Body", "--out", str(out), "--quiet", "--summary",
                 str(summary)]) == 1
    (failure,) = json.loads(summary.read_text())["failed"]
    assert failure["error"] == ("Nothing to weight: 'Helmet' (bone 'Upper') is left rigid on its bone. Name the meshes "
                                "to weight them.")
    assert not out.exists()


def test_helpers_named_explicitly_are_weighted(clean_scene):
    armature = make_armature()
    shape = bone_shape(armature)
    shape.location = (0.0, 0.0, 1.0)
    bpy.context.view_layer.update()
    assert object_roles.without_helpers([shape]) == []
    assert bpy.ops.autorig.skin_weights(armature="Armature", meshes="Icosphere", skin_resolution=32) == {"FINISHED"}
    assert shape.vertex_groups.keys() == [LOWER_BONE, UPPER_BONE]


# --------------------------------------------------------------------------- linked duplicates


def linked_cuffs():
    """A cuff around the body's Lower part and its linked duplicate (Alt+D),
    moved up around the Upper part and mirrored top to bottom."""
    vertices, faces = cylinder_geometry(1.1 * BODY_RADIUS, -0.2, 0.2, 32, 4, capped=False)
    lower = mesh_object("Cuff.Lower", vertices, faces)
    lower.location = (0.0, 0.0, 0.4)
    bpy.context.view_layer.update()
    select_only([lower], active=lower)
    assert bpy.ops.object.duplicate_move_linked(TRANSFORM_OT_translate={"value": (0.0, 0.0, 1.2)}) == {"FINISHED"}
    upper = bpy.context.active_object
    upper.name = "Cuff.Upper"
    upper.scale = (1.0, 1.0, -1.0)
    bpy.context.view_layer.update()
    assert upper != lower and upper.data == lower.data
    return lower, upper


def world_heights(obj):
    return evaluated_world_vertices(obj)[:, 2]


def test_transfer_onto_linked_duplicates_gives_each_its_own_mesh_and_weights(clean_scene, capfd):
    build_rig_scene(with_button=False)
    lower, upper = linked_cuffs()
    shared = lower.data
    capfd.readouterr()
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Cuff.Lower,Cuff.Upper") == {"FINISHED"}
    assert ("Cuff.Lower: 160 copied, 0 inpainted (0%); shared its mesh 'Cuff.Lower' with 'Cuff.Upper': it now has "
            "its own copy, so each keeps its own weights; Cuff.Upper: 160 copied, 0 inpainted (0%)"
            in "".join(capfd.readouterr()))
    assert lower.data != upper.data and upper.data == shared
    for cuff in (lower, upper):
        weights = group_weights(cuff, [LOWER_BONE, UPPER_BONE])
        np.testing.assert_allclose(weights, expected_body_weights(world_heights(cuff)), atol=1e-3)
    assert group_weights(lower, [LOWER_BONE]).min() == 1.0 and group_weights(upper, [UPPER_BONE]).min() == 1.0


def test_skinning_linked_duplicates_gives_each_its_own_mesh_and_weights(clean_scene, capfd):
    armature = make_armature()
    lower, upper = linked_cuffs()
    select_only([armature, lower, upper], active=armature)
    capfd.readouterr()
    assert bpy.ops.autorig.skin_weights(skin_resolution=40) == {"FINISHED"}
    assert "'Cuff.Lower' shared its mesh 'Cuff.Lower' with 'Cuff.Upper'" in "".join(capfd.readouterr())
    assert lower.data != upper.data
    assert group_weights(lower, [LOWER_BONE]).min() > 0.9
    assert group_weights(upper, [UPPER_BONE]).min() > 0.9


def test_a_failed_write_shares_the_mesh_again_and_leaves_no_copy(clean_scene, monkeypatch):
    rig = build_rig_scene(with_button=False)
    lower, upper = linked_cuffs()
    meshes_before = sorted(mesh.name for mesh in bpy.data.meshes)
    before = scene_state([rig.body, lower, upper])

    def fail_on_second(obj, status):
        if obj == upper:
            raise OSError("disk full")

    monkeypatch.setattr(transfer_job, "write_status_attribute", fail_on_second)
    with pytest.raises(RuntimeError, match="OSError: disk full"):
        bpy.ops.autorig.transfer_weights(source="Body", targets="Cuff.Lower,Cuff.Upper")
    assert lower.data == upper.data
    assert sorted(mesh.name for mesh in bpy.data.meshes) == meshes_before
    assert scene_state([rig.body, lower, upper]) == before


def test_skinning_default_meshes_that_are_all_helpers_is_refused_naming_them(clean_scene):
    from autorig_addon.blender.jobs.skin import SkinSettings, plan_skin

    rig = build_rig_scene(with_button=False)
    shape = bone_shape(rig.armature)
    before = scene_state([rig.armature, shape])
    with pytest.raises(InputError, match=re.escape(
            f"Nothing to skin: the meshes found ('{shape.name}') are helpers (bone shapes, hidden from render). "
            "Name the meshes to skin them: --mesh on the command line, meshes= from Python.")):
        plan_skin(rig.armature, [shape], SkinSettings(), bpy.context.evaluated_depsgraph_get(), named=False)
    assert scene_state([rig.armature, shape]) == before
