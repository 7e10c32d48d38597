"""Rigged-character loading, bind-pose checks, simplification and samples
(autorig_addon.blender.characters), on scenes built in code."""

import json
import math
import struct

import bpy
import numpy as np
import pytest

from autorig_addon.blender import bind_pose, bone_heat, characters, scene_io, simplify
from autorig_addon.core import dataset
from autorig_addon.core.errors import InputError
from autorig_addon.core.geometry.weld import weld_seams
from autorig_addon.core.types import Mesh, Skeleton, Weights
from blender_fixtures import (
    BODY_HEIGHT,
    BODY_RADIUS,
    LOWER_BONE,
    UPPER_BONE,
    add_weights,
    bind,
    box_geometry,
    build_rig_scene,
    expected_body_weights,
    make_armature,
    mesh_object,
    reset_scene,
)
from geometry_fixtures import arm_posed_humanoid, points_along_bones

#: Bounding-box diagonal of the body cylinder (0.6 x 0.6 x 2).
BODY_SIZE = math.sqrt((2 * BODY_RADIUS) ** 2 * 2 + BODY_HEIGHT ** 2)


def save_rig(path, edit=None):
    """The reference rig scene (armature, skinned body, loose sleeve) saved to ``path``."""
    reset_scene()
    rig = build_rig_scene(with_button=False)
    if edit is not None:
        edit(rig)
    bpy.context.view_layer.update()
    scene_io.save_scene(path)
    return rig


def patch_glb_node(path, node_name, translation):
    """Rewrite a .glb so one joint's node translation differs from its bind pose
    (the inverse bind matrices stay): the skeleton was moved after binding."""
    data = path.read_bytes()
    json_length = struct.unpack_from("<I", data, 12)[0]
    document = json.loads(data[20:20 + json_length])
    node = next(node for node in document["nodes"] if node.get("name") == node_name)
    node["translation"] = list(translation)
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + json_length:]
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, 20 + len(text) + len(rest))
                     + struct.pack("<II", len(text), 0x4E4F534A) + text + rest)


@pytest.mark.parametrize("extension", [".blend", ".glb"])
def test_load_character_reads_mesh_skeleton_and_weights(clean_scene, tmp_path, extension):
    path = tmp_path / f"rig{extension}"
    save_rig(path)
    character = characters.load_character(path, category="test")
    assert character.name == "rig" and character.category == "test" and character.armature_name == "Armature"
    assert character.mesh.object_names == ("Body",)
    # Every vertex of the cylinder lies on it, in world space.
    radial = np.linalg.norm(character.mesh.vertices[:, :2], axis=1)
    assert np.all((np.abs(radial - BODY_RADIUS) < 1e-5) | (radial < 1e-6))
    np.testing.assert_allclose(character.weights.matrix, expected_body_weights(character.mesh.vertices[:, 2]),
                               atol=1e-5)
    assert character.weights.bone_names == (LOWER_BONE, UPPER_BONE)
    assert character.skeleton.names == (LOWER_BONE, UPPER_BONE)
    np.testing.assert_allclose(character.skeleton.joints, [[0, 0, 0], [0, 0, 1]], atol=1e-5)
    np.testing.assert_array_equal(character.skeleton.deform, [True, True])
    assert character.unweighted_count == 0
    assert character.size == pytest.approx(BODY_SIZE, rel=1e-5)
    assert any("Sleeve" in note and "left out" in note for note in character.notes)
    # Real one-metre bones: their stored tails are kept, and the notes say so.
    assert any(note.startswith("stored bone tails used") for note in character.notes)
    np.testing.assert_allclose(character.skeleton.tails[0], [0, 0, 1], atol=1e-5)


def test_loader_picks_the_armature_with_most_skinned_vertices(clean_scene, tmp_path):
    def add_second_rig(rig):
        small = make_armature("Small")
        small.location = (3.0, 0.0, 0.0)
        vertices, faces = box_geometry((3.0, 0.0, 0.5), 0.2)
        box = mesh_object("Box", vertices, faces)
        add_weights(box, [LOWER_BONE], np.ones((8, 1)))
        bind(box, small)

    path = tmp_path / "two.blend"
    save_rig(path, add_second_rig)
    character = characters.load_character(path)
    assert character.armature_name == "Armature"
    assert character.mesh.vertex_count == 506
    assert any("'Small' (8 vertices)" in note for note in character.notes)


def test_unweighted_vertices_and_idle_bones_are_reported(clean_scene, tmp_path):
    def drop_upper_group(rig):
        rig.body.vertex_groups[UPPER_BONE].remove(list(range(len(rig.body.data.vertices))))

    path = tmp_path / "holes.blend"
    save_rig(path, drop_upper_group)
    character = characters.load_character(path)
    z = character.mesh.vertices[:, 2]
    # From z = 1.2 up only Upper had weight: 9 rings of 24 and the top centre.
    assert character.unweighted_count == int(np.sum(z > 1.2 - 1e-6)) == 9 * 24 + 1
    # Upper carries no weight any more: it is not a deform bone of the reference.
    np.testing.assert_array_equal(character.skeleton.deform, [True, False])
    assert character.weights.bone_names == (LOWER_BONE,)
    # Rows are normalised: the blend region now belongs to Lower alone.
    np.testing.assert_allclose(character.weights.matrix[z < 1.2 - 1e-6, 0], 1.0)
    assert any("no weight" in note and UPPER_BONE in note for note in character.notes)
    assert any(f"{character.unweighted_count} of 506 vertices" in note for note in character.notes)


def test_file_without_skinned_mesh_is_an_input_error(clean_scene, tmp_path):
    reset_scene()
    mesh_object("Lonely", *box_geometry((0, 0, 0), 1.0))
    path = tmp_path / "plain.blend"
    scene_io.save_scene(path)
    with pytest.raises(InputError, match="No armature"):
        characters.load_character(path)


@pytest.mark.parametrize("extension", [".blend", ".glb"])
def test_good_rig_deforms_to_itself(clean_scene, tmp_path, extension):
    path = tmp_path / f"good{extension}"
    save_rig(path)
    check = bind_pose.check_bind_pose(path)
    assert check.deforms_to_itself and check.rest_error < 1e-6
    assert check.reasons == ()
    # glTF export splits the 506 vertices along the fixture's flat-shaded edges.
    assert check.vertex_count == {".blend": 506, ".glb": 1058}[extension]
    if extension == ".glb":
        assert check.pose_error < 1e-6
    else:
        assert math.isnan(check.pose_error)  # a .blend has no default pose apart from its rest


def test_skeleton_moved_after_binding_is_caught(clean_scene, tmp_path):
    path = tmp_path / "moved.glb"
    save_rig(path)
    # The Upper joint's node moves 0.5 sideways; its inverse bind matrix stays.
    patch_glb_node(path, UPPER_BONE, [0.5, 1.0, 0.0])
    check = bind_pose.check_bind_pose(path)
    # Vertices weighted wholly to Upper move by exactly 0.5.
    assert check.pose_error == pytest.approx(0.5 / BODY_SIZE, rel=1e-4)
    assert check.rest_error < 1e-6
    assert not check.deforms_to_itself
    assert any(UPPER_BONE in reason for reason in check.reasons)
    assert any("inverse bind matrices" in reason for reason in check.reasons)


def test_animation_is_not_taken_for_the_default_pose(clean_scene, tmp_path):
    def animate(rig):
        pose_bone = rig.armature.pose.bones[UPPER_BONE]
        pose_bone.rotation_mode = "XYZ"
        pose_bone.rotation_euler = (0.8, 0.0, 0.0)
        pose_bone.keyframe_insert("rotation_euler", frame=1)
        pose_bone.rotation_euler = (0.0, 0.0, 0.0)
        pose_bone.keyframe_insert("rotation_euler", frame=20)

    path = tmp_path / "animated.glb"
    save_rig(path, animate)
    scene_io.load_scene(path)
    assert bpy.data.actions, "the fixture must carry an animation"
    check = bind_pose.check_bind_pose(path)
    assert check.deforms_to_itself, check


def test_shape_keys_and_modifiers_before_the_armature_are_reasons(clean_scene, tmp_path):
    def add_shape_key_and_displace(rig):
        rig.body.shape_key_add(name="Basis")
        key = rig.body.shape_key_add(name="Fat")
        for point in key.data:
            point.co.x *= 1.5
        key.value = 1.0
        displace = rig.body.modifiers.new("Push", "DISPLACE")
        displace.strength = 0.0
        rig.body.modifiers.move(len(rig.body.modifiers) - 1, 0)

    path = tmp_path / "keys.blend"
    save_rig(path, add_shape_key_and_displace)
    check = bind_pose.check_bind_pose(path)
    # The key widens x by half: the widest vertex moves 0.5 * 0.3.
    assert check.rest_error == pytest.approx(0.15 / BODY_SIZE, rel=1e-4)
    assert any("Fat" in reason for reason in check.reasons)
    assert any("Push (Displace)" in reason for reason in check.reasons)


def test_simplify_hits_the_target_and_carries_weights(clean_scene):
    reset_scene()
    rig = build_rig_scene(with_button=False)
    character = characters.read_character("body")
    # Split every vertex of the first 40 triangles, as a UV seam would.
    mesh = character.mesh
    seams = mesh.triangles[:40].ravel()
    split_vertices = np.vstack([mesh.vertices, mesh.vertices[seams]])
    triangles = mesh.triangles.copy()
    triangles[:40] = (mesh.vertex_count + np.arange(120)).reshape(40, 3)
    split = Mesh(split_vertices, triangles)
    split_weights = type(character.weights)(
        np.vstack([character.weights.matrix, character.weights.matrix[seams]]), character.weights.bone_names
    )
    welded, welded_weights = weld_seams(split, split_weights)
    assert welded.vertex_count == mesh.vertex_count
    simple, simple_weights = simplify.simplify(split, split_weights, 200)
    assert abs(simple.vertex_count - 200) <= simplify.SIMPLIFY_COUNT_TOLERANCE * 200
    assert simple_weights.matrix.shape == (simple.vertex_count, 2)
    np.testing.assert_allclose(simple_weights.matrix.sum(axis=1), 1.0)
    # The body's weights are linear in z between rings, and the collapse
    # interpolates them like positions, so they still follow the height.
    np.testing.assert_allclose(simple_weights.matrix, expected_body_weights(simple.vertices[:, 2]), atol=0.05)
    assert "AutoRig scratch" not in bpy.data.objects and "AutoRig scratch" not in bpy.data.meshes
    assert rig.body.name in bpy.data.objects
    # A target above the welded count refines first: same shape, same weights.
    dense, dense_weights = simplify.simplify(split, split_weights, 1500)
    assert abs(dense.vertex_count - 1500) <= simplify.SIMPLIFY_COUNT_TOLERANCE * 1500
    radial = np.linalg.norm(dense.vertices[:, :2], axis=1)
    assert radial.max() <= BODY_RADIUS + 1e-6 and dense.vertices[:, 2].min() >= -1e-6
    np.testing.assert_allclose(dense_weights.matrix, expected_body_weights(dense.vertices[:, 2]), atol=0.05)


def test_bone_heat_weights_on_a_copy(clean_scene):
    reset_scene()
    rig = build_rig_scene(with_button=False)
    character = characters.read_character("body")
    objects_before = sorted(obj.name for obj in bpy.data.objects)
    weights = bone_heat.bone_heat_weights(character.mesh, character.skeleton, rig.armature)
    assert sorted(obj.name for obj in bpy.data.objects) == objects_before
    assert weights.bone_names == (LOWER_BONE, UPPER_BONE)
    # Bone heat reached every vertex; its rows are close to, not exactly, one.
    rows = weights.matrix.sum(axis=1)
    assert np.all(rows > 0.9) and np.all(rows < 1.0 + 1e-6)
    share = weights.matrix / rows[:, None]
    z = character.mesh.vertices[:, 2]
    assert np.all(share[z < 0.5, 0] > 0.9) and np.all(share[z > 1.5, 1] > 0.9)
    # The artist's groups on the body are untouched.
    assert [group.name for group in rig.body.vertex_groups] == [LOWER_BONE, UPPER_BONE]


def test_character_samples_are_cached(clean_scene, tmp_path, monkeypatch):
    path = tmp_path / "chars" / "pack" / "rig.glb"
    save_rig(path)
    split = dataset.DataSplit(("pack/rig.glb",), (), {"pack/rig.glb": "biped"})
    first = characters.build_character_samples([path], tmp_path / "cache", 200, root=tmp_path / "chars", split=split)[0]
    assert first.name == "pack/rig" and first.category == "biped"
    assert abs(len(first.vertices) - 200) <= 10 and first.source_vertex_count > 200
    assert first.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-9)
    assert first.vertices[:, 2].max() == pytest.approx(1.0)  # 2 tall, 0.6 wide: height is the longest side

    def must_not_load(*_args, **_kwargs):
        raise AssertionError("the cached sample should have been used")

    monkeypatch.setattr(characters, "load_simplified", must_not_load)
    second = characters.build_character_samples([path], tmp_path / "cache", 200, root=tmp_path / "chars",
                                                split=split)[0]
    np.testing.assert_array_equal(first.vertices, second.vertices)
    np.testing.assert_array_equal(first.weights, second.weights)


def test_loader_notes_rigid_weights_the_mixamo_check_and_a_humanoids_rest_pose():
    skeleton = arm_posed_humanoid(70.0, 70.0)
    mesh, owners = points_along_bones(skeleton)
    weights = Weights(np.eye(len(skeleton.names))[owners], skeleton.names)
    humanoid = characters.RiggedCharacter("guy", "guy.glb", mesh, skeleton, weights, category=dataset.HUMANOID)
    notes = characters.weight_and_pose_notes(humanoid)
    assert notes[0] == "rigid weights: every weighted vertex follows one bone"
    assert notes[1].startswith("weights checked against the bone names: plausible (0 of 300 vertices unweighted;")
    assert notes[2] == "rest pose: arms down (arms 70 and 70 degrees below horizontal, left and right)"
    # Blended weights, no Mixamo names, and not a humanoid: nothing to say.
    blended = Weights(0.5 * np.eye(len(skeleton.names))[owners] + 0.5 * np.eye(len(skeleton.names))[0],
                      skeleton.names)
    plain_names = tuple(name.replace("mixamorig:", "") for name in skeleton.names)
    plain = Skeleton(skeleton.joints, skeleton.parents, plain_names)
    animal = characters.RiggedCharacter("cat", "cat.glb", mesh, plain, Weights(blended.matrix, plain.names),
                                        category="quadruped")
    assert characters.weight_and_pose_notes(animal) == []
    # A humanoid whose arms the names do not tell says so.
    anonymous = Skeleton(skeleton.joints, skeleton.parents, tuple(f"bone_{k}" for k in range(len(skeleton.names))))
    faceless = characters.RiggedCharacter("x", "x.glb", mesh, anonymous, Weights(blended.matrix, anonymous.names),
                                          category=dataset.HUMANOID)
    assert characters.weight_and_pose_notes(faceless) == ["rest pose: no left and right arm found by name"]


def test_train_samples_builds_every_split_character_and_reports_failures(clean_scene, tmp_path, capsys):
    from autorig_addon.training.command import _build_samples

    characters_folder = tmp_path / "characters"
    (characters_folder / "pack").mkdir(parents=True)
    save_rig(characters_folder / "pack" / "guy.glb")
    (characters_folder / "pack" / "broken.glb").write_bytes(b"not a glTF file")
    split_file = tmp_path / "split.json"
    split_file.write_text(json.dumps({"train": ["pack/guy.glb"], "validation": ["pack/broken.glb"],
                                      "excluded": {"pack/odd.glb": "its mesh is broken"}}))
    failed = _build_samples(characters_folder, tmp_path / "samples", split_file)
    assert failed == 1
    assert len(list((tmp_path / "samples").glob("guy-*.npz"))) == 1
    lines = capsys.readouterr().err.splitlines()
    assert any(line.startswith("[1/2] pack/guy.glb: ") and line.endswith(" vertices, unknown") for line in lines)
    assert any(line.startswith("[2/2] pack/broken.glb: FAILED: Error: Bad glTF: json error") for line in lines)
    assert any(line.startswith("1 samples in ") and line.endswith("1 failed; 1 files left out by the split "
                                                                  "(data_split.json 'excluded')") for line in lines)
