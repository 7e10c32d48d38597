"""core.rigging.character_parts: the character told from a ground plane,
stray specks and other characters, on procedural characters and boxes."""

import numpy as np
import pytest

from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.character_parts import (
    GROUND,
    SPECK,
    LeftOutPart,
    character_parts,
    left_out_notes,
    several_characters_message,
)
from autorig_addon.core.types import Mesh
from geometry_fixtures import body_with_hat, box_mesh, cylinder, grid

#: The procedural biped of seed 0 stands 0.94 tall, feet at z 0.07, 0.6 wide with its arms out.
BIPED_SEED = 0


def named(mesh: Mesh, name: str, offset=(0.0, 0.0, 0.0)) -> Mesh:
    """``mesh`` as one object called ``name``, moved by ``offset``."""
    return Mesh(mesh.vertices + np.asarray(offset, float), mesh.triangles, object_names=(name,))


def joined(name: str, *meshes: Mesh) -> Mesh:
    """``meshes`` joined into one object called ``name`` (Ctrl+J)."""
    both = Mesh.concatenate(meshes)
    return Mesh(both.vertices, both.triangles, object_names=(name,))


def biped(name: str = "Body", offset=(0.0, 0.0, 0.0)) -> Mesh:
    return named(generate_character(BIPED_SEED, "biped").mesh, name, offset)


def feet_level(mesh: Mesh) -> float:
    return float(mesh.vertices[:, 2].min())


def flat_square(name: str, side: float, centre_xy=(0.0, 0.0), z: float = 0.0, cells: int = 4) -> Mesh:
    """A level square sheet of ``side`` at height ``z``, facing up."""
    sheet = grid(cells + 1, cells + 1, side)
    return named(sheet, name, (centre_xy[0] - side / 2, centre_xy[1] - side / 2, z))


def stray_triangle(x: float) -> Mesh:
    return Mesh([[x, 0.0, 0.5], [x + 0.05, 0.0, 0.5], [x, 0.05, 0.55]], [[0, 1, 2]], object_names=("Speck",))


@pytest.mark.parametrize(("seed", "kind"), [(0, "biped"), (1, "biped"), (2, "biped"), (3, "quadruped"),
                                            (7, "quadruped")])
def test_a_character_alone_is_all_character(seed, kind):
    """Procedural characters are made of overlapping pieces (13 to 26, eyes of
    0.16 % of the area among them): none is left out, one character."""
    mesh = generate_character(seed, kind).mesh

    parts = character_parts(mesh)

    assert not parts.left_out.any() and parts.parts == () and not parts.several


def test_a_stray_triangle_far_away_is_a_speck_left_out():
    body = biped()
    mesh = joined("Body", body, stray_triangle(100.0))

    parts = character_parts(mesh)

    assert np.flatnonzero(parts.left_out).tolist() == [body.vertex_count, body.vertex_count + 1,
                                                       body.vertex_count + 2]
    (part,) = parts.parts
    assert (part.object_index, part.kind, part.pieces, part.vertices, part.whole_object) == (0, SPECK, 1, 3, False)
    assert part.distance == pytest.approx(100.0 - body.vertices[:, 0].max())
    assert left_out_notes(mesh, parts, bound=False) == [
        "'Body': 1 loose piece of 3 vertices 99.7 m from the character was left out of the skeleton (a stray speck?)"]
    assert left_out_notes(mesh, parts, bound=True) == [
        "'Body': 1 loose piece of 3 vertices 99.7 m from the character was left out of the skeleton and left "
        "unweighted (a stray speck?)"]
    assert not parts.several


def test_a_speck_of_its_own_object_is_left_out_whole_and_two_specks_together_too():
    body = biped()
    mesh = Mesh.concatenate([body, stray_triangle(100.0), named(stray_triangle(100.1), "Speck.001")])

    parts = character_parts(mesh)

    assert parts.left_out[body.vertex_count:].all() and not parts.left_out[:body.vertex_count].any()
    assert parts.whole_objects() == [1, 2]
    assert left_out_notes(mesh, parts, bound=True)[0] == (
        "'Speck' lies 99.7 m from the character: left out of the skeleton and not bound (a stray speck?)")


def test_small_parts_near_the_body_stay():
    """A loose hat 0.1 above a body, a button 2 cm before it, a tiny piece a
    fifth of the body's height away: none is a speck."""
    body_and_hat, hat_rows, _, _ = body_with_hat()
    button = box_mesh([-0.01, -0.23, 0.5], [0.01, -0.22, 0.52], 0.01)
    near = box_mesh([0.4, -0.01, 0.5], [0.41, 0.0, 0.51], 0.01)
    mesh = Mesh.concatenate([body_and_hat, button, near])

    parts = character_parts(mesh)

    assert not parts.left_out.any() and not parts.several
    # The same tiny piece 2 body heights away is one.
    far = Mesh.concatenate([body_and_hat, button, named(near, "mesh", (2.0, 0.0, 0.0))])
    assert np.flatnonzero(character_parts(far).left_out).tolist() == list(
        range(body_and_hat.vertex_count + button.vertex_count, far.vertex_count))


@pytest.mark.parametrize("as_object", [True, False])
def test_a_ground_plane_under_the_feet_is_left_out(as_object):
    body = biped()
    ground = flat_square("Ground", 4.0, z=feet_level(body))
    mesh = Mesh.concatenate([body, ground]) if as_object else joined("Body", body, ground)

    parts = character_parts(mesh)

    assert np.flatnonzero(parts.left_out).tolist() == list(range(body.vertex_count, mesh.vertex_count))
    assert parts.parts == (LeftOutPart(int(as_object), GROUND, 1, ground.vertex_count, as_object),)
    expected = ("'Ground' is flat, under the character and wider than it: left out of the skeleton and not bound "
                "(a ground plane?)" if as_object else
                "'Body': a flat piece of 25 vertices under the character and wider than it was left out of the "
                "skeleton and left unweighted (a ground plane?)")
    assert left_out_notes(mesh, parts, bound=True) == [expected]
    assert not parts.several


def test_a_ground_with_feet_sunk_into_it_or_a_slab_is_a_ground_too():
    body = biped()
    sunk = flat_square("Ground", 3.0, z=feet_level(body) + 0.03)
    slab = named(box_mesh([-2.0, -2.0, feet_level(body) - 0.05], [2.0, 2.0, feet_level(body)], 0.5), "Slab")
    for ground in (sunk, slab):
        mesh = Mesh.concatenate([body, ground])
        assert character_parts(mesh).whole_objects() == [1]


@pytest.mark.parametrize("name", ["thick plinth", "flat plinth under the feet", "board as wide as the feet",
                                  "cape", "flat skirt", "ground far above"])
def test_what_is_not_a_ground_stays(name):
    """A plinth 6 cm thick, a flat one narrower than the character, a board
    no wider than the feet, a flat cape hanging behind, a flat skirt at the
    waist wider than the body, a level sheet above the head: all stay."""
    body = biped()
    low, high = body.vertices.min(0), body.vertices.max(0)
    z = feet_level(body)
    other = {
        "thick plinth": box_mesh([-0.5, -0.5, z - 0.06], [0.5, 0.5, z], 0.1),
        "flat plinth under the feet": grid(3, 3, 0.4).vertices + [-0.2, -0.2, z],
        "board as wide as the feet": grid(3, 3, 1.0).vertices * [1.0, (high[1] - low[1]), 1] + [-0.5, low[1], z],
        "cape": grid(5, 5, 0.6).vertices[:, [0, 2, 1]] + [-0.3, high[1] + 0.01, z + 0.2],
        "flat skirt": grid(5, 5, 0.9).vertices + [-0.45, -0.45, 0.45],
        "ground far above": grid(5, 5, 4.0).vertices + [-2.0, -2.0, high[2] + 0.5],
    }[name]
    if isinstance(other, np.ndarray):
        cells = int(round(np.sqrt(len(other))))
        other = Mesh(other, grid(cells, cells).triangles)
    mesh = Mesh.concatenate([body, named(other, "Other")])

    parts = character_parts(mesh)

    assert not any(part.kind == GROUND for part in parts.parts)


def test_two_characters_apart_are_several_named_by_object():
    mesh = Mesh.concatenate([biped("Knight"), biped("Knight.001", (3.0, 0.0, 0.0))])

    parts = character_parts(mesh)

    assert parts.several and len(parts.characters) == 2
    np.testing.assert_array_equal(parts.characters[0] | parts.characters[1], np.ones(mesh.vertex_count, bool))
    assert parts.apart == pytest.approx(3.0 - (mesh.vertices[:1866, 0].max() - mesh.vertices[:1866, 0].min()))
    assert several_characters_message(mesh, parts, "select one") == (
        "The meshes hold 2 characters: 'Knight' and 'Knight.001' standing 2.4 m apart. One armature would span "
        "both: rig them one at a time: select one. Nothing was built.")


def test_two_characters_joined_into_one_mesh_are_two_parts_of_it():
    mesh = joined("Mesh", biped(), biped(offset=(1.2, 0.0, 0.0)))

    parts = character_parts(mesh)

    assert parts.several
    assert several_characters_message(mesh, parts, "separate them").startswith(
        "'Mesh' holds 2 characters: 2 parts of 'Mesh' standing 0.596 m apart.")


def test_a_biped_and_a_quadruped_on_one_ground_are_several_and_the_ground_is_left_out():
    body, animal = biped("Rider"), named(generate_character(3, "quadruped").mesh, "Horse", (2.0, 0.0, 0.0))
    ground = flat_square("Ground", 6.0, centre_xy=(1.0, 0.0), z=min(feet_level(body), feet_level(animal)))
    mesh = Mesh.concatenate([body, animal, ground])

    parts = character_parts(mesh)

    assert parts.several and parts.whole_objects() == [2]
    assert several_characters_message(mesh, parts, "select one").startswith(
        "The meshes hold 2 characters: 'Horse' and 'Rider' standing")


def test_a_sword_dropped_beside_the_character_is_not_a_second_character():
    """A blade 0.45 long lying 0.3 beside the biped: 4 % of the area, 1 cm
    tall. It stays part of what is rigged, as before."""
    body = biped()
    right = body.vertices[:, 0].max()
    sword = named(box_mesh([right + 0.3, -0.22, feet_level(body)], [right + 0.33, 0.23, feet_level(body) + 0.01],
                           0.01), "Sword")
    mesh = Mesh.concatenate([body, sword])

    parts = character_parts(mesh)

    assert not parts.several and not parts.left_out.any()


def test_a_post_as_tall_as_the_character_beside_it_is_a_second_character():
    """Height counts as well as area: a post half the character's height,
    0.5 beside it, is refused rather than rigged with it."""
    body = biped()
    post = named(cylinder(radius=0.03, height=0.5, z0=feet_level(body)), "Post", (1.0, 0.0, 0.0))

    parts = character_parts(Mesh.concatenate([body, post]))

    assert parts.several


def test_thousands_of_hair_cards_are_one_character_with_the_head():
    """5,000 loose cards, each a triangle within a few millimetres of the
    scalp: pieces that almost touch are joined on a grid before the groups
    are compared pair by pair."""
    body = biped()
    rng = np.random.default_rng(0)
    scalp = body.vertices[body.vertices[:, 2] > 0.95]
    roots = scalp[rng.integers(len(scalp), size=5000)] + rng.normal(0.0, 0.003, (5000, 3))
    cards = np.stack([roots, roots + [0.01, 0.0, 0.0], roots + [0.0, 0.0, -0.03]], axis=1).reshape(-1, 3)
    hair = Mesh(cards, np.arange(len(cards)).reshape(-1, 3), object_names=("Hair",))
    mesh = Mesh.concatenate([body, hair])

    parts = character_parts(mesh)

    assert not parts.left_out.any() and not parts.several


def test_loose_vertices_belong_to_no_piece_and_stay():
    body = biped()
    mesh = Mesh(np.vstack([body.vertices, [[50.0, 0.0, 0.0]]]), body.triangles, object_names=("Body",))

    parts = character_parts(mesh)

    assert not parts.left_out.any() and parts.parts == ()


def test_mesh_subset_keeps_the_objects_of_the_kept_vertices():
    mesh = Mesh.concatenate([biped("A"), stray_triangle(10.0), biped("B", (0.0, 3.0, 0.0))])
    keep = np.ones(mesh.vertex_count, dtype=bool)
    keep[1866:1869] = False
    keep[1869] = False

    subset = mesh.subset(keep)

    assert subset.object_names == ("A", "B") and subset.object_offsets.tolist() == [0, 1866, 1866 + 1865]
    np.testing.assert_array_equal(subset.vertices, mesh.vertices[keep])
    assert len(subset.triangles) == 3680 + 3680 - np.count_nonzero((mesh.triangles == 1869).any(axis=1))
    np.testing.assert_array_equal(subset.vertices[subset.triangles[0]], mesh.vertices[mesh.triangles[0]])
