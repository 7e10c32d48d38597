"""core.rigging.props: rigid props (a sword, a shield) told from the body,
on cylinders and boxes with known answers and the procedural biped."""

import numpy as np
import pytest

from autorig_addon.core.geometry.normals import vertex_normals
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.props import GRIP_TIE, carried_props, held_note, holding_bone, prop_notes, rigid_props
from autorig_addon.core.types import Mesh, Skeleton
from geometry_fixtures import box_mesh, cylinder

#: The body: a closed cylinder of radius 0.2 up z from 0 to 1 (largest side 1: "near" is within 0.03).
RADIUS = 0.2


def named(mesh: Mesh, name: str, offset=(0.0, 0.0, 0.0)) -> Mesh:
    """``mesh`` as one object called ``name``, moved by ``offset``."""
    return Mesh(mesh.vertices + np.asarray(offset, float), mesh.triangles, object_names=(name,))


def body() -> Mesh:
    return named(cylinder(radius=RADIUS, height=1.0, segments=32, rings=21), "Body")


def stick(name: str = "Stick", x_from: float = 0.15, y: float = 0.1) -> Mesh:
    """A thin box 4 cm square from ``x_from`` out to 0.7 along +x at height
    0.5, off both of the body's mirror planes (x = 0, y = 0) by ``y``: from
    0.15 it starts inside the body."""
    return named(box_mesh([x_from, y - 0.02, 0.5], [0.7, y + 0.02, 0.54], 0.02), name)


def shell(mesh: Mesh, rows: np.ndarray, name: str, offset: float) -> Mesh:
    """The triangles of ``mesh`` whose corners are all in ``rows`` (bool),
    pushed ``offset`` out along the normals: a garment made by duplicating
    part of the body and inflating it."""
    normals = vertex_normals(mesh.vertices, mesh.triangles)
    kept = mesh.triangles[rows[mesh.triangles].all(axis=1)]
    used, triangles = np.unique(kept, return_inverse=True)
    return Mesh(mesh.vertices[used] + offset * normals[used], triangles.reshape(-1, 3), object_names=(name,))


def test_a_thin_box_sticking_out_of_the_body_is_a_held_prop_gripped_where_it_enters():
    mesh = Mesh.concatenate([body(), stick()])

    (prop,) = rigid_props(mesh)

    assert prop.object_index == 1 and prop.held and prop.gap < 1e-3
    # The mean of its surface within 0.03 of the body's: from x 0.15 inside to about 0.22 outside.
    assert prop.grip == pytest.approx([0.185, 0.1, 0.52], abs=0.015)


def test_a_sleeve_around_the_body_and_a_patch_on_one_side_are_not_props():
    """A sleeve has a twin of itself across the mirror plane; a patch on one
    side has none, but lies on the body (0.01 off its surface)."""
    cylinder_body = body()
    z = cylinder_body.vertices[:, 2]
    sleeve = shell(cylinder_body, (z >= 0.3) & (z <= 0.7), "Sleeve", 0.01)
    patch = shell(cylinder_body, (z >= 0.3) & (z <= 0.7) & (cylinder_body.vertices[:, 0] > 0.1)
                  & (cylinder_body.vertices[:, 1] > 0.0), "Patch", 0.01)

    assert rigid_props(Mesh.concatenate([cylinder_body, sleeve])) == ()
    assert rigid_props(Mesh.concatenate([cylinder_body, patch])) == ()
    # With a stick too, the stick alone.
    assert [prop.object_index for prop in rigid_props(Mesh.concatenate([cylinder_body, sleeve, patch, stick()]))] \
        == [3]


def test_arms_of_their_own_have_twins_the_stick_in_one_hand_has_none():
    """KayKit's way: a torso, two arm objects mirrored across x = 0, a stick held at the right arm's end."""
    torso = body()
    right_arm = named(box_mesh([-0.7, -0.05, 0.75], [-0.15, 0.05, 0.85], 0.025), "ArmRight")
    left_arm = named(box_mesh([0.15, -0.05, 0.75], [0.7, 0.05, 0.85], 0.025), "ArmLeft")
    sword = named(box_mesh([-0.68, -0.6, 0.78], [-0.64, 0.03, 0.82], 0.02), "Sword")
    mesh = Mesh.concatenate([torso, right_arm, left_arm, sword])

    (prop,) = rigid_props(mesh)

    assert mesh.object_names[prop.object_index] == "Sword" and prop.held
    assert prop.grip[0] == pytest.approx(-0.66, abs=0.01) and prop.grip[2] == pytest.approx(0.8, abs=0.01)
    # Without the right arm the torso, round, is its own twin across y = 0 too, and so is the left arm there:
    # the sword alone is a prop, which nothing holds now.
    (prop,) = rigid_props(Mesh.concatenate([torso, left_arm, sword]))
    assert prop.object_index == 2 and not prop.held


def test_a_pair_of_mirrored_sticks_is_part_of_the_body():
    twin = Mesh(stick().vertices * [-1.0, 1.0, 1.0], stick().triangles[:, ::-1], object_names=("Stick.001",))
    mesh = Mesh.concatenate([body(), stick(), twin])

    assert rigid_props(mesh) == ()


def test_a_stick_set_down_beside_the_body_is_a_prop_nothing_holds():
    mesh = Mesh.concatenate([body(), stick(x_from=0.4)])

    (prop,) = rigid_props(mesh)

    assert not prop.held
    # Its nearest corner (0.4, 0.08, 0.5 .. 0.54) lies sqrt(0.4^2 + 0.08^2) - 0.2 from the body.
    assert prop.gap == pytest.approx(np.hypot(0.4, 0.08) - RADIUS, abs=2e-3)
    assert prop_notes(mesh, (prop,), bound=True) == [
        "'Stick' lies 0.208 m from the character and nothing holds it: left out of the skeleton and not bound "
        "(a prop set down?)"]
    assert prop_notes(mesh, (prop,), bound=False) == [
        "'Stick' lies 0.208 m from the character and nothing holds it: left out of the skeleton (a prop set down?)"]


def test_no_prop_is_told_on_a_lopsided_body_or_a_big_object():
    """A posed body (bent over, forwards and to one side) has no mirror
    plane: its own parts would lack twins too. A box as large as the body
    is no prop."""
    bent = body()
    vertices = bent.vertices.copy()
    vertices[:, :2] += 2.4 * np.clip(vertices[:, 2:] - 0.4, 0.0, None) ** 2 * [1.0, -1.0]
    lopsided = Mesh(vertices, bent.triangles, object_names=("Body",))
    big = named(box_mesh([0.15, 0.05, 0.0], [1.4, 0.6, 0.6], 0.05), "Crate")

    assert rigid_props(Mesh.concatenate([lopsided, stick(y=-0.1)])) == ()
    assert rigid_props(Mesh.concatenate([body(), big])) == ()
    assert rigid_props(body()) == ()


def test_a_stick_joined_into_the_bodys_mesh_is_a_prop_piece_of_it():
    """Joined into one object (Ctrl+J), the stick is a loose piece of the
    body's mesh: the prop is that piece, gripped where it enters the body;
    a mirrored pair joined in stays the body. Before, one object held no
    prop, and its stick was skinned over the arm's bones."""
    joined = Mesh.concatenate([body(), stick()])
    one_object = Mesh(joined.vertices, joined.triangles, object_names=("Body",))

    (prop,) = rigid_props(one_object)

    assert prop.object_index == 0 and prop.held and prop.gap < 1e-3
    np.testing.assert_array_equal(prop.piece, np.arange(body().vertex_count, joined.vertex_count))
    assert prop.grip == pytest.approx([0.185, 0.1, 0.52], abs=0.015)
    twin = Mesh(stick().vertices * [-1.0, 1.0, 1.0], stick().triangles[:, ::-1])
    pair = Mesh.concatenate([body(), stick(), twin])
    assert rigid_props(Mesh(pair.vertices, pair.triangles, object_names=("Body",))) == ()
    # A separate object is still told whole.
    (whole,) = rigid_props(joined)
    assert whole.object_index == 1 and whole.piece is None


def test_a_body_of_many_pieces_without_twins_tells_no_piece():
    """The procedural biped (25 loose pieces) twisted 45 degrees about its
    height, as a Simple Deform leaves it: the rest still mirrors within the
    tolerance once 7 or 8 of its pieces are set aside, 3 of them held (two
    at its shoulders, one at the top of its head). Told as props, they were
    left out of the skeleton, whose right forearm then lay outside the body;
    more than ``MAX_TWINLESS_PIECES`` (3) pieces without a twin say the
    plane does not pair them, so none is told."""
    character = generate_character(0, "biped").mesh
    vertices = character.vertices
    turn = np.radians(45.0) * (vertices[:, 2] - vertices[:, 2].min()) / np.ptp(vertices[:, 2])
    twisted = np.stack([np.cos(turn) * vertices[:, 0] - np.sin(turn) * vertices[:, 1],
                        np.sin(turn) * vertices[:, 0] + np.cos(turn) * vertices[:, 1], vertices[:, 2]], axis=1)
    body = Mesh(twisted, character.triangles, object_names=("Biped",))
    assert rigid_props(body) == ()
    # Nor is a separate stick told by the plane those pieces' absence let through: told again with whole
    # objects only, as before pieces were, the twisted body does not mirror. Beside the straight biped it is.
    beside = stick(x_from=0.25, y=0.0)
    assert rigid_props(Mesh.concatenate([body, beside])) == ()
    straight = Mesh(vertices, character.triangles, object_names=("Biped",))
    (prop,) = rigid_props(Mesh.concatenate([straight, beside]))
    assert prop.object_index == 1 and prop.piece is None and prop.held


def test_what_a_replaced_rig_carried_on_a_bone_and_sticks_out_is_a_held_prop_twin_or_not():
    """A stick in each hand, mirrored (each the other's twin, so not told by
    shape), carried by the old rig's hand bones: both held props, gripped at
    those bones. A shell lying on the body carried by a bone (a helmet)
    stays the body; a mesh of carried parts only has no body to tell them from."""
    twin = Mesh(stick().vertices * [-1.0, 1.0, 1.0], stick().triangles[:, ::-1], object_names=("Stick.001",))
    rows = body().vertices[:, 2] > 0.8
    helmet = shell(body(), rows, "Helmet", 0.01)
    mesh = Mesh.concatenate([body(), stick(), twin, helmet])
    assert rigid_props(mesh) == ()
    grips = {1: np.array([0.2, 0.1, 0.52]), 2: np.array([-0.2, 0.1, 0.52]), 3: np.array([0.0, 0.0, 0.9])}

    props = carried_props(mesh, grips)

    assert [prop.object_index for prop in props] == [1, 2] and all(prop.held for prop in props)
    np.testing.assert_array_equal(props[0].grip, grips[1])
    np.testing.assert_array_equal(props[1].grip, grips[2])
    assert props[0].gap < 1e-3  # it enters the body
    assert carried_props(Mesh.concatenate([stick(), twin]), {0: grips[1], 1: grips[2]}) == ()


def test_left_out_vertices_are_neither_body_nor_prop():
    """The stick left out whole (as a speck would be) is no prop; a stick
    with a piece left out is not bound whole either."""
    mesh = Mesh.concatenate([body(), stick()])
    stick_rows = np.arange(mesh.vertex_count) >= body().vertex_count

    assert rigid_props(mesh, stick_rows) == ()
    assert rigid_props(mesh, stick_rows & (np.cumsum(stick_rows) == 1)) == ()


def test_a_sword_at_the_procedural_bipeds_right_hand_is_held_there():
    character = generate_character(0, "biped")
    sword = named(box_mesh([-0.286, -0.5, 0.565], [-0.27, 0.03, 0.581], 0.02), "Sword")
    mesh = Mesh.concatenate([named(character.mesh, "Biped"), sword])

    (prop,) = rigid_props(mesh)

    assert prop.object_index == 1 and prop.held
    skeleton = character.skeleton
    assert holding_bone(prop.grip, skeleton) == "hand.R"
    assert prop_notes(mesh, (prop,), bound=False) == ["'Sword' is held: a rigid prop, left out of the skeleton"]
    assert prop_notes(mesh, (prop,), bound=True) == []


def test_the_holding_bone_is_the_nearest_deform_segment():
    """Two bones up z and a control bone (not deforming) right at the grip."""
    skeleton = Skeleton(np.array([[0, 0, 0.0], [0, 0, 0.5], [0.3, 0, 0.5]]), np.array([-1, 0, 0]),
                        ("lower", "upper", "control"), np.array([[0, 0, 0.5], [0, 0, 1.0], [0.4, 0, 0.5]]),
                        np.array([True, True, False]))

    assert holding_bone(np.array([0.35, 0.0, 0.6]), skeleton) == "upper"
    assert holding_bone(np.array([0.1, 0.0, 0.2]), skeleton) == "lower"
    assert held_note("hand.R") == "held: bound wholly to bone 'hand.R' (a rigid prop, left out of the skeleton)"


def test_a_grip_where_the_forearm_ends_and_the_hand_begins_is_in_the_hand():
    """A forearm along +x from 0 to 0.25 and a hand from 0.25 to 0.33 (the skeleton 0.33 long): a grip 6 mm off the
    wrist, a hair nearer the forearm's segment, is held by the hand; one a forearm's tenth back by the forearm."""
    skeleton = Skeleton(np.array([[0.0, 0, 0], [0.25, 0, 0]]), np.array([-1, 0]), ("forearm", "hand"),
                        np.array([[0.25, 0, 0], [0.33, 0, 0]]), np.array([True, True]))
    assert GRIP_TIE == 0.01
    near_wrist = np.array([0.2499, 0.006, 0.0])
    assert holding_bone(near_wrist, skeleton) == "hand"
    assert holding_bone(np.array([0.225, 0.006, 0.0]), skeleton) == "forearm"
    # On the forearm's line 0.003 behind the wrist, within the tie (0.01 of 0.33): still the hand; 0.005 behind, the
    # forearm.
    assert holding_bone(np.array([0.247, 0.0, 0.0]), skeleton) == "hand"
    assert holding_bone(np.array([0.245, 0.0, 0.0]), skeleton) == "forearm"
