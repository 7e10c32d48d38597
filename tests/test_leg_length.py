"""Short legs read again (core/rigging/leg_length.py): the crotch found in
the solid, the stretch to typical leg length and back, and a short-legged
biped whose hip joints the landmark network puts far too high at first."""

import numpy as np
import pytest

from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging import leg_length
from autorig_addon.core.rigging.joint_features import solid_depth
from autorig_addon.core.rigging.leg_length import HeightMap, crotch_height, short_leg_map
from autorig_addon.core.rigging.predict import predict_votes, skeleton_from_votes
from autorig_addon.core.skeleton.key_joints import key_joints
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh

#: The trunk of the two-legged block body starts at this height.
CROTCH = 0.3


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


def test_the_height_map_sends_the_crotch_to_its_target_and_back():
    height_map = HeightMap(crotch=0.2, target=0.44, top=1.0)
    np.testing.assert_allclose(height_map.forward([0.0, 0.1, 0.2, 0.6, 1.0]), [0.0, 0.22, 0.44, 0.72, 1.0])
    heights = np.linspace(0.0, 1.0, 11)
    np.testing.assert_allclose(height_map.inverse(height_map.forward(heights)), heights)


def test_the_crotch_is_where_the_line_between_the_knees_enters_the_solid(block_body):
    knees = np.array([[0.1, 0.0, 0.15], [-0.1, 0.0, 0.15]])
    # Half a voxel deep in a solid of 1/96 voxels: within a voxel of the trunk's bottom.
    assert crotch_height(block_body, knees, top=1.0) == pytest.approx(CROTCH, abs=block_body.cell_size)
    # Knees above the trunk's top: nothing inside below 0.8 of the height.
    assert crotch_height(block_body, knees + [0, 0, 0.7], top=1.0) is None


def test_only_hip_joints_far_above_the_crotch_ask_for_the_stretch(block_body):
    points = {"knee.L": np.array([0.1, 0.0, 0.15]), "knee.R": np.array([-0.1, 0.0, 0.15])}
    # Hip joints 0.1 above a crotch at 0.3 (a third of its height): read as they are.
    points.update({"hip.L": np.array([0.1, 0.0, 0.4]), "hip.R": np.array([-0.1, 0.0, 0.4])})
    assert short_leg_map(points, block_body, top=1.0) is None
    # 0.3 above it (a whole crotch height): the body is stretched, the crotch to 0.44 of the height.
    points.update({"hip.L": np.array([0.1, 0.0, 0.6]), "hip.R": np.array([-0.1, 0.0, 0.6])})
    height_map = short_leg_map(points, block_body, top=1.0)
    assert height_map.crotch == pytest.approx(CROTCH, abs=block_body.cell_size)
    assert height_map.target == pytest.approx(leg_length.TYPICAL_CROTCH_SHARE)


def short_legged_biped():
    """The procedural biped of seed 0 with its legs below the crotch
    squashed to 45 % of their length (a chibi's crotch at 20 % of the
    height), and its artist's key joints moved with it."""
    character = generate_character(0, "biped")
    vertices = character.mesh.vertices
    floor, top = vertices[:, 2].min(), np.ptp(vertices[:, 2])
    truth = key_joints(character.skeleton.names, character.skeleton.joints, parents=character.skeleton.parents)
    crotch = 0.5 * (truth.positions["hip.L"][2] + truth.positions["hip.R"][2]) - floor - 0.03 * top
    squash = HeightMap(crotch, 0.45 * crotch, top)

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
    assert any(note.startswith("The legs are short (crotch at 18% of the height)") for note in notes), notes
    monkeypatch.setattr(leg_length, "HIP_ABOVE_CROTCH", np.inf)
    first_reading, notes = hip_joint_errors(mesh, truth)
    assert min(first_reading) > 0.08, first_reading
    assert not any("legs are short" in note for note in notes)
