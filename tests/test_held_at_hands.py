"""Props held at the hands (autorig_addon.core.rigging.held_at_hands):
how thin a shape is, which objects may be held, thin or thick, and which are."""

import numpy as np
import pytest

from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.held_at_hands import (
    AT_HAND_SHARE,
    HAND_PAST,
    HAND_RADIUS,
    HAND_REACH,
    HELD_PAST,
    THIN_RATIO,
    Candidate,
    hand_candidates,
    held_at_hands,
    own_hands,
    props_held_at_hands,
    props_held_at_hands_reading,
    thick_candidates,
    thin_candidates,
    thinness,
)
from autorig_addon.core.rigging.nearest_character import surface_points
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh, procedural_biped_posed, procedural_biped_with


def mirror_image(mesh: Mesh) -> Mesh:
    """``mesh`` mirrored across x = 0, its faces turned so they still face out."""
    return Mesh(mesh.vertices * [-1.0, 1.0, 1.0], mesh.triangles[:, ::-1])


def box_points(low, high) -> np.ndarray:
    box = box_mesh(low, high, 0.02)
    return surface_points(box.vertices, box.triangles, 2048)


def test_thinness_is_the_smallest_principal_extent_over_the_largest():
    assert thinness(box_points((0, 0, 0), (1.0, 0.1, 0.05))) == pytest.approx(0.05, abs=0.005)
    # A cube has no principal axes of its own: along any, its extents lie between its side and sqrt(3) times it.
    assert thinness(box_points((0, 0, 0), (0.3, 0.3, 0.3))) > 1 / np.sqrt(3) - 0.01
    # Turned 45 degrees about z, a blade is as thin: the axes are its own.
    turn = np.array([[np.sqrt(0.5), -np.sqrt(0.5), 0], [np.sqrt(0.5), np.sqrt(0.5), 0], [0, 0, 1.0]])
    assert thinness(box_points((0, 0, 0), (1.0, 0.1, 0.05)) @ turn.T) == pytest.approx(0.05, abs=0.005)
    assert thinness(np.zeros((4, 3))) == 1.0


def body_with(*others: Mesh) -> Mesh:
    """A 1 x 0.4 x 2 block (the body) and ``others``, objects of their own."""
    body = box_mesh((-0.5, -0.2, 0.0), (0.5, 0.2, 2.0), 0.1)
    parts = [Mesh(body.vertices, body.triangles, object_names=("Body",))]
    parts += [Mesh(other.vertices, other.triangles, object_names=(f"Part{k}",)) for k, other in enumerate(others)]
    return Mesh.concatenate(parts)


def test_thin_objects_sticking_out_and_touching_are_candidates():
    stick = box_mesh((0.5, -0.02, 1.0), (1.3, 0.02, 1.04), 0.02)  # touches the side, 0.8 out
    block = box_mesh((0.5, -0.1, 1.5), (0.7, 0.1, 1.7), 0.02)  # touches, sticks out, not thin
    flat = box_mesh((-0.3, 0.2, 0.5), (0.3, 0.23, 1.5), 0.02)  # thin, lying on the body's front
    apart = box_mesh((2.0, -0.02, 1.0), (2.8, 0.02, 1.04), 0.02)  # thin, far from the body
    mesh = body_with(stick, block, flat, apart)
    (candidate,) = thin_candidates(mesh)
    assert candidate.object_index == 1 and candidate.gap < 1e-6
    # Where it touches: its end at the body's side (within 3 % of the body's largest side, 2.0).
    assert np.all(candidate.touching[:, 0] <= 0.5 + 0.06 + 1e-9)
    assert thinness(surface_points(stick.vertices, stick.triangles, 512)) < THIN_RATIO
    # Told as a prop already (or left out), it is no candidate.
    assert thin_candidates(mesh, told=[1]) == ()
    left_out = np.zeros(mesh.vertex_count, dtype=bool)
    left_out[mesh.object_slice(1)] = True
    assert thin_candidates(mesh, left_out) == ()


def test_a_candidate_touching_at_a_wrist_and_reaching_out_of_the_hand_is_held_gripped_there():
    wrists = {"wrist.L": np.array([0.5, 0.0, 1.0]), "wrist.R": np.array([-0.5, 0.0, 1.0])}
    size = 2.0
    reach = HAND_REACH * size
    rng = np.random.default_rng(0)
    at_right = wrists["wrist.R"] + rng.uniform(-0.5, 0.5, (30, 3)) * reach
    at_left = wrists["wrist.L"] + rng.uniform(-0.5, 0.5, (40, 3)) * reach
    at_head = np.array([0.0, 0.0, 1.9]) + rng.uniform(-0.05, 0.05, (30, 3))
    # A blade from the right hand 0.8 forward: most of it beyond the hand.
    blade = wrists["wrist.R"] + np.linspace(0.0, 0.8, 100)[:, None] * [0.0, -1.0, 0.0]
    sword = Candidate(3, np.vstack([at_right, blade]), at_right, 0.0)
    ear = Candidate(4, at_head, at_head, 0.0)
    # A staff held in both hands, more of it in the left: gripped at the left.
    shaft = np.linspace(wrists["wrist.R"], wrists["wrist.L"], 100) + [0.0, -0.05, 0.0]
    staff = Candidate(5, shaft, np.vstack([at_left, at_right[:20]]), 0.0)
    props = held_at_hands([sword, ear, staff], wrists, size)
    assert [prop.object_index for prop in props] == [3, 5]
    assert all(prop.held for prop in props)
    np.testing.assert_allclose(props[0].grip, at_right.mean(axis=0))
    np.testing.assert_allclose(props[1].grip, at_left.mean(axis=0))
    # Touching mostly elsewhere: a wing along the arm and the back, a fifth of it at the hand.
    wing = Candidate(6, np.vstack([blade, at_head]), np.vstack([at_right[:6], at_head[:24]]), 0.0)
    assert 6 / 30 < AT_HAND_SHARE and held_at_hands([wing], wrists, size) == ()
    # A glove, or both hands in one object: at the wrists, but nothing of it beyond a hand's reach.
    hands = Candidate(7, np.vstack([at_right, at_left]), np.vstack([at_right, at_left]), 0.0)
    assert held_at_hands([hands], wrists, size) == ()
    assert held_at_hands([sword], {}, size) == ()


def test_the_procedural_bipeds_mirrored_swords_are_held_and_its_ears_are_not():
    """The biped (seed 0, 0.94 tall, right hand near x -0.28, z 0.57) with a
    sword through each hand, mirror images, and two flat ears on its head:
    all four are thin candidates; the swords touch it at the wrists the
    landmark network reads, the ears at the head."""
    sword = box_mesh((-0.286, -0.5, 0.565), (-0.27, 0.03, 0.581), 0.02)
    ear = box_mesh((0.03, -0.01, 0.98), (0.07, 0.01, 1.15), 0.02)
    mesh = procedural_biped_with(("Sword", sword), ("Sword.L", mirror_image(sword)), ("Ear.L", ear),
                                 ("Ear.R", mirror_image(ear)))
    assert [candidate.object_index for candidate in thin_candidates(mesh)] == [1, 2, 3, 4]
    props = props_held_at_hands(mesh)
    assert [prop.object_index for prop in props] == [1, 2]
    # Gripped where the blades pass through the hands.
    np.testing.assert_allclose(props[0].grip, [-0.278, -0.01, 0.573], atol=0.03)
    np.testing.assert_allclose(props[1].grip, [0.278, -0.01, 0.573], atol=0.03)


def test_a_body_goes_on_past_a_wrist_only_where_it_has_a_hand_of_its_own():
    """own_hands: vertices within a hand's reach of the wrist and HAND_PAST beyond it along the forearm."""
    size = 2.0
    wrists = {"wrist.L": np.array([0.5, 0.0, 1.0]), "wrist.R": np.array([-0.5, 0.0, 1.0])}
    elbows = {"elbow.L": np.array([0.3, 0.0, 1.0]), "elbow.R": np.array([-0.3, 0.0, 1.0])}
    forearms = np.array([[x, 0.0, 1.0] for x in np.linspace(-0.5, 0.5, 41)])
    past = 1.2 * HAND_PAST * size
    left_hand = np.array([[0.5 + past, 0.0, 1.0]])
    hands = own_hands(wrists, elbows, np.vstack([forearms, left_hand]), size)
    assert list(hands) == ["wrist.L"]
    np.testing.assert_allclose(hands["wrist.L"], [1.0, 0.0, 0.0])
    # Short of HAND_PAST, off the forearm's line (a thigh beside a hanging hand), or with no elbow to tell the
    # forearm's direction: no hand.
    short = np.array([[0.5 + 0.8 * HAND_PAST * size, 0.0, 1.0]])
    assert own_hands(wrists, elbows, np.vstack([forearms, short]), size) == {}
    beside = np.array([[0.5 + past, 0.0, 1.0 - 1.2 * HAND_RADIUS * size]])
    assert np.linalg.norm(beside[0] - wrists["wrist.L"]) <= HAND_REACH * size
    assert own_hands(wrists, elbows, np.vstack([forearms, beside]), size) == {}
    assert own_hands(wrists, {}, np.vstack([forearms, left_hand]), size) == {}


def test_a_thick_candidate_is_held_only_in_a_hand_of_the_bodys_own_and_past_the_wrist():
    size = 2.0
    wrists = {"wrist.L": np.array([0.5, 0.0, 1.0]), "wrist.R": np.array([-0.5, 0.0, 1.0])}
    reach = HAND_REACH * size
    rng = np.random.default_rng(1)
    at_right = wrists["wrist.R"] + rng.uniform(-0.3, 0.3, (30, 3)) * reach
    # A mug in the right hand: its surface past the wrist (toward -x, the right forearm's way) ...
    mug_surface = wrists["wrist.R"] + [-0.08, -0.05, 0.0] + rng.uniform(-0.04, 0.04, (200, 3))
    mug = Candidate(1, mug_surface, at_right, 0.0, thin=False)
    # ... and a cuff around the forearm short of the wrist, touching at the same place.
    cuff = Candidate(2, wrists["wrist.R"] + [0.08, 0.0, 0.0] + rng.uniform(-0.04, 0.04, (200, 3)), at_right,
                     0.0, thin=False)
    # ... and a bracelet at the wrist, its middle past it by half of HELD_PAST only.
    bracelet = Candidate(3, wrists["wrist.R"] + [-0.5 * HELD_PAST * size, 0.0, 0.0]
                         + rng.uniform(-0.04, 0.04, (200, 3)) * [0.0, 1.0, 1.0], at_right, 0.0, thin=False)
    right_hand = {"wrist.R": np.array([-1.0, 0.0, 0.0])}
    assert 0.08 > HELD_PAST * size
    props = held_at_hands([mug, cuff, bracelet], wrists, size, right_hand)
    assert [prop.object_index for prop in props] == [1]
    np.testing.assert_allclose(props[0].grip, at_right.mean(axis=0))
    # Without a hand of the body's own there (the object may be the hand), or not told: not held.
    assert held_at_hands([mug], wrists, size, {"wrist.L": np.array([1.0, 0.0, 0.0])}) == ()
    assert held_at_hands([mug], wrists, size) == ()


def test_the_procedural_bipeds_mirrored_mugs_are_thick_candidates_held_in_its_hands():
    """A mug (a box 6 cm across) in front of each hand, mirror images: not thin, held all the same."""
    mug = box_mesh((-0.33, -0.06, 0.50), (-0.27, 0.0, 0.58), 0.01)
    mesh = procedural_biped_with(("Mug", mug), ("Mug.L", mirror_image(mug)))
    assert thin_candidates(mesh) == ()
    assert [(candidate.object_index, candidate.thin) for candidate in hand_candidates(mesh)] == [(1, False),
                                                                                               (2, False)]
    props = props_held_at_hands(mesh)
    assert [prop.object_index for prop in props] == [1, 2]
    np.testing.assert_allclose(props[0].grip, [-0.289, -0.011, 0.558], atol=0.02)
    np.testing.assert_allclose(props[1].grip, [0.289, -0.011, 0.558], atol=0.02)


@pytest.mark.parametrize("holding", [False, True], ids=["empty", "holding a ball"])
def test_hands_that_are_objects_of_their_own_are_not_held(holding):
    """The biped's hands with the ends of its forearms cut off into objects of their own (x beyond 0.19;
    the wrists lie near 0.26): thick candidates at the wrists, but without them the body ends short of
    the wrists, so they are the hands, not what the hands hold. A ball (4 cm) at the right hand's
    fingertips changes nothing: asked without every thick object at a wrist (the hand and the ball
    alike), the body has no hand of its own there, so neither is held."""
    character = generate_character(0, "biped").mesh
    vertices, triangles = character.vertices, character.triangles
    cut = (np.abs(vertices[triangles][:, :, 0]) > 0.19).all(axis=1)
    side = np.sign(vertices[triangles[:, 0], 0])

    def piece(mask, name):
        used = np.unique(triangles[mask])
        index = np.full(len(vertices), -1)
        index[used] = np.arange(len(used))
        return Mesh(vertices[used], index[triangles[mask]], object_names=(name,))

    objects = [piece(~cut, "Body"), piece(cut & (side < 0), "Hand.R"), piece(cut & (side > 0), "Hand.L")]
    if holding:
        ball = box_mesh((-0.34, -0.02, 0.55), (-0.30, 0.02, 0.59), 0.005)
        objects.append(Mesh(ball.vertices, ball.triangles, object_names=("Ball",)))
    mesh = Mesh.concatenate(objects)
    assert [candidate.object_index for candidate in thick_candidates(mesh)] == ([1, 2, 3] if holding else [1, 2])
    props, reading = props_held_at_hands_reading(mesh)
    assert props == ()
    # Not for want of wrists: the body is read as a biped, its wrists found.
    assert reading.votes.landmarks.kind == "biped"
    assert {"wrist.L", "wrist.R"} <= set(reading.votes.landmarks.points_for("biped"))


def test_a_sword_in_a_hand_raised_60_degrees_is_held_there():
    """The procedural biped with its right arm raised 60 degrees (a posed character, not left-right
    symmetric there) and a sword through that hand: held, gripped at the raised hand. The wrists are the
    standard skeleton's, read from the mesh: the network's own right wrist lay 0.09 short of the hand,
    past a hand's reach of where the blade touches it (measured)."""
    body, heads = procedural_biped_posed({"upper_arm.R": ((0.0, 1.0, 0.0), 60.0)})
    hand = heads["hand.R"] + 0.25 * (heads["hand.R"] - heads["forearm.R"])  # the palm: a quarter forearm past the wrist
    sword = box_mesh(hand + [-0.008, -0.5, -0.008], hand + [0.008, 0.03, 0.008], 0.02)
    mesh = Mesh.concatenate([body, Mesh(sword.vertices, sword.triangles, object_names=("Sword",))])
    (prop,) = props_held_at_hands(mesh)
    assert prop.object_index == 1 and prop.held
    np.testing.assert_allclose(prop.grip, hand, atol=0.03)
