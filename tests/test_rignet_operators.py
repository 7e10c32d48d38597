"""RigNet rig files through Blender: building armatures, import and export operators."""

import re

import numpy as np
import pytest

from autorig_addon.blender.jobs import rignet
from autorig_addon.core.errors import InputError
from autorig_addon.core.io.rignet_rig import read_rignet_rig
from autorig_addon.core.types import Skeleton
from blender_fixtures import (
    LOWER_BONE,
    UPPER_BONE,
    build_rig_scene,
    group_weights,
    make_armature,
    scene_state,
    select_only,
)

pytestmark = pytest.mark.all_blenders

#: Two joints up z, a root and its child, vertices 0 to 2 skinned.
TWO_JOINT_RIG = ("joints root 0 0 0\njoints tip 0 0 1\nroot root\nhier root tip\n"
                 "skin 0 root 1.0\nskin 1 tip 1.0\nskin 2 root 0.5 tip 0.5\n")


def test_build_armature_reproduces_skeleton_in_world_space(clean_scene):
    from autorig_addon.blender.armature_builder import build_armature
    from autorig_addon.blender.convert import read_skeleton

    skeleton = Skeleton(
        joints=[[0, 0, 1], [0, 0, 1.5], [0.2, 0, 1.4], [-0.2, 0, 1.4]],
        parents=[-1, 0, 1, 1], names=("spine", "chest", "arm.L", "arm.R"),
        deform=[True, True, True, False],
    )
    armature = build_armature(skeleton, "Built")
    again = read_skeleton(armature)
    assert again.names == skeleton.names
    np.testing.assert_allclose(again.joints, skeleton.joints, atol=1e-6)
    np.testing.assert_allclose(again.tails, skeleton.tails, atol=1e-6)
    np.testing.assert_array_equal(again.parents, skeleton.parents)
    np.testing.assert_array_equal(again.deform, [True, True, True, False])
    assert armature.data.bones["chest"].use_connect  # head on the parent's tail
    assert not armature.data.bones["arm.L"].use_connect
    assert armature.mode == "OBJECT"


def test_zero_length_bone_is_refused_and_nothing_is_left(clean_scene):
    import bpy

    from autorig_addon.blender.armature_builder import build_armature

    skeleton = Skeleton(joints=[[0, 0, 0], [0, 0, 1]], parents=[-1, 0], names=("a", "b"),
                        tails=[[0, 0, 1], [0, 0, 1]])
    before = (len(bpy.data.objects), len(bpy.data.armatures))
    with pytest.raises(InputError, match=re.escape("1 bone(s) have zero length (b); Blender cannot keep them.")):
        build_armature(skeleton, "Broken")
    assert (len(bpy.data.objects), len(bpy.data.armatures)) == before


def test_export_then_import_round_trips_bones_and_weights(clean_scene, tmp_path):
    import bpy

    scene = build_rig_scene(with_button=False)
    path = str(tmp_path / "rig.txt")
    select_only([scene.body], active=scene.body)
    assert bpy.ops.autorig.export_rignet(filepath=path) == {"FINISHED"}
    skeleton, weights = read_rignet_rig(path, vertex_count=len(scene.body.data.vertices))
    assert skeleton.names == (LOWER_BONE, UPPER_BONE)
    np.testing.assert_array_equal(skeleton.parents, [-1, 0])
    np.testing.assert_allclose(skeleton.joints, [[0, 0, 0], [0, 0, 1]], atol=1e-6)
    np.testing.assert_allclose(weights.matrix, group_weights(scene.body, skeleton.names), atol=1e-6)

    # Re-import onto a fresh copy of the body without groups.
    copy = scene.body.copy()
    copy.data = scene.body.data.copy()
    copy.vertex_groups.clear()
    copy.modifiers.clear()
    copy.parent = None
    bpy.context.scene.collection.objects.link(copy)
    select_only([copy], active=copy)
    assert bpy.ops.autorig.import_rignet(filepath=path) == {"FINISHED"}
    imported = bpy.data.objects["rig"]
    assert imported.type == "ARMATURE" and copy.parent == imported
    assert [bone.name for bone in imported.data.bones] == [LOWER_BONE, UPPER_BONE]
    np.testing.assert_allclose([tuple(bone.head_local) for bone in imported.data.bones], skeleton.joints, atol=1e-6)
    np.testing.assert_allclose(group_weights(copy, skeleton.names), weights.matrix, atol=1e-6)
    assert any(m.type == "ARMATURE" and m.object == imported for m in copy.modifiers)


def test_import_with_wrong_vertex_count_leaves_the_scene_unchanged(clean_scene, tmp_path):
    import bpy

    from blender_fixtures import mesh_object

    path = tmp_path / "rig.txt"
    path.write_text("joints root 0 0 0\njoints tip 0 0 1\nroot root\nhier root tip\nskin 5 root 1.0\n")
    small = mesh_object("Small", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    select_only([small], active=small)
    before = sorted(o.name for o in bpy.data.objects)
    with pytest.raises(RuntimeError, match=re.escape(
            "Line 5: vertex index 5 is out of range for a mesh of 3 vertices; "
            "the rig file does not belong to this mesh.")):
        bpy.ops.autorig.import_rignet(filepath=str(path))
    assert sorted(o.name for o in bpy.data.objects) == before
    assert len(small.vertex_groups) == 0


def test_import_onto_a_mesh_the_file_leaves_mostly_unweighted_is_refused(clean_scene, tmp_path):
    import bpy

    from blender_fixtures import mesh_object

    path = tmp_path / "rig.txt"
    path.write_text(TWO_JOINT_RIG)  # weights vertices 0 to 2
    grid = [[x, y, 0] for y in range(3) for x in range(3)]
    bigger = mesh_object("Bigger", grid, [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]])
    bpy.context.view_layer.update()
    select_only([bigger], active=bigger)
    before = scene_state([bigger])
    with pytest.raises(RuntimeError, match=re.escape(
            "The file weights 3 of the 9 vertices of 'Bigger' and leaves the rest without weight: "
            "it is not the mesh the rig was made for.")):
        bpy.ops.autorig.import_rignet(filepath=str(path))
    assert scene_state([bigger]) == before


def test_export_of_a_mesh_whose_last_vertex_is_unweighted_imports_back_onto_it(clean_scene, tmp_path, capfd):
    import bpy

    scene = build_rig_scene(with_button=False)
    body = scene.body
    last = len(body.data.vertices) - 1  # the top cap's centre
    for group in body.vertex_groups:
        group.remove([last])  # legal: a vertex may have no weight, and then has no 'skin' line
    names = (LOWER_BONE, UPPER_BONE)
    exported = group_weights(body, names)
    assert not exported[last].any() and exported[:last].sum(axis=1).min() > 0.99
    path = tmp_path / "rig.txt"
    select_only([body], active=body)
    assert bpy.ops.autorig.export_rignet(filepath=str(path)) == {"FINISHED"}
    assert f"skin {last - 1} " in path.read_text() and f"skin {last} " not in path.read_text()

    assert bpy.ops.autorig.import_rignet(filepath=str(path)) == {"FINISHED"}
    imported = bpy.data.objects["rig"]
    np.testing.assert_allclose(group_weights(body, names), exported, atol=1e-6)
    assert [m.object for m in body.modifiers if m.type == "ARMATURE"] == [imported]
    assert ("Imported 'rig' with 2 bones, 'Body' bound (1 of its vertices have no weight in the file and stay "
            "in place when posed).") in capfd.readouterr().out


@pytest.mark.parametrize("content, message", [
    (b"glTF\x02\x00\x00\x00",
     "'picked.txt' is a binary glTF file, not a RigNet rig: import it with File > Import > glTF 2.0."),
    (b"\x89PNG\r\n\x1a\n", "'picked.txt' is not a RigNet rig: it is not text (byte 0x89 at position 0 is not UTF-8)."),
    (b"joints a 0 0 0\njoints b 0 0 1e30\nroot a\nhier a b\n", "Line 2: joint 'b' lies at 0, 0, 1e+30, beyond 1e+06"),
    (b"joints a 0 0 0\njoints b 0 0 0\nroot a\nhier a b\n",
     "Line 2: joint 'b' is at the same position as its parent 'a'"),
    (b"joints a 0 0 0\njoints b 0 0 1\nroot a\nhier a b\nskin 1000000000000 a 1\n",
     "Line 5: vertex index 1000000000000 is larger than any mesh can have"),
])
def test_import_of_a_wrong_or_damaged_file_reports_why_and_changes_nothing(clean_scene, tmp_path, content, message):
    import bpy

    from blender_fixtures import mesh_object

    path = tmp_path / "picked.txt"
    path.write_bytes(content)
    mesh = mesh_object("Triangle", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    bpy.context.view_layer.update()
    for active in (mesh, None):
        select_only([mesh] if active else [], active=active)
        before = scene_state([mesh])
        with pytest.raises(RuntimeError, match=re.escape(message)):
            bpy.ops.autorig.import_rignet(filepath=str(path))
        assert scene_state([mesh]) == before and len(bpy.data.armatures) == 0


def test_import_that_fails_while_writing_leaves_neither_armature_nor_groups(clean_scene, tmp_path, monkeypatch):
    import bpy

    from blender_fixtures import mesh_object

    path = tmp_path / "rig.txt"
    path.write_text(TWO_JOINT_RIG)
    mesh = mesh_object("Triangle", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    bpy.context.view_layer.update()
    before = scene_state([mesh])
    real_write = rignet.write_weights

    def write_then_fail(obj, weights, armature, **kwargs):
        real_write(obj, weights, armature, **kwargs)  # groups, modifier and parent are in place...
        raise RuntimeError("disk full")  # ...when the write fails

    monkeypatch.setattr(rignet, "write_weights", write_then_fail)
    with pytest.raises(RuntimeError, match="disk full"):
        rignet.import_rignet_rig(bpy.context, str(path), mesh)
    assert scene_state([mesh]) == before
    assert "rig" not in bpy.data.objects and "rig" not in bpy.data.armatures


def test_import_normalises_weights_the_file_left_unnormalised_and_says_so(clean_scene, tmp_path, capfd):
    import bpy

    from blender_fixtures import mesh_object

    path = tmp_path / "loud.txt"
    path.write_text("joints root 0 0 0\njoints tip 0 0 1\nroot root\nhier root tip\n"
                    "skin 0 root 5.0\n"             # one bone at 5: becomes 1
                    "skin 1 root 5.0 tip 15.0\n"    # sums to 20: becomes 0.25 / 0.75
                    "skin 2 root 0.1 tip 0.2\n"     # sums to 0.3: becomes 1/3 / 2/3
                    "skin 3 root 0.5 tip 0.5\n"     # already sums to 1
                    "skin 4 root 0.0 tip 0.0\n")    # sums to 0: stays unweighted
    fan = mesh_object("Fan", [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [-1, 1, 0]],
                      [[0, 1, 2], [0, 2, 3], [0, 3, 4]])
    bpy.context.view_layer.update()
    select_only([fan], active=fan)
    capfd.readouterr()

    assert bpy.ops.autorig.import_rignet(filepath=str(path)) == {"FINISHED"}

    np.testing.assert_allclose(group_weights(fan, ("root", "tip")),
                               [[1, 0], [0.25, 0.75], [1 / 3, 2 / 3], [0.5, 0.5], [0, 0]], atol=1e-6)
    assert ("Imported 'loud' with 2 bones, 'Fan' bound (1 of its vertices have no weight in the file and stay in "
            "place when posed); the weights of 3 vertices did not sum to 1 in the file (sums from 0.3 to 20); each "
            "was scaled to sum to 1.") in capfd.readouterr().out


def test_export_in_edit_mode_writes_the_unsaved_bone_edits_and_stays_in_edit_mode(clean_scene, tmp_path):
    import bpy

    armature = make_armature("Rig")
    select_only([armature], active=armature)
    bpy.ops.object.mode_set(mode="EDIT")
    upper = armature.data.edit_bones[UPPER_BONE]
    upper.use_connect = False
    upper.head = (0.2, 0.0, 1.1)  # was (0, 0, 1); not saved to the armature data until Edit Mode is left
    path = tmp_path / "rig.txt"

    assert bpy.ops.autorig.export_rignet(filepath=str(path)) == {"FINISHED"}

    skeleton, _ = read_rignet_rig(str(path))
    np.testing.assert_allclose(skeleton.joints[skeleton.names.index(UPPER_BONE)], [0.2, 0.0, 1.1], atol=1e-6)
    assert armature.mode == "EDIT" and bpy.context.mode == "EDIT_ARMATURE"
    np.testing.assert_allclose(tuple(armature.data.edit_bones[UPPER_BONE].head), [0.2, 0.0, 1.1], atol=1e-6)
    bpy.ops.object.mode_set(mode="OBJECT")


def test_import_without_a_mesh_builds_the_armature_alone(clean_scene, tmp_path):
    import bpy

    path = tmp_path / "alone.txt"
    path.write_text(TWO_JOINT_RIG)
    armature, notes = rignet.import_rignet_rig(bpy.context, str(path))
    assert armature.name == "alone" and notes == []
    assert [(bone.name, bone.parent.name if bone.parent else None) for bone in armature.data.bones] == [
        ("root", None), ("tip", "root")]
    np.testing.assert_allclose([tuple(bone.head_local) for bone in armature.data.bones], [[0, 0, 0], [0, 0, 1]])


def test_export_refuses_an_armature_without_deform_bones(clean_scene, tmp_path):
    armature = make_armature("Controls", deform_upper=False)
    armature.data.bones[LOWER_BONE].use_deform = False
    path = tmp_path / "rig.txt"
    with pytest.raises(InputError, match="^'Controls' has no deform bones to export.$"):
        rignet.export_rignet_rig(str(path), armature)
    assert not path.exists()


def test_import_onto_a_linked_duplicate_gives_it_its_own_mesh(clean_scene, tmp_path, capfd):
    import bpy

    scene = build_rig_scene(with_button=False)
    path = str(tmp_path / "rig.txt")
    select_only([scene.body], active=scene.body)
    assert bpy.ops.autorig.export_rignet(filepath=path) == {"FINISHED"}
    mesh = scene.body.data.copy()  # shared by two objects below
    first = bpy.data.objects.new("First", mesh)
    twin = bpy.data.objects.new("Twin", mesh)
    for obj in (first, twin):
        bpy.context.scene.collection.objects.link(obj)
        obj.vertex_groups.clear()
    mesh_weights_before = [[(e.group, e.weight) for e in v.groups] for v in mesh.vertices]
    select_only([first], active=first)
    capfd.readouterr()
    assert bpy.ops.autorig.import_rignet(filepath=path) == {"FINISHED"}
    assert first.data is not mesh and twin.data is mesh
    assert [[(e.group, e.weight) for e in v.groups] for v in mesh.vertices] == mesh_weights_before
    _, weights = read_rignet_rig(path, vertex_count=len(mesh.vertices))
    np.testing.assert_allclose(group_weights(first, (LOWER_BONE, UPPER_BONE)), weights.matrix, atol=1e-6)
    assert (f"Imported 'rig' with 2 bones, 'First' bound; it shared its mesh '{mesh.name}' with 'Twin': it now has "
            "its own copy, so each keeps its own weights.") in capfd.readouterr().out
