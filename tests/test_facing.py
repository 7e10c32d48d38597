"""Which way a character faces (core/rigging/facing.py): a biped's toes, a
quadruped's head end, the landmark network's readings both ways, and the
reading from behind turned back."""

import numpy as np
import pytest

from autorig_addon.core.dataset.normalise import normalise
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.facing import (
    END_SHARE,
    FOOT_BAND,
    HEAD_END_SURE,
    SHIN_BAND,
    TOE_REACH_SURE,
    Facing,
    facing,
    from_behind,
    head_end_rise,
    toe_reach,
)
from autorig_addon.core.rigging.networks.landmarks import LANDMARKS
from autorig_addon.core.rigging.standard_skeleton import BIPED, Landmarks
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh


def boxes(*corners, spacing=0.02) -> Mesh:
    """One mesh of axis-aligned boxes, each given as (low, high)."""
    meshes = [box_mesh(low, high, spacing) for low, high in corners]
    offsets = np.cumsum([0] + [mesh.vertex_count for mesh in meshes[:-1]])
    return Mesh(np.concatenate([mesh.vertices for mesh in meshes]),
                np.concatenate([mesh.triangles + offset for mesh, offset in zip(meshes, offsets)]))


#: The feet and shins of two legs (x 0.05 to 0.15 each side): each foot from 0.12 ahead of its shin's middle to 0.04
#: behind it, the shins within the shin band, on a trunk up to a height of 1.
BIPED_BOXES = [box for sign in (1.0, -1.0) for box in (
    ([min(sign * 0.05, sign * 0.15), -0.03, 0.13], [max(sign * 0.05, sign * 0.15), 0.03, 0.24]),
    ([min(sign * 0.05, sign * 0.15), -0.12, 0.0], [max(sign * 0.05, sign * 0.15), 0.04, 0.04]))]
TRUNK = ([-0.15, -0.05, 0.5], [0.15, 0.05, 1.0])


def half_turn(mesh: Mesh) -> Mesh:
    return Mesh(mesh.vertices * [-1.0, -1.0, 1.0], mesh.triangles)


def test_the_toes_reach_is_how_much_farther_the_feet_reach_ahead_of_the_shins_than_behind():
    assert (FOOT_BAND, SHIN_BAND, TOE_REACH_SURE) == (0.05, (0.12, 0.25), 0.02)
    body = boxes(*BIPED_BOXES, TRUNK)
    # Each foot reaches 0.12 ahead of its shin's middle and 0.04 behind: 0.08 of the height toward -y.
    assert toe_reach(body) == pytest.approx(0.08, abs=1e-12)
    assert toe_reach(half_turn(body)) == pytest.approx(-0.08, abs=1e-12)
    # A generated biped facing -y, as the generator makes it, and turned half a turn.
    character = generate_character(0, BIPED)
    surface = normalise(character.mesh, character.skeleton).mesh
    assert toe_reach(surface) > TOE_REACH_SURE
    assert toe_reach(half_turn(surface)) < -TOE_REACH_SURE


def landmarks_of(kind_probabilities: dict) -> Landmarks:
    return Landmarks({name: np.zeros(3) for name in LANDMARKS}, kind_probabilities)


SURE_BIPED = {"biped": 0.95, "quadruped": 0.0, "other": 0.05}
UNSURE = {"biped": 0.3, "quadruped": 0.0, "other": 0.7}


def test_a_bipeds_toes_decide_which_way_it_faces():
    body = boxes(*BIPED_BOXES, TRUNK)  # toes toward -y
    assert facing(landmarks_of(SURE_BIPED), landmarks_of(UNSURE), body) == Facing(False)
    # Given facing +y and read surely both ways: turned.
    assert facing(landmarks_of(SURE_BIPED), landmarks_of(SURE_BIPED), half_turn(body)) == Facing(
        True, reason="its toes point toward +Y")
    # Kept by its toes, though turned it reads far more surely as a biped: that reading is taken, turned back.
    assert facing(landmarks_of(UNSURE), landmarks_of(SURE_BIPED), body) == Facing(False, True,
                                                                                 "its toes point that way")


def test_without_a_shape_cue_the_surer_reading_turned_decides():
    # A box has no toes and both its ends stand alike: the landmark network's readings decide.
    block = boxes(([-0.2, -0.2, 0.0], [0.2, 0.2, 1.0]))
    assert facing(landmarks_of(UNSURE), landmarks_of(SURE_BIPED), block) == Facing(
        True, reason="turned, it reads more surely as a biped")
    # Read as "other" both ways: kept as given, and nothing told its front.
    assert facing(landmarks_of(UNSURE), landmarks_of(UNSURE), block) == Facing(False, front_untold=True)


def test_where_the_network_put_the_ankles_does_not_turn_a_biped_whose_toes_do_not_tell():
    # Boots reaching as far behind the shins as ahead: the toes do not tell.
    boots = [box for sign in (1.0, -1.0) for box in (
        ([min(sign * 0.05, sign * 0.15), -0.03, 0.13], [max(sign * 0.05, sign * 0.15), 0.03, 0.24]),
        ([min(sign * 0.05, sign * 0.15), -0.08, 0.0], [max(sign * 0.05, sign * 0.15), 0.08, 0.04]))]
    body = boxes(*boots, TRUNK)
    assert abs(toe_reach(body)) < TOE_REACH_SURE
    # The network put the ankles at the boots' front, so the boots reach far behind them; read alike both ways.
    points = {name: np.zeros(3) for name in LANDMARKS}
    for name, x in (("ankle.L", 0.1), ("ankle.R", -0.1), ("hip.L", 0.1), ("hip.R", -0.1)):
        points[name] = np.array([x, -0.06, 0.05 if name.startswith("ankle") else 0.5])
    reading = Landmarks(points, SURE_BIPED)
    # Kept as given either way round (a cue on the network's ankles turned such bodies whichever way they faced),
    # and the report is to say that nothing told its front.
    assert facing(reading, reading, body) == Facing(False, untold_kind="biped")
    assert facing(reading, reading, half_turn(body)) == Facing(False, untold_kind="biped")


def test_a_quadrupeds_higher_end_is_its_front():
    assert (END_SHARE, HEAD_END_SURE) == (0.15, 0.05)
    # A body along y from -0.5 to 0.5: a trunk 0.3 to 0.6 high, a head up to 0.9 at the -y end, four legs.
    legs = [([x - 0.03, y - 0.03, 0.0], [x + 0.03, y + 0.03, 0.3]) for x in (-0.1, 0.1) for y in (-0.3, 0.3)]
    animal = boxes(([-0.12, -0.4, 0.3], [0.12, 0.5, 0.6]), ([-0.06, -0.5, 0.6], [0.06, -0.4, 0.9]), *legs)
    assert head_end_rise(animal) > HEAD_END_SURE
    assert head_end_rise(half_turn(animal)) == pytest.approx(-head_end_rise(animal), abs=1e-12)
    sure = {"biped": 0.0, "quadruped": 0.95, "other": 0.05}
    assert facing(landmarks_of(sure), landmarks_of(UNSURE), animal) == Facing(False)
    assert facing(landmarks_of(sure), landmarks_of(sure), half_turn(animal)) == Facing(
        True, reason="its head end is toward +Y")


def test_a_reading_from_behind_is_turned_back_with_its_sides_swapped():
    points = {name: np.zeros(3) for name in LANDMARKS}
    # Read from behind, the network put a "left" wrist at +x of the turned frame: the character's right hand.
    points["wrist.L"], points["wrist.R"] = np.array([0.3, 0.02, 0.6]), np.array([-0.3, 0.02, 0.6])
    points["head"] = np.array([0.0, 0.01, 0.9])
    turned = Landmarks(points, {"biped": 0.9, "quadruped": 0.0, "other": 0.1})
    back = from_behind(turned)
    # Turned back half a turn: its right hand at -x, in front (y -0.02) as the hand was seen from behind.
    np.testing.assert_allclose(back.points["wrist.R"], [-0.3, -0.02, 0.6])
    np.testing.assert_allclose(back.points["wrist.L"], [0.3, -0.02, 0.6])
    np.testing.assert_allclose(back.points["head"], [0.0, -0.01, 0.9])
    assert set(back.points) == set(LANDMARKS) and back.kind_probabilities == turned.kind_probabilities


def test_a_zero_area_face_alone_at_an_end_tells_nothing_and_breaks_nothing():
    # A zero-area triangle standing alone beyond the body's -y end: that end has no area to weigh, so the head-end
    # cue does not tell (rather than dividing by zero) and the readings decide.
    block = boxes(([-0.2, -0.2, 0.0], [0.2, 0.2, 1.0]))
    speck = len(block.vertices)
    with_speck = Mesh(np.concatenate([block.vertices, [[0.0, -0.5, 0.5]] * 3]),
                      np.concatenate([block.triangles, [[speck, speck + 1, speck + 2]]]))
    assert head_end_rise(with_speck) is None
    sure = {"biped": 0.0, "quadruped": 0.95, "other": 0.05}
    assert facing(landmarks_of(sure), landmarks_of(UNSURE), with_speck) == Facing(False)


def test_a_body_turned_by_its_shape_keeps_the_reading_it_gave_as_it_was_when_that_one_is_far_surer():
    # Given facing +y, toes and all: it is turned; the network read it far more surely as it was given, which is
    # the reading from behind once it is turned.
    given = half_turn(boxes(*BIPED_BOXES, TRUNK))
    assert facing(landmarks_of(SURE_BIPED), landmarks_of(UNSURE), given) == Facing(
        True, True, "its toes point toward +Y")
    assert facing(landmarks_of(SURE_BIPED), landmarks_of(SURE_BIPED), given) == Facing(
        True, False, "its toes point toward +Y")


def quadruped_reading(head_y: float, hips_y: float, probabilities: dict) -> Landmarks:
    points = {name: np.zeros(3) for name in LANDMARKS}
    points["head"], points["hips"] = np.array([0.0, head_y, 0.8]), np.array([0.0, hips_y, 0.5])
    return Landmarks(points, probabilities)


def test_a_reading_from_behind_that_puts_a_quadrupeds_head_on_its_tail_is_not_taken():
    """Kept facing -y by its higher head end and read far more surely turned:
    that reading is taken only when, turned back, its head lies toward -y of
    its hips. Before, a validation stegosaurus (its back plates standing
    highest) was read with its head on the tail tip: every key joint wrong."""
    legs = [([x - 0.03, y - 0.03, 0.0], [x + 0.03, y + 0.03, 0.3]) for x in (-0.1, 0.1) for y in (-0.3, 0.3)]
    animal = boxes(([-0.12, -0.4, 0.3], [0.12, 0.5, 0.6]), ([-0.06, -0.5, 0.6], [0.06, -0.4, 0.9]), *legs)
    unsure = {"biped": 0.0, "quadruped": 0.4, "other": 0.6}
    sure = {"biped": 0.0, "quadruped": 0.95, "other": 0.05}
    # Read on the turned body with its head at -y there: turned back, the head lands at +y, the tail end.
    tail_first = quadruped_reading(-0.45, 0.35, sure)
    assert from_behind(tail_first).points["head"][1] == pytest.approx(0.45)
    assert facing(quadruped_reading(-0.45, 0.35, unsure), tail_first, animal) == Facing(False)
    # Read with its head at +y of the turned body, where the head really is: taken, turned back.
    head_first = quadruped_reading(0.45, -0.35, sure)
    assert facing(quadruped_reading(-0.45, 0.35, unsure), head_first, animal) == Facing(
        False, True, "its head end is that way")
    # Given facing +y: turned by its head end; the reading as given is the one from behind, and the same holds.
    given = half_turn(animal)
    assert facing(tail_first, quadruped_reading(-0.45, 0.35, unsure), given) == Facing(
        True, False, "its head end is toward +Y")
    assert facing(head_first, quadruped_reading(-0.45, 0.35, unsure), given) == Facing(
        True, True, "its head end is toward +Y")
