"""Short legs and big heads read again (core/rigging/typical_proportions.py): the
crotch and the neck's pinch found in the solid (an open trunk's crotch by
its surface's winding number), the map to typical proportions and back, a
short-legged biped whose hip joints and a big-headed one whose neck the
landmark network puts far too high at first, and hip joints read below the
crotch raised to it."""

import re
from dataclasses import replace

import numpy as np
import pytest

from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging import predict
from autorig_addon.core.rigging import typical_proportions as proportions
from autorig_addon.core.rigging.joint_features import solid_depth
from autorig_addon.core.rigging.networks.landmarks import LANDMARKS
from autorig_addon.core.rigging.predict import predict_votes, skeleton_from_votes
from autorig_addon.core.rigging.quality import enclosed_by
from autorig_addon.core.rigging.standard_skeleton import Landmarks
from autorig_addon.core.rigging.typical_proportions import (
    HeightMap,
    crotch_height,
    hip_joints_raised_to_crotch,
    neck_pinch,
    typical_proportions,
)
from autorig_addon.core.skeleton.key_joints import key_joints
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh

#: The trunk of the two-legged block body starts at this height.
CROTCH = 0.3


SURE_BIPED = {"biped": 0.95, "quadruped": 0.0, "other": 0.05}


def joined(*meshes: Mesh) -> Mesh:
    offsets = np.cumsum([0] + [mesh.vertex_count for mesh in meshes[:-1]])
    return Mesh(np.concatenate([mesh.vertices for mesh in meshes]),
                np.concatenate([mesh.triangles + offset for mesh, offset in zip(meshes, offsets)]))


@pytest.fixture(scope="module")
def block_body():
    """Two legs (x = +-0.1, up to the crotch) under a trunk up to z = 1."""
    legs = [box_mesh([side * 0.1 - 0.05, -0.05, 0.0], [side * 0.1 + 0.05, 0.05, CROTCH], 0.05) for side in (-1, 1)]
    trunk = box_mesh([-0.2, -0.08, CROTCH], [0.2, 0.08, 1.0], 0.05)
    return solid_depth(joined(*legs, trunk))


def test_the_height_map_sends_each_knot_to_its_target_and_back():
    height_map = HeightMap(heights=(0.0, 0.2, 1.0), targets=(0.0, 0.44, 1.0))
    np.testing.assert_allclose(height_map.forward([0.0, 0.1, 0.2, 0.6, 1.0]), [0.0, 0.22, 0.44, 0.72, 1.0])
    heights = np.linspace(0.0, 1.0, 11)
    np.testing.assert_allclose(height_map.inverse(height_map.forward(heights)), heights)
    # Crotch and neck: the head above 0.6 squeezed into the top 0.16.
    height_map = HeightMap(heights=(0.0, 0.3, 0.6, 1.0), targets=(0.0, 0.44, 0.84, 1.0))
    np.testing.assert_allclose(height_map.forward([0.15, 0.45, 0.8]), [0.22, 0.64, 0.92])
    np.testing.assert_allclose(height_map.inverse(height_map.forward(heights)), heights)


def test_the_crotch_is_where_the_line_between_the_knees_enters_the_solid(block_body):
    knees = np.array([[0.1, 0.0, 0.15], [-0.1, 0.0, 0.15]])
    # Half a voxel deep in a solid of 1/96 voxels: within a voxel of the trunk's bottom.
    assert crotch_height(block_body, knees, top=1.0) == pytest.approx(CROTCH, abs=block_body.cell_size)
    # Knees above the trunk's top: nothing inside below 0.8 of the height.
    assert crotch_height(block_body, knees + [0, 0, 0.7], top=1.0) is None


def test_only_hip_joints_far_above_the_crotch_ask_for_the_stretch(block_body):
    points = {"knee.L": np.array([0.1, 0.0, 0.15]), "knee.R": np.array([-0.1, 0.0, 0.15]),
              "neck": np.array([0.0, 0.0, 0.9])}
    # Hip joints 0.1 above a crotch at 0.3 (a third of its height): read as they are.
    points.update({"hip.L": np.array([0.1, 0.0, 0.4]), "hip.R": np.array([-0.1, 0.0, 0.4])})
    assert typical_proportions(points, block_body, top=1.0) is None
    # 0.3 above it (a whole crotch height): the body is stretched, the crotch to 0.44 of the height.
    points.update({"hip.L": np.array([0.1, 0.0, 0.6]), "hip.R": np.array([-0.1, 0.0, 0.6])})
    found = typical_proportions(points, block_body, top=1.0)
    assert found.short_legs and not found.big_head
    assert found.height_map.heights[1] == pytest.approx(CROTCH, abs=block_body.cell_size)
    assert found.height_map.targets == pytest.approx((0.0, proportions.TYPICAL_CROTCH_SHARE, 1.0))


#: The block figure's neck: a narrow box from NECK to NECK + 0.05 under a wide head up to z = 1.
NECK = 0.6


def block_figure_mesh() -> Mesh:
    """Two legs up to the crotch, a trunk up to NECK, a neck a quarter as
    wide and a head as wide as the trunk up to z = 1."""
    legs = [box_mesh([side * 0.1 - 0.05, -0.05, 0.0], [side * 0.1 + 0.05, 0.05, CROTCH], 0.05) for side in (-1, 1)]
    trunk = box_mesh([-0.2, -0.08, CROTCH], [0.2, 0.08, NECK], 0.05)
    neck = box_mesh([-0.05, -0.04, NECK], [0.05, 0.04, NECK + 0.05], 0.05)
    head = box_mesh([-0.2, -0.12, NECK + 0.05], [0.2, 0.12, 1.0], 0.05)
    return joined(*legs, trunk, neck, head)


@pytest.fixture(scope="module")
def block_figure():
    return solid_depth(block_figure_mesh())


def test_the_neck_is_the_pinch_between_the_chest_and_the_head(block_figure, block_body):
    pinch = neck_pinch(block_figure, CROTCH, top=1.0)
    assert NECK - block_figure.cell_size <= pinch <= NECK + 0.05 + block_figure.cell_size
    # A trunk that runs straight up into the head has no neck.
    assert neck_pinch(block_body, CROTCH, top=1.0) is None


def test_the_empty_midline_above_the_crown_is_no_neck():
    # The block body under a head ending at 0.8, with two horns (off the midline) up to 1.0.
    legs = [box_mesh([side * 0.1 - 0.05, -0.05, 0.0], [side * 0.1 + 0.05, 0.05, CROTCH], 0.05) for side in (-1, 1)]
    horns = [box_mesh([side * 0.15 - 0.03, -0.03, 0.8], [side * 0.15 + 0.03, 0.03, 1.0], 0.05) for side in (-1, 1)]
    horned = solid_depth(joined(*legs, box_mesh([-0.2, -0.08, CROTCH], [0.2, 0.08, 0.8], 0.05), *horns))
    assert neck_pinch(horned, CROTCH, top=1.0) is None
    # The block figure with the same horns: its neck is still the pinch under its head.
    neck = box_mesh([-0.05, -0.04, NECK], [0.05, 0.04, NECK + 0.05], 0.05)
    head = box_mesh([-0.2, -0.12, NECK + 0.05], [0.2, 0.12, 0.8], 0.05)
    figure = solid_depth(joined(*legs, box_mesh([-0.2, -0.08, CROTCH], [0.2, 0.08, NECK], 0.05), neck, head, *horns))
    assert NECK - figure.cell_size <= neck_pinch(figure, CROTCH, top=1.0) <= NECK + 0.05 + figure.cell_size


def test_the_height_map_goes_on_along_its_end_pieces_and_refuses_knots_out_of_order():
    height_map = HeightMap(heights=(0.0, 0.2, 1.0), targets=(0.0, 0.44, 1.0))
    # Below the floor along the first piece (slope 2.2), above the top along the last (slope 0.7).
    np.testing.assert_allclose(height_map.forward([-0.01, 1.1]), [-0.022, 1.07])
    np.testing.assert_allclose(height_map.inverse(height_map.forward([-0.01, 1.1])), [-0.01, 1.1])
    with pytest.raises(ValueError):
        HeightMap(heights=(0.0, 0.6, 0.5, 1.0), targets=(0.0, 0.44, 0.84, 1.0))


def test_only_a_neck_read_far_above_the_pinch_asks_for_the_map(block_figure):
    points = {"knee.L": np.array([0.1, 0.0, 0.15]), "knee.R": np.array([-0.1, 0.0, 0.15]),
              "hip.L": np.array([0.1, 0.0, 0.32]), "hip.R": np.array([-0.1, 0.0, 0.32])}
    # A neck read about 0.02 above the pinch (found at 0.609): as it is.
    assert typical_proportions({**points, "neck": np.array([0.0, 0.0, NECK + 0.03])}, block_figure, 1.0) is None
    # About 0.17 above it: the pinch goes to 0.84 of the height and the crotch to 0.44.
    found = typical_proportions({**points, "neck": np.array([0.0, 0.0, NECK + 0.175])}, block_figure, 1.0)
    assert found.big_head and not found.short_legs
    assert found.height_map.targets == pytest.approx(
        (0.0, proportions.TYPICAL_CROTCH_SHARE, proportions.TYPICAL_NECK_SHARE, 1.0))
    assert found.height_map.heights[2] == pytest.approx(found.neck)


def short_legged_biped():
    """The procedural biped of seed 0 with its legs below the crotch
    squashed to 45 % of their length (a chibi's crotch at 20 % of the
    height), and its artist's key joints moved with it."""
    character = generate_character(0, "biped")
    vertices = character.mesh.vertices
    floor, top = vertices[:, 2].min(), np.ptp(vertices[:, 2])
    truth = key_joints(character.skeleton.names, character.skeleton.joints, parents=character.skeleton.parents)
    crotch = 0.5 * (truth.positions["hip.L"][2] + truth.positions["hip.R"][2]) - floor - 0.03 * top
    squash = HeightMap((0.0, crotch, top), (0.0, 0.45 * crotch, top))

    def squashed(points):
        points = np.array(points, dtype=np.float64)
        points[:, 2] = squash.forward(points[:, 2] - floor) + floor
        return points

    mesh = Mesh(squashed(vertices), character.mesh.triangles)
    return mesh, {name: squashed(point[None])[0] for name, point in truth.positions.items()}


def hip_joint_errors(mesh: Mesh, truth: dict) -> tuple:
    votes = predict_votes(mesh)
    skeleton = skeleton_from_votes(votes)
    found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
    size = np.ptp(mesh.vertices, axis=0).max()
    return [np.linalg.norm(found[name] - truth[name]) / size for name in ("hip.L", "hip.R")], votes.notes


def test_a_short_legged_biped_is_read_again_and_its_hip_joints_come_down(monkeypatch):
    mesh, truth = short_legged_biped()
    errors, notes = hip_joint_errors(mesh, truth)
    # Measured: 0.017 of the largest side with the second reading, 0.109 without.
    assert max(errors) < 0.05, errors
    # The note gives the crotch it measured on the mesh: the squashed crotch lies at 19.8 % of the height (the
    # reading finds the legs' parting a little below it, 17 to 18 %).
    shares = [int(found.group(1)) for found in (re.match(r"The legs are short \(crotch at (\d+)% of the height\)", note)
                                                for note in notes) if found]
    assert len(shares) == 1 and 15 <= shares[0] <= 20, notes
    # The first reading alone: neither reading again.
    monkeypatch.setattr(proportions, "HIP_ABOVE_CROTCH", np.inf)
    monkeypatch.setattr(proportions, "NECK_ABOVE_PINCH", np.inf)
    first_reading, notes = hip_joint_errors(mesh, truth)
    assert min(first_reading) > 0.08, first_reading
    assert not any("legs are short" in note for note in notes)


def big_headed_biped():
    """The procedural biped of seed 4 with its head (the vertices its head
    bone and the bones below it move most) scaled 4 times about the head
    joint: a chibi, its neck at 53 % of the height."""
    character = generate_character(4, "biped")
    skeleton, weights = character.skeleton, character.weights
    truth = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents)
    head_bones = {truth.bones["head"]}
    for bone, parent in enumerate(skeleton.parents):  # parents come first
        if parent in head_bones:
            head_bones.add(bone)
    columns = [weights.bone_names.index(skeleton.names[bone]) for bone in head_bones
               if skeleton.names[bone] in weights.bone_names]
    in_head = np.isin(np.argmax(weights.matrix, axis=1), columns)
    vertices = character.mesh.vertices.copy()
    centre = truth.positions["head"]
    vertices[in_head] = centre + 4.0 * (vertices[in_head] - centre)
    return Mesh(vertices, character.mesh.triangles), truth.positions


def neck_error(mesh: Mesh, truth: dict) -> tuple:
    votes = predict_votes(mesh)
    skeleton = skeleton_from_votes(votes)
    found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
    return np.linalg.norm(found["neck"] - truth["neck"]) / np.ptp(mesh.vertices, axis=0).max(), votes.notes


def test_a_big_headed_biped_is_read_again_and_its_neck_comes_down(monkeypatch):
    mesh, truth = big_headed_biped()
    error, notes = neck_error(mesh, truth)
    # Measured: 0.030 of the largest side with the second reading, 0.093 without.
    assert error < 0.05, error
    assert any(note.startswith("The head is big (neck at 57% of the height") for note in notes), notes
    # The first reading alone: neither reading again.
    monkeypatch.setattr(proportions, "NECK_ABOVE_PINCH", np.inf)
    monkeypatch.setattr(proportions, "HIP_ABOVE_CROTCH", np.inf)
    first_reading, notes = neck_error(mesh, truth)
    assert first_reading > 0.08, first_reading
    assert not any("head is big" in note for note in notes)


def test_a_body_read_from_behind_is_read_again_from_behind(monkeypatch, block_figure):
    """The second reading of a body whose first was taken from behind is
    from behind too: wrists the network puts in front of the body it is
    shown lie behind it once that reading is turned back."""
    seen = {name: np.zeros(3) for name in LANDMARKS}
    seen["wrist.L"], seen["wrist.R"] = np.array([0.3, -0.05, 0.6]), np.array([-0.3, -0.05, 0.6])
    monkeypatch.setattr(predict, "predict_landmarks", lambda graph: Landmarks(dict(seen), SURE_BIPED))
    first = {name: np.zeros(3) for name in LANDMARKS}
    first.update({"knee.L": np.array([0.1, 0.0, 0.15]), "knee.R": np.array([-0.1, 0.0, 0.15]),
                  "hip.L": np.array([0.1, 0.0, 0.32]), "hip.R": np.array([-0.1, 0.0, 0.32]),
                  "neck": np.array([0.0, 0.0, NECK + 0.175])})
    mesh = block_figure_mesh()
    for from_behind, wrists_side in ((False, -1.0), (True, 1.0)):
        again, notes = predict._read_again_at_typical_proportions(mesh, block_figure, Landmarks(first, SURE_BIPED),
                                                                  from_behind)
        assert notes and notes[0].startswith("The head is big")
        # The right wrist stays at the body's right (-x) either way; in front (-y) as given, behind turned back.
        assert again.points["wrist.R"][0] < 0.0
        assert np.sign(again.points["wrist.R"][1]) == np.sign(again.points["wrist.L"][1]) == wrists_side


def open_bottomed_block_body() -> Mesh:
    """The block body whose trunk has no bottom face (a low-poly body whose
    legs are objects of their own leaves that hole): its solid leaks to a
    shell."""
    legs = [box_mesh([side * 0.1 - 0.05, -0.05, 0.0], [side * 0.1 + 0.05, 0.05, CROTCH], 0.05) for side in (-1, 1)]
    trunk = box_mesh([-0.2, -0.08, CROTCH], [0.2, 0.08, 1.0], 0.05)
    bottom = np.all(np.isclose(trunk.vertices[trunk.triangles][:, :, 2], CROTCH), axis=1)
    return joined(*legs, Mesh(trunk.vertices, trunk.triangles[~bottom]))


def test_an_open_trunk_s_crotch_is_where_its_surface_encloses_the_line():
    mesh = open_bottomed_block_body()
    solid = solid_depth(mesh)
    knees = np.array([[0.1, 0.0, 0.15], [-0.1, 0.0, 0.15]])
    # The solid alone is a shell: the line between the knees goes up the hollow trunk and meets nothing.
    assert crotch_height(solid, knees, top=1.0) is None
    # Enclosed by the surface (winding number 0.5 at the hole, rising above it): just above the trunk's bottom.
    crotch = crotch_height(solid, knees, top=1.0, enclosed=enclosed_by(mesh))
    assert CROTCH <= crotch <= CROTCH + 0.02, crotch
    # A closed body's crotch stays the solid's.
    closed = joined(*[box_mesh([s * 0.1 - 0.05, -0.05, 0.0], [s * 0.1 + 0.05, 0.05, CROTCH], 0.05) for s in (-1, 1)],
                    box_mesh([-0.2, -0.08, CROTCH], [0.2, 0.08, 1.0], 0.05))
    closed_solid = solid_depth(closed)
    assert (crotch_height(closed_solid, knees, 1.0, enclosed_by(closed))
            == crotch_height(closed_solid, knees, 1.0))


def test_legs_inside_a_robe_open_at_the_bottom_keep_their_own_crotch():
    """A robe, a tube open at the bottom from below the knees up to the trunk, encloses the line from
    the hem up: that is no crotch, so the legs' own fork (in the solid) stays the crotch."""
    legs = [box_mesh([side * 0.1 - 0.05, -0.05, 0.0], [side * 0.1 + 0.05, 0.05, 0.45], 0.05) for side in (-1, 1)]
    trunk = box_mesh([-0.2, -0.08, 0.45], [0.2, 0.08, 1.0], 0.05)
    tube = box_mesh([-0.3, -0.15, 0.05], [0.3, 0.15, 0.6], 0.05)
    bottom = np.all(np.isclose(tube.vertices[tube.triangles][:, :, 2], 0.05), axis=1)
    mesh = joined(*legs, trunk, Mesh(tube.vertices, tube.triangles[~bottom]))
    solid = solid_depth(mesh)
    knees = np.array([[0.1, 0.0, 0.22], [-0.1, 0.0, 0.22]])
    assert enclosed_by(mesh)(knees.mean(axis=0)[None])[0]  # the line starts inside the robe
    assert crotch_height(solid, knees, 1.0, enclosed_by(mesh)) == crotch_height(solid, knees, 1.0)


def test_hip_joints_read_below_the_crotch_are_raised_to_it_with_the_hips(block_body):
    points = {"knee.L": np.array([0.1, 0.0, 0.15]), "knee.R": np.array([-0.1, 0.0, 0.15]),
              "hip.L": np.array([0.1, 0.01, 0.22]), "hip.R": np.array([-0.1, 0.01, 0.24]),
              "hips": np.array([0.0, 0.02, 0.2]), "neck": np.array([0.0, 0.0, 0.9])}
    raised, lift = hip_joints_raised_to_crotch(points, block_body, top=1.0)
    crotch = crotch_height(block_body, np.array([points["knee.L"], points["knee.R"]]), 1.0)
    # The middle of the hip joints (0.23) goes to the crotch (about 0.3); each keeps its offset, the hips too.
    assert lift == pytest.approx(crotch - 0.23)
    assert 0.06 < lift < 0.08
    for name in ("hip.L", "hip.R", "hips"):
        np.testing.assert_allclose(raised[name], points[name] + [0.0, 0.0, lift])
    for name in ("knee.L", "knee.R", "neck"):
        np.testing.assert_array_equal(raised[name], points[name])
    # Hip joints at or above the crotch stay, and so does everything else.
    above = {**points, "hip.L": np.array([0.1, 0.0, 0.33]), "hip.R": np.array([-0.1, 0.0, 0.33])}
    kept, lift = hip_joints_raised_to_crotch(above, block_body, top=1.0)
    assert lift == 0.0 and kept is above
    # Knees above the trunk's top find no crotch: nothing moves.
    high_knees = {**points, "knee.L": np.array([0.1, 0.0, 0.85]), "knee.R": np.array([-0.1, 0.0, 0.85])}
    assert hip_joints_raised_to_crotch(high_knees, block_body, top=1.0)[1] == 0.0


def test_a_biped_s_landmarks_get_their_hip_joints_raised_in_the_prediction():
    """The step the prediction runs: a sure biped's landmarks raised on its open body, a quadruped's as they are."""
    mesh = open_bottomed_block_body()
    first = {name: np.zeros(3) for name in LANDMARKS}
    first.update({"knee.L": np.array([0.1, 0.0, 0.15]), "knee.R": np.array([-0.1, 0.0, 0.15]),
                  "hip.L": np.array([0.1, 0.0, 0.2]), "hip.R": np.array([-0.1, 0.0, 0.2]),
                  "hips": np.array([0.0, 0.0, 0.19])})
    raised = predict._raise_hip_joints_to_crotch(mesh, solid_depth(mesh), Landmarks(first, SURE_BIPED))
    assert CROTCH <= raised.points["hip.L"][2] <= CROTCH + 0.02
    assert raised.points["hips"][2] == pytest.approx(raised.points["hip.L"][2] - 0.01)
    quadruped = Landmarks(first, {"biped": 0.0, "quadruped": 0.95, "other": 0.05})
    assert predict._raise_hip_joints_to_crotch(mesh, solid_depth(mesh), quadruped) is quadruped


def test_the_prediction_raises_the_hip_joints_it_reads(monkeypatch):
    """predict_votes hands its landmarks to the raise and keeps what it returns."""
    raised = []

    def spy(normalised, solid, landmarks):
        moved = {**landmarks.points, "hip.L": landmarks.points["hip.L"] + [0.0, 0.0, 0.05]}
        raised.append(moved["hip.L"])
        return replace(landmarks, points=moved)

    monkeypatch.setattr(predict, "_raise_hip_joints_to_crotch", spy)
    votes = predict_votes(short_legged_biped()[0])
    assert len(raised) == 1
    np.testing.assert_array_equal(votes.landmarks.points["hip.L"], raised[0])
