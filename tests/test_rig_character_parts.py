"""What is not the character, in Predict Skeleton, Auto-Rig and the ``rig``
command (``core.rigging.character_parts`` through ``blender.jobs.rig``):
a ground plane selected with the character, a stray triangle in its mesh,
two characters side by side, a sword beside one; built as a user builds
them, with real bpy."""

import json
import re

import bpy
import numpy as np
import pytest

from autorig_addon.blender import convert, scene_io
from autorig_addon.cli.main import main
from autorig_addon.core.procedural import generate_character
from blender_fixtures import (
    BIPED_SEED,
    add_biped,
    armatures,
    evaluated_world_vertices,
    group_weights,
    mesh_object,
    pose_bone_turned,
    reset_scene,
    scene_state,
    select_only,
)
from geometry_fixtures import box_mesh, grid

pytestmark = pytest.mark.all_blenders

# The biped (blender_fixtures.add_biped) is 0.94 tall (feet at z 0.074), 0.6 wide with its arms out.
#: A bone tail may stick out of the character's bounding box by this share of its diagonal (a leaf's tail is
#: extrapolated from its chain); heads may not.
BOX_SLACK = 0.05
#: A stray triangle's distance from the origin along +x, metres.
SPECK_X = 100.0


def biped_geometry():
    mesh = generate_character(BIPED_SEED, "biped").mesh
    return mesh.vertices, mesh.triangles


def add_ground(name="Ground", side=4.0):
    """A level plane of ``side`` under the biped's feet, 5 by 5 vertices, as Add > Mesh > Plane scaled."""
    sheet = grid(5, 5, side)
    feet = biped_geometry()[0][:, 2].min()
    obj = mesh_object(name, sheet.vertices + [-side / 2, -side / 2, feet], sheet.triangles)
    bpy.context.view_layer.update()
    return obj


def outside_box(points, vertices) -> np.ndarray:
    """(k,) how far each point lies outside the vertices' bounding box, share of its diagonal (0 inside)."""
    low, high = vertices.min(0), vertices.max(0)
    outside = np.maximum(low - points, 0) + np.maximum(points - high, 0)
    return np.linalg.norm(outside, axis=1) / np.linalg.norm(high - low)


def assert_skeleton_within_the_biped(armature):
    skeleton = convert.read_skeleton(armature)
    body = biped_geometry()[0]
    assert outside_box(skeleton.joints, body).max() == 0.0
    assert outside_box(skeleton.tails, body).max() <= BOX_SLACK
    return skeleton


def test_auto_rig_leaves_a_ground_plane_selected_with_the_character_unbound(clean_scene, capfd):
    """The plane, active in the selection, is not bound, gets no bones and
    does not name the armature; before, the prediction was refused as poor
    ("spine lies mostly outside the body"), and kept anyway it had bones on
    the plane's corners (joints 1.86 from the centre) and the plane was bound."""
    body, ground = add_biped(), add_ground()
    select_only([body, ground], active=ground)
    ground_before = scene_state([ground])
    ground_before.pop("objects")

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    assert armature.name == "Biped_rig"
    skeleton = assert_skeleton_within_the_biped(armature)
    np.testing.assert_allclose(group_weights(body, skeleton.names).sum(axis=1), 1.0, atol=1e-5)
    ground_after = scene_state([ground])
    ground_after.pop("objects")
    assert ground_after == ground_before and ground.parent is None
    assert ("'Ground' is flat, under the character and wider than it: left out of the skeleton and not bound "
            "(a ground plane?)") in capfd.readouterr().out


def test_a_stray_triangle_in_the_mesh_is_left_out_unweighted_and_stays_put(clean_scene, capfd):
    """A triangle 100 m away in the character's own mesh: no 97 m bone, no
    weight, and posing leaves it where it is; before, the prediction was
    refused as poor, and kept anyway the skinning refused the armature as
    lying far from the mesh."""
    vertices, triangles = biped_geometry()
    count = len(vertices)
    speck = [[SPECK_X, 0.0, 0.5], [SPECK_X + 0.05, 0.0, 0.5], [SPECK_X, 0.05, 0.55]]
    body = mesh_object("Body", np.vstack([vertices, speck]), np.vstack([triangles, [[count, count + 1, count + 2]]]))
    bpy.context.view_layer.update()
    select_only([body], active=body)

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    skeleton = assert_skeleton_within_the_biped(armature)
    weights = group_weights(body, skeleton.names)
    np.testing.assert_allclose(weights[:count].sum(axis=1), 1.0, atol=1e-5)
    assert not weights[count:].any()
    assert all(len(vertex.groups) == 0 for vertex in list(body.data.vertices)[count:])
    pose_bone_turned(armature, skeleton.names[0], 30.0)
    posed = evaluated_world_vertices(body)
    np.testing.assert_allclose(posed[count:], speck, atol=1e-5)
    assert np.abs(posed[:count] - vertices).max() > 0.01
    assert ("'Body': 1 loose piece of 3 vertices 99.7 m from the character was left out of the skeleton and left "
            "unweighted (a stray speck?)") in capfd.readouterr().out


def two_characters(how):
    """Two bipeds 3 m apart: two objects, a linked duplicate (Alt+D) or joined into one mesh (Ctrl+J)."""
    knight = add_biped("Knight")
    if how == "objects":
        return [knight, add_biped("Ogre", (3.0, 0.0, 0.0))]
    if how == "linked duplicate":
        duplicate = bpy.data.objects.new("Knight.001", knight.data)
        bpy.context.scene.collection.objects.link(duplicate)
        duplicate.location = (3.0, 0.0, 0.0)
        bpy.context.view_layer.update()
        return [knight, duplicate]
    vertices, triangles = biped_geometry()
    both = mesh_object("Knights", np.vstack([vertices, vertices + [3.0, 0.0, 0.0]]),
                       np.vstack([triangles, triangles + len(vertices)]))
    bpy.data.objects.remove(knight)
    bpy.context.view_layer.update()
    return [both]


@pytest.mark.parametrize(("how", "who"), [
    ("objects", "The meshes hold 2 characters: 'Knight' and 'Ogre' standing 2.4 m apart."),
    ("linked duplicate", "The meshes hold 2 characters: 'Knight' and 'Knight.001' standing 2.4 m apart."),
    ("joined", "'Knights' holds 2 characters: 2 parts of 'Knights' standing 2.4 m apart."),
])
def test_two_characters_are_refused_naming_them_and_the_scene_is_unchanged(clean_scene, how, who):
    """Before, the prediction was refused as poor ("leg.R lies mostly outside
    the body"), and kept anyway one 2.96 m bone joined the two."""
    objects = two_characters(how)
    select_only(objects, active=objects[0])
    before = scene_state(objects)
    fix = "select one character's meshes and rig it, then the next"
    if how == "joined":
        fix = ("first separate the characters joined in 'Knights' into objects of their own (Edit Mode: Mesh > "
               "Separate > By Loose Parts), then " + fix)
    for operator in (bpy.ops.autorig.predict_skeleton, bpy.ops.autorig.auto_rig):
        with pytest.raises(RuntimeError, match=re.escape(
                f"{who} One armature would span both: rig them one at a time: {fix}. Nothing was built.")):
            operator()
        assert scene_state(objects) == before and len(bpy.data.armatures) == 0


def test_a_sword_beside_the_character_is_not_a_second_character(clean_scene, capfd):
    """A blade 0.45 long lying on the ground 0.3 beside the biped (4 % of the
    area, 1 cm tall) is not refused as a second character: it is a prop set
    down (``core.rigging.props``), left out of the skeleton and not bound.
    Before props were told apart, the prediction read it and the feet came
    out poor."""
    body = add_biped()
    feet = biped_geometry()[0][:, 2].min()
    blade = box_mesh([0.6, -0.22, feet], [0.63, 0.23, feet + 0.01], 0.01)
    sword = mesh_object("Sword", blade.vertices, blade.triangles)
    bpy.context.view_layer.update()
    select_only([body, sword], active=body)

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    assert_skeleton_within_the_biped(armature)
    assert body.parent == armature and sword.parent is None and len(sword.modifiers) == 0
    assert ("'Sword' lies 0.468 m from the character and nothing holds it: left out of the skeleton and not bound "
            "(a prop set down?)") in capfd.readouterr().out


def run_main(arguments, capsys):
    capsys.readouterr()
    code = main(arguments)
    return code, capsys.readouterr().out


def test_the_rig_command_refuses_a_file_of_two_characters_then_rigs_one_named(clean_scene, tmp_path, capsys):
    """Without --mesh the command takes every mesh of the file: the refusal
    says how to name one character."""
    reset_scene()
    add_biped("Knight"), add_biped("Ogre", (3.0, 0.0, 0.0)), add_ground("Ground", 8.0)
    source, out = tmp_path / "two.blend", tmp_path / "out"
    scene_io.save_scene(source)

    code, stdout = run_main(["rig", str(source), "--out", str(out), "--quiet"], capsys)

    assert code == 1 and not out.exists()
    assert json.loads(stdout)["failed"][0]["error"] == (
        "The meshes hold 2 characters: 'Knight' and 'Ogre' standing 2.4 m apart. One armature would span both: rig "
        "them one at a time: name one character's meshes with --mesh. Nothing was built.")

    code, stdout = run_main(["rig", str(source), "--out", str(out), "--mesh", "Ogre,Ground", "--skin", "none",
                             "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert item["armature"] == "Ogre_rig" and item["meshes"] == ["Ogre"]
    assert item["notes"][0] == ("'Ground' is flat, under the character and wider than it: left out of the skeleton "
                                "(a ground plane?)")


def hair_cards(count: int = 12):
    """``count`` hair cards, each an open strip 0.016 wide of two quads, from
    just off the biped's scalp (around the back half of its head) down to
    its shoulders: vertices and triangles, as a hair mesh of its own."""
    character = generate_character(BIPED_SEED, "biped")
    vertices = character.mesh.vertices
    head_joint = character.skeleton.joints[list(character.skeleton.names).index("spine.006")]
    head = vertices[vertices[:, 2] > head_joint[2]]
    centre, radii = head.mean(axis=0), np.ptp(head, axis=0) / 2
    points, triangles = [], []
    for k in range(count):
        angle = np.pi * (0.15 + 0.7 * k / (count - 1))  # around the back of the head (+y)
        out = np.array([np.cos(angle), np.sin(angle), 0.0])
        top = centre + out * radii * 0.85 + [0.0, 0.0, 0.6 * radii[2]]  # the head is 0.8 of its radius wide there
        bottom = centre + out * radii * 1.15 - [0.0, 0.0, 1.6 * radii[2]]
        across = np.cross(out, [0.0, 0.0, 1.0]) * 0.008
        base = len(points)
        for along in (0.0, 0.5, 1.0):
            middle = top + along * (bottom - top)
            points += [middle - across, middle + across]
        for quad in (base, base + 2):
            triangles += [[quad, quad + 1, quad + 3], [quad, quad + 3, quad + 2]]
    return np.array(points), np.array(triangles)


def test_hair_cards_follow_the_head(clean_scene):
    """Twelve cards hanging from the scalp to the shoulders: bound wholly to
    the head, so turning the head turns them without stretching them. Before,
    weighted as body, 62 of their 72 vertices were mostly on the chest and
    the shoulders, and turning the head 45 degrees stretched card edges by up
    to 29 %."""
    body = add_biped()
    hair = mesh_object("Hair", *hair_cards())
    bpy.context.view_layer.update()
    select_only([body, hair], active=body)

    assert bpy.ops.autorig.auto_rig() == {"FINISHED"}

    (armature,) = armatures()
    skeleton = assert_skeleton_within_the_biped(armature)
    assert {"neck", "head"} <= set(skeleton.names)
    weights = group_weights(hair, skeleton.names)
    np.testing.assert_array_equal(weights[:, skeleton.names.index("head")], 1.0)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)
    rest = evaluated_world_vertices(hair)
    pose_bone_turned(armature, "head", 45.0, "Y")
    turned = evaluated_world_vertices(hair)
    assert np.abs(turned - rest).max() > 0.02  # the hair moved with the head
    # ... as one piece: every card edge keeps its length (float32 positions).
    edges = np.array([[a, b] for a, b, c in hair_cards()[1] for a, b in ((a, b), (b, c), (c, a))])
    lengths = [np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1) for points in (rest, turned)]
    np.testing.assert_allclose(lengths[1], lengths[0], atol=1e-5)
