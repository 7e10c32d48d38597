"""A body laid out as a biped (autorig_addon.core.rigging.body_layout), on
blocky bodies built from boxes with the joints where an artist puts them."""

import numpy as np
import pytest

from autorig_addon.core.rigging.body_layout import (
    MAX_FEET_LEVEL_GAP,
    MIN_INSIDE_SHARE,
    MIN_LEG_INSIDE_SHARE,
    MIN_TRUNK_RISE,
    SEGMENT_SAMPLES,
    biped_layout,
    quadruped_layout,
)
from autorig_addon.core.rigging.joint_features import solid_depth
from autorig_addon.core.skeleton.naming import mirror_name
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh

SPACING = 0.05


def _boxes(*corners) -> Mesh:
    return Mesh.concatenate([box_mesh(low, high, SPACING) for low, high in corners])


#: A chibi of boxes facing -y, 1 tall: legs 0.25 (apart by 0.1), trunk 0.3, a head 0.45 as wide as it is tall,
#: arms held out to the sides (a T-pose).
LEGS = (([-0.2, -0.08, 0.0], [-0.05, 0.08, 0.25]), ([0.05, -0.08, 0.0], [0.2, 0.08, 0.25]))
TRUNK = ([-0.2, -0.1, 0.25], [0.2, 0.1, 0.55])
HEAD = ([-0.25, -0.2, 0.55], [0.25, 0.2, 1.0])
ARMS = (([-0.5, -0.06, 0.42], [-0.2, 0.06, 0.52]), ([0.2, -0.06, 0.42], [0.5, 0.06, 0.52]))
#: Its joints, where an artist puts them.
CHIBI_JOINTS = {
    "hips": [0.0, 0.0, 0.28], "neck": [0.0, 0.0, 0.54], "head": [0.0, 0.0, 0.6],
    "shoulder.L": [0.22, 0.0, 0.47], "elbow.L": [0.33, 0.0, 0.47], "wrist.L": [0.44, 0.0, 0.47],
    "hip.L": [0.12, 0.0, 0.26], "knee.L": [0.12, 0.0, 0.13], "ankle.L": [0.12, 0.0, 0.03],
}


def _both_sides(points: dict) -> dict:
    points = {name: np.array(point, dtype=np.float64) for name, point in points.items()}
    for name in [name for name in points if name.endswith(".L")]:
        points[name[:-2] + ".R"] = points[name] * np.array([-1.0, 1.0, 1.0])
    return points


@pytest.fixture(scope="module")
def chibi():
    return solid_depth(_boxes(*LEGS, TRUNK, HEAD, *ARMS))


def test_a_blocky_chibi_with_its_joints_in_place_is_laid_out_as_a_biped(chibi):
    layout = biped_layout(_both_sides(CHIBI_JOINTS), chibi)
    assert layout is not None and layout.kind == "biped"
    assert layout.inside_share == 1.0
    assert layout.note == ("its biped landmarks make an upright body (every limb, the trunk and the neck inside it, "
                           "the legs apart, the head on top), so it is taken for a biped")


def test_legs_in_one_column_are_no_pair_of_legs():
    # The same body standing on one block as wide as both legs: between the knees is inside.
    column = ([-0.2, -0.08, 0.0], [0.2, 0.08, 0.25])
    solid = solid_depth(_boxes(column, TRUNK, HEAD, *ARMS))
    assert biped_layout(_both_sides(CHIBI_JOINTS), solid) is None


def test_a_limb_mostly_outside_the_body_breaks_the_layout(chibi):
    # The wrists read far past the hands: the forearms leave the body after a third of their length.
    points = _both_sides({**CHIBI_JOINTS, "wrist.L": [0.7, 0.0, 0.47]})
    assert biped_layout(points, chibi) is None
    # Read just past the hands, the forearm is still mostly inside (its end allowed out).
    points = _both_sides({**CHIBI_JOINTS, "wrist.L": [0.52, 0.0, 0.47]})
    layout = biped_layout(points, chibi)
    assert MIN_INSIDE_SHARE <= layout.inside_share < 1.0
    assert layout.inside_share == pytest.approx(round(layout.inside_share * SEGMENT_SAMPLES) / SEGMENT_SAMPLES)
    assert f"every limb, the trunk and the neck at least {layout.inside_share:.0%} inside it" in layout.note
    # The arm's box ends at x = 0.5: a wrist at 0.59 leaves 7 of the forearm's 11 points inside (0.64, enough), one at
    # 0.64 leaves 6 (0.55, too few).
    assert biped_layout(_both_sides({**CHIBI_JOINTS, "wrist.L": [0.59, 0.0, 0.47]}), chibi).inside_share == \
        pytest.approx(7 / 11)
    assert 6 / 11 < MIN_INSIDE_SHARE < 7 / 11
    assert biped_layout(_both_sides({**CHIBI_JOINTS, "wrist.L": [0.64, 0.0, 0.47]}), chibi) is None


def test_joints_out_of_their_top_to_bottom_order_are_no_biped(chibi):
    # The head read below the neck, or a knee below an ankle.
    assert biped_layout(_both_sides({**CHIBI_JOINTS, "head": [0.0, 0.0, 0.5]}), chibi) is None
    assert biped_layout(_both_sides({**CHIBI_JOINTS, "knee.L": [0.12, 0.0, 0.02]}), chibi) is None


def test_a_trunk_leaning_more_than_it_rises_over_two_is_no_upright_biped():
    # A chibi with a trunk as deep as its head, its neck read forward of its hips: rising 0.26, the trunk may run
    # 0.13 along y at most.
    deep_trunk = ([-0.2, -0.2, 0.25], [0.2, 0.2, 0.55])
    solid = solid_depth(_boxes(*LEGS, deep_trunk, HEAD, *ARMS))
    assert MIN_TRUNK_RISE == 2.0
    assert biped_layout(_both_sides({**CHIBI_JOINTS, "neck": [0.0, -0.1, 0.54]}), solid) is not None
    assert biped_layout(_both_sides({**CHIBI_JOINTS, "neck": [0.0, -0.16, 0.54]}), solid) is None


#: A four-legged box animal facing -y, 0.7 tall: legs 0.3 long (each pair 0.1 apart), a body 0.9 long, a head
#: standing up at its front.
ANIMAL_LEGS = tuple(([x0, y0, 0.0], [x0 + 0.1, y0 + 0.1, 0.3]) for x0 in (-0.15, 0.05) for y0 in (-0.4, 0.3))
ANIMAL_BODY = ([-0.15, -0.45, 0.3], [0.15, 0.45, 0.55])
ANIMAL_HEAD = ([-0.1, -0.6, 0.45], [0.1, -0.4, 0.7])
#: Its landmarks as the network gives a quadruped's: the hips at its rump, the neck and head at its front, the
#: "arms" its front legs, the "legs" its hind legs.
ANIMAL_JOINTS = {
    "hips": [0.0, 0.35, 0.42], "neck": [0.0, -0.4, 0.5], "head": [0.0, -0.5, 0.6],
    "shoulder.L": [0.1, -0.35, 0.4], "elbow.L": [0.1, -0.35, 0.32], "wrist.L": [0.1, -0.35, 0.2],
    "hip.L": [0.1, 0.35, 0.4], "knee.L": [0.1, 0.35, 0.2], "ankle.L": [0.1, 0.35, 0.05],
}


@pytest.fixture(scope="module")
def animal():
    return solid_depth(_boxes(*ANIMAL_LEGS, ANIMAL_BODY, ANIMAL_HEAD))


def test_a_quadrupeds_trunk_lies_along_its_length(animal):
    # Legs apart, all inside, in order from the top: only the trunk's run along y tells it is no biped.
    points = _both_sides(ANIMAL_JOINTS)
    assert biped_layout(points, animal) is None
    # Stood up on its hind legs (the same landmarks with the neck above the hips) it would pass the trunk test: the
    # other tests are what they are, and the trunk is what failed.
    upright = dict(points, hips=np.array([0.0, 0.35, 0.35]), neck=np.array([0.0, 0.33, 0.5]),
                   head=np.array([0.0, 0.33, 0.52]))
    assert biped_layout(upright, animal) is not None
    assert quadruped_layout(upright, animal) is None


def test_a_box_animal_with_its_joints_in_place_is_laid_out_as_a_quadruped(animal):
    layout = quadruped_layout(_both_sides(ANIMAL_JOINTS), animal)
    assert layout is not None and layout.kind == "quadruped"
    assert layout.inside_share == 1.0
    assert layout.note == ("its quadruped landmarks make a four-legged body (every leg and the trunk inside it, each "
                           "pair of feet apart, the front and hind feet level, the trunk above them along the body's "
                           "length), so it is taken for a quadruped")
    # An upright chibi's landmarks are no quadruped: its trunk rises.
    assert quadruped_layout(_both_sides(CHIBI_JOINTS), solid_depth(_boxes(*LEGS, TRUNK, HEAD, *ARMS))) is None


def test_a_quadruped_facing_plus_y_or_with_its_feet_crossed_is_not_laid_out_as_one(animal):
    points = _both_sides(ANIMAL_JOINTS)
    # Read the wrong way round (the neck behind the hips, at +y): not a quadruped facing -y.
    turned = {name: point * np.array([1.0, -1.0, 1.0]) for name, point in points.items()}
    assert quadruped_layout(turned, animal) is None
    # The front legs' landmarks on the hind legs and the hind legs' on the front legs: all inside, in order and level,
    # but the front feet behind the hind feet.
    crossed = {name: point * np.array([1.0, -1.0, 1.0]) if name not in ("hips", "neck", "head") else point
               for name, point in points.items()}
    assert quadruped_layout(crossed, animal) is None
    # A knee read below its ankle.
    assert quadruped_layout(_both_sides({**ANIMAL_JOINTS, "knee.L": [0.1, 0.35, 0.02]}), animal) is None


def _raptor(front_leg_bottom: float, elbow: float, wrist: float):
    """A body on two hind legs 0.5 long (ankles at 0.05) with a trunk at 0.5 to 0.65 (hips at 0.57) and front legs
    from the trunk down to ``front_leg_bottom``, and its landmarks with the front ``elbow`` and ``wrist`` at those
    heights."""
    front = tuple(([x0, -0.4, front_leg_bottom], [x0 + 0.1, -0.3, 0.55]) for x0 in (-0.15, 0.05))
    hind = tuple(([x0, 0.3, 0.0], [x0 + 0.1, 0.4, 0.55]) for x0 in (-0.15, 0.05))
    body = ([-0.15, -0.45, 0.5], [0.15, 0.45, 0.65])
    solid = solid_depth(_boxes(*front, *hind, body, ([-0.1, -0.6, 0.6], [0.1, -0.4, 0.8])))
    points = _both_sides({
        "hips": [0.0, 0.35, 0.57], "neck": [0.0, -0.4, 0.6], "head": [0.0, -0.5, 0.7],
        "shoulder.L": [0.1, -0.35, 0.52], "elbow.L": [0.1, -0.35, elbow], "wrist.L": [0.1, -0.35, wrist],
        "hip.L": [0.1, 0.35, 0.5], "knee.L": [0.1, 0.35, 0.27], "ankle.L": [0.1, 0.35, 0.05],
    })
    return points, solid


def test_front_feet_held_high_are_hands_not_legs():
    # Short front legs ending 0.3 above the ground (a raptor's arms): the wrists 0.35 high, 0.30 above the ankles,
    # the trunk 0.52 above them. 0.30 > 0.5 * 0.52: hands, not feet.
    assert MAX_FEET_LEVEL_GAP == 0.5
    assert quadruped_layout(*_raptor(0.3, 0.45, 0.35)) is None
    # Front feet 0.25 high (0.20 above the ankles) stand on the ground with the hind ones, as far as the test goes.
    assert quadruped_layout(*_raptor(0.2, 0.4, 0.25)) is not None
    # Legs to the ground, as a quadruped's.
    assert quadruped_layout(*_raptor(0.0, 0.3, 0.05)) is not None


def test_a_quadrupeds_thin_legs_need_half_their_length_inside(animal):
    # Hind ankles read behind the leg (its box ends at y = 0.4): the shin leaves it partway down. At y = 0.45, 6 of
    # the shin's 11 points are inside: enough for a quadruped's thin leg, not for a biped's limb.
    assert MIN_LEG_INSIDE_SHARE == 0.5 < 6 / 11 < MIN_INSIDE_SHARE
    half = quadruped_layout(_both_sides({**ANIMAL_JOINTS, "ankle.L": [0.1, 0.45, 0.05]}), animal)
    assert half is not None and half.inside_share == pytest.approx(6 / 11)
    assert "every leg and the trunk at least 55% inside it" in half.note
    # At y = 0.47, 5 of 11.
    assert quadruped_layout(_both_sides({**ANIMAL_JOINTS, "ankle.L": [0.1, 0.47, 0.05]}), animal) is None
    # Front feet in one column (a single block under the chest): no pair of legs.
    column = ([-0.15, -0.4, 0.0], [0.15, -0.3, 0.3])
    solid = solid_depth(_boxes(column, *ANIMAL_LEGS[1::2], ANIMAL_BODY, ANIMAL_HEAD))
    assert quadruped_layout(_both_sides(ANIMAL_JOINTS), solid) is None


OTHER_SURELY = {"biped": 0.05, "quadruped": 0.05, "other": 0.9}


def _votes(monkeypatch, mesh, kind_probabilities, nearest=None, joints=CHIBI_JOINTS, body=None, head_at=None):
    """predict_votes on ``mesh`` with the landmark network's kind head reading
    ``kind_probabilities`` (as it reads Kenney's minis: "other") and its points
    ``joints`` (default the chibi's) of ``body`` (default the chibi), in the
    frame the graph is in (its box is the body's box, scaled and moved), and
    ``nearest`` as the nearest known body. ``head_at``: None, the points as
    given (their head toward -y) whichever way the graph faces; ``"head
    end"``, a network that finds the head at the graph's higher end (its
    points turned half a turn when that end is at +y); ``"tail end"``, one
    that puts it at the lower end."""
    from dataclasses import replace

    from autorig_addon.core.rigging import predict

    body = _boxes(*LEGS, TRUNK, HEAD, *ARMS) if body is None else body
    low, high = body.vertices.min(axis=0), body.vertices.max(axis=0)
    network = predict.predict_landmarks

    def read(graph):
        found = network(graph)
        vertices = graph.vertices
        box_low, box_high = vertices.min(axis=0), vertices.max(axis=0)
        given = _both_sides(joints)
        if head_at is not None:
            end = 0.15 * (box_high[1] - box_low[1])
            higher_at_plus_y = (vertices[vertices[:, 1] > box_high[1] - end, 2].mean()
                                > vertices[vertices[:, 1] < box_low[1] + end, 2].mean())
            if higher_at_plus_y == (head_at == "head end"):
                given = {mirror_name(name): point * np.array([-1.0, -1.0, 1.0]) for name, point in given.items()}
        points = {name: box_low + (point - low) / (high - low) * (box_high - box_low) for name, point in given.items()}
        return replace(found, points={**found.points, **points}, kind_probabilities=kind_probabilities)

    monkeypatch.setattr(predict, "predict_landmarks", read)
    monkeypatch.setattr(predict, "nearest_known_body", lambda surface: nearest)
    return predict.predict_votes(mesh)


def _half_turned(mesh: Mesh) -> Mesh:
    """``mesh`` turned half a turn about z (facing +y if it faced -y)."""
    return Mesh(mesh.vertices * np.array([-1.0, -1.0, 1.0]), mesh.triangles)


def test_a_body_read_as_other_with_no_known_relative_is_a_biped_by_its_layout(monkeypatch):
    from autorig_addon.core.rigging import predict
    from autorig_addon.core.skeleton.key_joints import key_joints

    mesh = _boxes(*LEGS, TRUNK, HEAD, *ARMS)
    votes = _votes(monkeypatch, mesh, OTHER_SURELY)
    assert votes.landmarks.relative is None and votes.landmarks.layout is not None
    assert votes.landmarks.kind_told_by is votes.landmarks.layout
    kind, note = predict.chosen_template(votes, known_rig=False)
    assert kind == "biped"
    assert note.startswith("Template: standard biped skeleton; the landmark network reads the body as other (90% "
                           "sure), not surely a biped or quadruped; its biped landmarks make an upright body")
    skeleton = predict.skeleton_from_votes(votes, fingers=False, known_rig=False)
    found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
    assert len(found) == 15
    # In the mesh's own space: the left shoulder on the body's left (+x, facing -y), the head above the neck above
    # the hips, the ankles at the feet.
    assert found["shoulder.L"][0] > 0.15 and found["shoulder.R"][0] < -0.15
    assert found["head"][2] > found["neck"][2] > found["hips"][2] > 0.25
    assert found["ankle.L"][2] < 0.1 and found["ankle.R"][2] < 0.1
    # Were its landmarks laid out otherwise (no layout found), nothing would tell its kind: the free-form skeleton.
    monkeypatch.setattr(predict, "biped_layout", lambda points, solid: None)
    assert predict.chosen_template(predict.predict_votes(mesh))[0] == "free-form"


def test_the_layout_is_read_only_when_neither_the_network_nor_a_known_biped_tells_the_kind(monkeypatch):
    from autorig_addon.core.rigging.rig_library import KnownRelative

    mesh = _boxes(*LEGS, TRUNK, HEAD, *ARMS)
    # Read surely as a biped: nothing else is asked.
    surely = _votes(monkeypatch, mesh, {"biped": 0.9, "quadruped": 0.05, "other": 0.05}).landmarks
    assert surely.layout is None and surely.kind_told_by is None and surely.standard_kind == "biped"
    # Near a known biped: the relative tells it, and the layout is not read.
    relative = KnownRelative("kaykit/Ranger", "biped", 0.03)
    near = _votes(monkeypatch, mesh, OTHER_SURELY, nearest=relative).landmarks
    assert near.layout is None and near.kind_told_by == relative


def test_a_body_a_biped_by_its_layout_facing_plus_y_is_turned_by_its_toes(monkeypatch):
    from autorig_addon.core.rigging import predict
    from autorig_addon.core.skeleton.key_joints import key_joints

    # The chibi with feet reaching forward of its legs (toes), given facing +Y: turned half a turn.
    feet = [([x0, -0.2, 0.0], [x0 + 0.15, 0.08, 0.05]) for x0 in (-0.2, 0.05)]
    facing_minus_y = _boxes(*LEGS, *feet, TRUNK, HEAD, *ARMS)
    mesh = type(facing_minus_y)(facing_minus_y.vertices * np.array([-1.0, -1.0, 1.0]), facing_minus_y.triangles)
    votes = _votes(monkeypatch, mesh, OTHER_SURELY)
    assert votes.landmarks.layout is not None
    assert ("The character faces away from -Y (its toes point toward +Y); it was turned half a turn for the "
            "prediction, so its .L bones lie on its own left.") in votes.notes
    skeleton = predict.skeleton_from_votes(votes, fingers=False, known_rig=False)
    found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
    # Facing +Y, its own left lies at -X.
    assert found["shoulder.L"][0] < -0.15 and found["shoulder.R"][0] > 0.15


def test_a_body_read_as_other_laid_out_as_a_quadruped_gets_the_quadruped_skeleton(monkeypatch):
    from autorig_addon.core.rigging import predict
    from autorig_addon.core.skeleton.key_joints import key_joints

    mesh = _boxes(*ANIMAL_LEGS, ANIMAL_BODY, ANIMAL_HEAD)
    votes = _votes(monkeypatch, mesh, OTHER_SURELY, joints=ANIMAL_JOINTS, body=mesh)
    layout = votes.landmarks.layout
    assert layout is not None and layout.kind == "quadruped" and votes.landmarks.kind_told_by is layout
    kind, note = predict.chosen_template(votes, known_rig=False)
    assert kind == "quadruped"
    assert note.startswith("Template: standard quadruped skeleton; the landmark network reads the body as other (90% "
                           "sure), not surely a biped or quadruped; its quadruped landmarks make a four-legged body")
    skeleton = predict.skeleton_from_votes(votes, known_rig=False)
    found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
    # Front legs take the arm roles and stand at the head end (-y), the hind legs' at the rump.
    assert len(found) == 15
    assert found["head"][1] < found["neck"][1] < found["hips"][1]
    assert found["wrist.L"][1] < -0.25 and found["ankle.L"][1] > 0.25
    assert found["shoulder.L"][0] > 0.0 and found["shoulder.R"][0] < 0.0
    # Nothing but the layout tells its kind: without it, the free-form skeleton.
    monkeypatch.setattr(predict, "quadruped_layout", lambda points, solid: None)
    assert predict.chosen_template(predict.predict_votes(mesh))[0] == "free-form"


#: The box animal with a tail as long as its head reaches forward: its box is the same either way round, and its head
#: end stands higher than its tail's.
TAIL = ([-0.03, 0.45, 0.45], [0.03, 0.6, 0.5])


@pytest.mark.parametrize("head_at", [None, "head end"])
def test_a_body_a_quadruped_by_its_layout_facing_plus_y_is_turned_by_its_head_end(monkeypatch, head_at):
    from autorig_addon.core.rigging import predict
    from autorig_addon.core.skeleton.key_joints import key_joints

    # The box animal given facing +Y. head_at None: read as given or turned, the network lays it out as a quadruped
    # facing -y, first with its head on the tail (its head end, toward +Y, turns it), then where it is. "head end": a
    # network that finds the head where it is, so its landmarks as given (head at +y) make no quadruped facing -y; read
    # turned half a turn, they do.
    facing_minus_y = _boxes(*ANIMAL_LEGS, ANIMAL_BODY, ANIMAL_HEAD, TAIL)
    votes = _votes(monkeypatch, _half_turned(facing_minus_y), OTHER_SURELY, joints=ANIMAL_JOINTS,
                   body=facing_minus_y, head_at=head_at)
    assert votes.landmarks.layout is not None and votes.landmarks.layout.kind == "quadruped"
    assert ("The character faces away from -Y (its head end is toward +Y); it was turned half a turn for the "
            "prediction, so its .L bones lie on its own left.") in votes.notes
    skeleton = predict.skeleton_from_votes(votes, known_rig=False)
    found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
    # In the mesh's own space the head is at +y and, facing +Y, its own left lies at -X.
    assert found["head"][1] > found["hips"][1] + 0.3
    assert found["shoulder.L"][0] < 0.0 and found["shoulder.R"][0] > 0.0
    # Given facing -Y, it is read as it stands: no turn.
    votes = _votes(monkeypatch, facing_minus_y, OTHER_SURELY, joints=ANIMAL_JOINTS, body=facing_minus_y,
                   head_at=head_at)
    assert votes.landmarks.layout.kind == "quadruped" and not any("turned half a turn" in n for n in votes.notes)


def test_a_quadruped_laid_out_with_its_head_on_its_tail_either_way_round_is_no_quadruped(monkeypatch):
    from autorig_addon.core.rigging import predict
    from autorig_addon.core.rigging.facing import front_untold_note

    # A network that puts the head at the lower end: given facing +Y, the landmarks make a quadruped facing -y with
    # its head on the tail, and turned, another with its head on the tail. Its head end stands toward +Y, so the first
    # is reversed and the second no better: neither is taken, and the body keeps the free-form skeleton.
    facing_minus_y = _boxes(*ANIMAL_LEGS, ANIMAL_BODY, ANIMAL_HEAD, TAIL)
    votes = _votes(monkeypatch, _half_turned(facing_minus_y), OTHER_SURELY, joints=ANIMAL_JOINTS,
                   body=facing_minus_y, head_at="tail end")
    assert votes.landmarks.layout is None
    assert not any("turned half a turn" in n for n in votes.notes)
    assert front_untold_note("-Y") in votes.notes
    assert predict.chosen_template(votes)[0] == "free-form"


def test_a_quadruped_by_its_layout_whose_ends_stand_alike_is_taken_as_given_and_says_so(monkeypatch):
    from autorig_addon.core.rigging import predict
    from autorig_addon.core.rigging.facing import front_untold_note

    # The box animal without head or tail: neither end stands higher, so nothing tells its front.
    mesh = _boxes(*ANIMAL_LEGS, ANIMAL_BODY)
    votes = _votes(monkeypatch, mesh, OTHER_SURELY, joints={**ANIMAL_JOINTS, "head": [0.0, -0.44, 0.5]}, body=mesh)
    assert votes.landmarks.layout is not None and votes.landmarks.layout.kind == "quadruped"
    note = front_untold_note("-Y", "quadruped")
    assert "and neither end of it stands higher)" in note and note in votes.notes
    assert predict.chosen_template(votes, known_rig=False)[0] == "quadruped"
