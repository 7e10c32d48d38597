"""Triangles wound outward whatever the file's winding
(``core.geometry.outward_faces``), and what it changes for the jobs that
read normals: a character with flipped normals gets the skeleton and the
skin weights of the same character wound right (issue 17)."""

import numpy as np
import pytest

from autorig_addon.core.geometry.outward_faces import (
    inward_faces_note,
    inward_triangles,
    outward_mesh,
    outward_triangles,
)
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.predict import predict_votes, skeleton_from_votes
from autorig_addon.core.skinning.methods import DEFAULT_SKIN_METHOD, skin_weights
from autorig_addon.core.skinning.options import SkinningOptions
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh, cylinder, grid

#: The generated character of the behaviour tests (3,680 triangles, one piece per body part).
CHARACTER_SEED, CHARACTER_KIND = 0, "biped"
#: Share of the triangles flipped at random in the "some faces flipped" cases.
FLIPPED_SHARE = 0.5


def turned(F: np.ndarray, which: np.ndarray) -> np.ndarray:
    """``F`` with the ``which`` rows wound the other way (corners 1 and 2 swapped, as the module does)."""
    F = F.copy()
    F[which] = F[which][:, [0, 2, 1]]
    return F


def randomly_flipped(mesh: Mesh, seed: int = 0) -> tuple[Mesh, np.ndarray]:
    """``mesh`` with about :data:`FLIPPED_SHARE` of its triangles flipped, and which."""
    which = np.random.default_rng(seed).random(len(mesh.triangles)) < FLIPPED_SHARE
    return Mesh(mesh.vertices, turned(mesh.triangles, which)), which


def same_triangles(F: np.ndarray, G: np.ndarray) -> bool:
    """The same triangles, row by row, each read from its smallest corner (a cyclic turn is the same winding)."""
    def from_smallest(T):
        first = np.argmin(T, axis=1)
        return np.stack([T[np.arange(len(T)), (first + k) % 3] for k in range(3)], axis=1)
    return np.array_equal(from_smallest(F), from_smallest(G))


#: Closed outward meshes: a capped cylinder, a box whose six sides are
#: separate grids (joined only by position), a generated character.
CLOSED_SHAPES = {
    "cylinder": lambda: cylinder(radius=0.2, height=1.0),
    "box of six grids": lambda: box_mesh((0, 0, 0), (1.0, 0.5, 2.0), 0.1),
    "character": lambda: generate_character(CHARACTER_SEED, CHARACTER_KIND).mesh,
}
#: ... and open ones: a tube, a flat sheet.
OPEN_SHAPES = {"tube": lambda: cylinder(capped=False), "sheet": lambda: grid(8, 8)}


# --------------------------------------------------------------------------- the winding itself


@pytest.mark.parametrize("shape", [*CLOSED_SHAPES, *OPEN_SHAPES])
def test_a_mesh_wound_outward_comes_back_unchanged(shape):
    mesh = {**CLOSED_SHAPES, **OPEN_SHAPES}[shape]()
    oriented, which = outward_mesh(mesh)
    assert oriented is mesh and not which.any()
    F, which = outward_triangles(mesh.vertices, mesh.triangles)
    np.testing.assert_array_equal(F, mesh.triangles)


@pytest.mark.parametrize("shape", CLOSED_SHAPES)
def test_a_closed_mesh_wound_inside_out_comes_back_as_it_was(shape):
    mesh = CLOSED_SHAPES[shape]()
    inside_out = Mesh(mesh.vertices, turned(mesh.triangles, np.ones(len(mesh.triangles), dtype=bool)))
    oriented, which = outward_mesh(inside_out)
    assert which.all()
    np.testing.assert_array_equal(oriented.triangles, mesh.triangles)
    # Reversed the other way round (c, b, a): the same triangles, each from another corner.
    reversed_rows = Mesh(mesh.vertices, mesh.triangles[:, ::-1])
    assert same_triangles(outward_mesh(reversed_rows)[0].triangles, mesh.triangles)


@pytest.mark.parametrize("shape", CLOSED_SHAPES)
def test_half_the_faces_flipped_are_turned_back_and_only_they(shape):
    mesh = CLOSED_SHAPES[shape]()
    flipped, which = randomly_flipped(mesh)
    oriented, turned_back = outward_mesh(flipped)
    np.testing.assert_array_equal(turned_back, which)
    np.testing.assert_array_equal(oriented.triangles, mesh.triangles)


def test_of_two_separate_closed_pieces_only_the_inside_out_one_turns():
    body, other = cylinder(radius=0.2, height=1.0), cylinder(radius=0.1, height=0.5, z0=2.0)
    mesh = Mesh.concatenate([body, Mesh(other.vertices, turned(other.triangles, np.ones(len(other.triangles), bool)))])
    oriented, which = outward_mesh(mesh)
    np.testing.assert_array_equal(which, np.arange(len(mesh.triangles)) >= len(body.triangles))
    np.testing.assert_array_equal(oriented.triangles, Mesh.concatenate([body, other]).triangles)


def test_an_open_tube_like_a_sleeve_or_a_dress_is_turned_outward():
    sleeve = cylinder(radius=0.15, height=1.0, capped=False)
    inside_out = cylinder(radius=0.15, height=1.0, capped=False, flip=True)
    assert same_triangles(outward_mesh(inside_out)[0].triangles, sleeve.triangles)
    flipped, which = randomly_flipped(sleeve)
    np.testing.assert_array_equal(outward_mesh(flipped)[1], which)


def test_a_flat_sheet_keeps_the_winding_most_of_it_had_unless_the_whole_file_is_inside_out():
    sheet = grid(10, 10)
    flipped, which = randomly_flipped(sheet, seed=3)
    majority = which.sum() > len(which) / 2
    # A sheet has no inside: its minority turns to agree with the rest.
    np.testing.assert_array_equal(outward_mesh(flipped)[1], which != majority)
    # Beside a body whose winding says the file was written inside out, it turns with it.
    body = cylinder(radius=0.2, height=1.0, z0=-1.5)
    mesh = Mesh.concatenate([body, sheet])
    inside_out = Mesh(mesh.vertices, turned(mesh.triangles, np.ones(len(mesh.triangles), dtype=bool)))
    oriented, which = outward_mesh(inside_out)
    assert which.all()
    np.testing.assert_array_equal(oriented.triangles, mesh.triangles)


def test_double_sided_triangles_and_triangles_with_a_repeated_corner_turn_only_with_the_whole_file():
    body = cylinder(radius=0.2, height=1.0)
    sheet = grid(4, 4)
    cloak = Mesh(sheet.vertices + [0.5, 0.0, 0.5], np.vstack([sheet.triangles, sheet.triangles[:, [0, 2, 1]]]))
    mesh = Mesh.concatenate([body, cloak])
    F = np.vstack([mesh.triangles, [[0, 0, 1]]])
    assert not inward_triangles(mesh.vertices, F).any()
    # Flipped with the body, the two sides of the cloak swap: the same triangles.
    assert inward_triangles(mesh.vertices, turned(F, np.ones(len(F), dtype=bool))).all()


def test_an_empty_mesh_and_a_lone_triangle_are_left_alone():
    assert inward_triangles(np.zeros((0, 3)), np.zeros((0, 3), dtype=int)).shape == (0,)
    triangle = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    for F in ([[0, 1, 2]], [[0, 2, 1]]):
        assert not inward_triangles(triangle, np.array(F)).any()


def test_the_note_counts_the_triangles():
    assert inward_faces_note(1, "the skinning") == (
        "1 triangle of the mesh faced inwards (flipped normals); the skinning read them turned outward "
        "(the file is unchanged)")
    assert inward_faces_note(3680, "the skeleton prediction").startswith("3680 triangles of the mesh faced inwards")


# --------------------------------------------------------------------------- what the jobs read


@pytest.fixture(scope="module")
def character():
    return generate_character(CHARACTER_SEED, CHARACTER_KIND)


def flipped_characters(mesh: Mesh) -> dict:
    """The character as users send it: every face flipped (a negative scale
    applied, a bad export) and half of them flipped."""
    return {"all faces flipped": Mesh(mesh.vertices, mesh.triangles[:, ::-1]),
            "half the faces flipped": randomly_flipped(mesh)[0]}


def test_flipped_normals_give_the_same_skeleton(character):
    votes = predict_votes(character.mesh)
    skeleton = skeleton_from_votes(votes)
    assert not any("faced inwards" in note for note in votes.notes)
    for case, mesh in flipped_characters(character.mesh).items():
        flipped_votes = predict_votes(mesh)
        flipped = skeleton_from_votes(flipped_votes)
        assert flipped.names == skeleton.names, case
        np.testing.assert_array_equal(flipped.parents, skeleton.parents)
        np.testing.assert_allclose(flipped.joints, skeleton.joints, atol=1e-6, rtol=0, err_msg=case)
        count = int((mesh.triangles != character.mesh.triangles).any(axis=1).sum())
        assert flipped_votes.notes[0] == inward_faces_note(count, "the skeleton prediction"), case


def test_flipped_normals_give_the_same_skin_weights_by_the_default_method(character):
    options = SkinningOptions(DEFAULT_SKIN_METHOD)
    weights = skin_weights(character.mesh, character.skeleton, options)
    for case, mesh in flipped_characters(character.mesh).items():
        flipped = skin_weights(mesh, character.skeleton, options)
        assert flipped.bone_names == weights.bone_names
        np.testing.assert_allclose(flipped.matrix, weights.matrix, atol=1e-6, rtol=0, err_msg=case)
