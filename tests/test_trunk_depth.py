"""Trunk joints between front and back (autorig_addon.core.rigging.trunk_depth), on box bodies with known depths."""

import numpy as np
import pytest

from autorig_addon.core.rigging.joint_features import solid_depth
from autorig_addon.core.rigging.trunk_depth import DEPTH_RANGE, solid_runs_along_y, trunk_joints_in_depth
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh

#: The trunk's front and back (it faces -y).
FRONT, BACK = -0.1, 0.1


def _trunk(depth: float = BACK - FRONT):
    """The solid of a trunk 0.2 wide, ``depth`` deep (its front at FRONT) and 1 tall, and its cell size (a run is
    known to half a cell)."""
    solid = solid_depth(box_mesh([-0.1, FRONT, 0.0], [0.1, FRONT + depth, 1.0], 0.05))
    return solid, solid.cell_size


@pytest.mark.parametrize("depth", [0.2, 0.25, 0.2083])
def test_the_solid_along_y_runs_from_the_front_to_the_back_of_the_body(depth):
    # 0.25 and 0.2083 put the surface on a cell boundary, where the solid marks the cells on both sides of it.
    solid, cell = _trunk(depth)
    runs = solid_runs_along_y(solid, np.array([0.0, 0.0, 0.5]))
    assert len(runs) == 1
    np.testing.assert_allclose(runs[0], [FRONT, FRONT + depth], atol=0.5 * cell + 1e-9)
    # Beside the body, off the solid's grid or at NaN the line meets nothing.
    for point in ([0.3, 0.0, 0.5], [0.0, 0.0, 5.0], [np.nan, 0.0, 0.5]):
        assert solid_runs_along_y(solid, np.array(point)) == []


def test_joints_near_the_front_or_in_front_of_the_body_move_back_into_its_middle_along_y_only():
    solid, cell = _trunk()
    points = {"shoulder.L": np.array([0.05, -0.09, 0.8]),  # 0.05 of the way back: at the chest's surface
              "neck": np.array([0.0, -0.2, 0.9]),  # in front of the body
              "hips": np.array([0.0, 0.095, 0.4]),  # at the back
              "hip.L": np.array([0.05, 0.01, 0.4]),  # in the middle already
              "elbow.L": np.array([0.05, -0.09, 0.6])}  # not a trunk joint
    moved = trunk_joints_in_depth(points, solid)
    low, high = DEPTH_RANGE
    depth = BACK - FRONT
    np.testing.assert_allclose(moved["shoulder.L"], [0.05, FRONT + low * depth, 0.8], atol=cell)
    np.testing.assert_allclose(moved["neck"], [0.0, FRONT + low * depth, 0.9], atol=cell)
    np.testing.assert_allclose(moved["hips"], [0.0, FRONT + high * depth, 0.4], atol=cell)
    np.testing.assert_array_equal(moved["hip.L"], points["hip.L"])
    np.testing.assert_array_equal(moved["elbow.L"], points["elbow.L"])
    # x and z are the network's: only the depth moves.
    for role in points:
        assert moved[role][0] == points[role][0] and moved[role][2] == points[role][2]


def test_a_joint_inside_a_hollow_garment_keeps_its_place():
    # A dress open at the hem: its solid is its front and its back, 0.02 thick, nothing between.
    dress = Mesh.concatenate([box_mesh([-0.1, FRONT, 0.0], [0.1, FRONT + 0.02, 1.0], 0.05),
                              box_mesh([-0.1, BACK - 0.02, 0.0], [0.1, BACK, 1.0], 0.05)])
    solid = solid_depth(dress)
    runs = solid_runs_along_y(solid, np.array([0.0, 0.0, 0.5]))
    assert len(runs) == 2
    hips = np.array([0.0, -0.03, 0.5])  # behind the front panel, nearer it than the back: in the gap, not in a run
    assert trunk_joints_in_depth({"hips": hips}, solid)["hips"] is hips


def test_a_joint_before_or_behind_several_runs_moves_into_the_nearest_end_one():
    # A trunk with a backpack behind it, 0.05 apart: two runs on the line through the shoulders.
    body = Mesh.concatenate([box_mesh([-0.1, FRONT, 0.0], [0.1, BACK, 1.0], 0.05),
                             box_mesh([-0.1, BACK + 0.05, 0.5], [0.1, BACK + 0.15, 0.9], 0.05)])
    solid = solid_depth(body)
    cell = solid.cell_size
    (front, back), (pack_front, pack_back) = solid_runs_along_y(solid, np.array([0.05, 0.0, 0.8]))
    low, high = DEPTH_RANGE
    moved = trunk_joints_in_depth({"shoulder.L": np.array([0.05, -0.3, 0.8]),  # in front of the trunk
                                   "shoulder.R": np.array([-0.05, 0.4, 0.8])}, solid)  # behind the backpack
    np.testing.assert_allclose(moved["shoulder.L"], [0.05, front + low * (back - front), 0.8], atol=1e-12)
    np.testing.assert_allclose(moved["shoulder.R"], [-0.05, pack_front + high * (pack_back - pack_front), 0.8],
                               atol=1e-12)
    np.testing.assert_allclose([front, back, pack_front, pack_back], [FRONT, BACK, BACK + 0.05, BACK + 0.15],
                               atol=0.5 * cell + 1e-9)
