"""Deformation error and edge stretch (autorig_addon.core.evaluation.deformation / .stretch)."""

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.evaluation.deform_weights import deform_weight_matrix
from autorig_addon.core.evaluation.deformation import deformation_error
from autorig_addon.core.evaluation.stretch import edge_stretch, posed_edge_stretch
from autorig_addon.core.geometry.topology import edges
from autorig_addon.core.skeleton.posing import random_poses
from autorig_addon.core.types import Skeleton, Weights

QUARTER_TURN_Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def chain_skeleton(count=3):
    """Joints at (k, 0, 0), each the child of the previous."""
    joints = np.zeros((count, 3))
    joints[:, 0] = np.arange(count)
    return Skeleton(joints, np.arange(count) - 1, tuple(f"bone{k}" for k in range(count)))


def two_root_skeleton():
    """Two unrelated roots: one at the origin, one at (5, 0, 0)."""
    return Skeleton([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]], [-1, -1], ("turning", "still"))


def identity_pose(bone_count):
    return np.broadcast_to(np.eye(3), (bone_count, 3, 3)).copy()


def quarter_turn_of_first_of_two():
    """One pose of :func:`two_root_skeleton`: 'turning' a quarter turn about z."""
    pose = identity_pose(2)
    pose[0] = QUARTER_TURN_Z
    return pose[None]


# --- deformation error -----------------------------------------------------------


def test_deformation_error_zero_for_rest_pose_and_equal_weights():
    skeleton = two_root_skeleton()
    vertices = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [3.0, 0.0, 1.0]])
    pred = np.array([[1.0, 0.0], [0.0, 1.0], [0.3, 0.7]])
    ref = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5]])
    rest = deformation_error(vertices, pred, ref, skeleton, identity_pose(2)[None])
    assert rest == {"mean": 0.0, "max": 0.0}
    same = deformation_error(vertices, ref, ref, skeleton, random_poses(skeleton, count=5))
    assert same == {"mean": 0.0, "max": 0.0}


def test_deformation_error_hand_computed():
    # Vertex (2,0,0) fully on the turning bone goes to (0,2,0); fully on the
    # still bone it stays at (2,0,0): distance 2*sqrt(2). Vertex (0,0,0)
    # sits on the rotation axis: distance 0. Size = bbox diagonal = 2.
    # Mean = sqrt(2)*2/2/2 = sqrt(2)/2, max = 2*sqrt(2)/2 = sqrt(2).
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    ref = np.array([[1.0, 0.0], [1.0, 0.0]])
    pred = np.array([[0.0, 1.0], [0.0, 1.0]])
    pose = quarter_turn_of_first_of_two()
    error = deformation_error(vertices, pred, ref, skeleton, pose)
    assert error["mean"] == pytest.approx(np.sqrt(2.0) / 2.0)
    assert error["max"] == pytest.approx(np.sqrt(2.0))
    # Two poses, the second the rest pose: the mean halves, the max stays.
    both = deformation_error(vertices, pred, ref, skeleton, np.concatenate([pose, identity_pose(2)[None]]))
    assert both["mean"] == pytest.approx(np.sqrt(2.0) / 4.0)
    assert both["max"] == pytest.approx(np.sqrt(2.0))
    # An explicit size of 4 halves both again.
    halved = deformation_error(vertices, pred, ref, skeleton, pose, size=4.0)
    assert halved["mean"] == pytest.approx(np.sqrt(2.0) / 4.0)
    assert halved["max"] == pytest.approx(np.sqrt(2.0) / 2.0)


def test_deformation_error_ignores_how_rows_are_scaled():
    # Skinning divides by the total weight, as Blender does: (0.25, 0.25)
    # poses the mesh exactly as (0.5, 0.5), and (2, 0) as (1, 0).
    skeleton = two_root_skeleton()
    vertices = np.array([[1.0, 0.0, 0.0], [2.0, 1.0, 0.0]])
    pred = np.array([[0.25, 0.25], [2.0, 0.0]])
    ref = np.array([[0.5, 0.5], [1.0, 0.0]])
    error = deformation_error(vertices, pred, ref, skeleton, quarter_turn_of_first_of_two())
    assert error["mean"] == pytest.approx(0.0, abs=1e-15)
    assert error["max"] == pytest.approx(0.0, abs=1e-15)


def test_unweighted_prediction_stays_at_rest():
    # Vertex (2,0,0): the reference turns it to (0,2,0); without predicted
    # weight it stays at (2,0,0): 2 sqrt(2) apart. Vertex (0,0,0) is on the
    # axis. Size 2: mean 2 sqrt(2) / 2 / 2, max 2 sqrt(2) / 2.
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    pred = np.array([[0.0, 0.0], [1.0, 0.0]])
    ref = np.array([[1.0, 0.0], [1.0, 0.0]])
    error = deformation_error(vertices, pred, ref, skeleton, quarter_turn_of_first_of_two())
    assert error["mean"] == pytest.approx(np.sqrt(2.0) / 2.0)
    assert error["max"] == pytest.approx(np.sqrt(2.0))


def test_deformation_error_aligns_named_weights_to_deform_bones():
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    # Columns in the opposite order to the skeleton, plus an unknown bone.
    ref = Weights(np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]]), ("still", "turning", "extra"))
    pred = Weights(np.array([[1.0], [1.0]]), ("still",))
    error = deformation_error(vertices, pred, ref, skeleton, quarter_turn_of_first_of_two())
    assert error["max"] == pytest.approx(np.sqrt(2.0))


def test_deformation_error_rejects_bad_input():
    with pytest.raises(InputError, match=r"The predicted weights have shape \(3, 3\) but the mesh has 3 vertices "
                                         r"and the skeleton 2 deform bones"):
        deformation_error(np.eye(3), np.ones((3, 3)), np.ones((3, 2)), two_root_skeleton())
    with pytest.raises(InputError, match="The reference weights contain NaN or infinite values"):
        deformation_error(np.eye(3), np.ones((3, 2)), np.full((3, 2), np.nan), two_root_skeleton())
    with pytest.raises(InputError, match="The character size must be a positive length, got 0.0"):
        deformation_error(np.eye(3), np.ones((3, 2)), np.ones((3, 2)), two_root_skeleton(), size=0.0)
    with pytest.raises(InputError, match="All vertices lie at one point"):
        deformation_error(np.ones((3, 3)), np.ones((3, 2)), np.ones((3, 2)), two_root_skeleton())


def test_deform_weight_matrix_picks_deform_columns_by_name():
    skeleton = Skeleton([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], [-1, 0, 1], ("a", "ik", "b"),
                        deform=[True, False, True])
    weights = Weights(np.array([[0.2, 0.5, 0.3]]), ("b", "ik", "other"))
    np.testing.assert_array_equal(deform_weight_matrix(weights, skeleton, 1), [[0.0, 0.2]])


# --- edge stretch ------------------------------------------------------------------


def test_edge_stretch_hand_computed():
    # Rest lengths 1 and 2; posed 1.5 and 2: stretches 0.5 and 0.
    # p99 by linear interpolation: 0 + 0.99 * (0.5 - 0) = 0.495.
    rest = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 2.0, 0.0]])
    posed = np.array([[0.0, 0.0, 0.0], [1.5, 0.0, 0.0], [1.5, 2.0, 0.0]])
    stretch = edge_stretch(rest, [[0, 1], [1, 2]], posed)
    assert stretch["max"] == pytest.approx(0.5)
    assert stretch["p99"] == pytest.approx(0.495)


def test_edge_stretch_counts_shrinking_and_pools_poses():
    rest = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    poses = np.array([rest, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]])
    stretch = edge_stretch(rest, [[0, 1]], poses)
    assert stretch["max"] == pytest.approx(0.5)
    assert stretch["p99"] == pytest.approx(0.495)


def test_edge_stretch_skips_degenerate_edges():
    # Edge (1, 2) has rest length 1e-12, below 1e-9 of the size 1: its
    # 1e12-fold stretch is left out; edge (0, 1) doubles: stretch 1.
    rest = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1e-12, 0.0]])
    posed = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0]])
    assert edge_stretch(rest, [[0, 1], [1, 2]], posed) == {"p99": pytest.approx(1.0), "max": pytest.approx(1.0)}
    assert edge_stretch(rest, [[1, 2]], posed) == {"p99": 0.0, "max": 0.0}
    with pytest.raises(InputError, match="An edge refers to a vertex that does not exist"):
        edge_stretch(rest, [[0, 3]], posed)


def test_rigid_motion_does_not_stretch():
    # Every vertex on one bone: the mesh turns rigidly, edge lengths stay.
    skeleton = chain_skeleton(3)
    rng = np.random.default_rng(0)
    vertices = rng.normal(size=(30, 3))
    triangles = rng.integers(0, 30, size=(40, 3))
    weights = np.zeros((30, 3))
    weights[:, 1] = 1.0
    stretch = posed_edge_stretch(vertices, edges(triangles), weights, skeleton, random_poses(skeleton, count=4))
    assert stretch["max"] < 1e-12


def test_posed_edge_stretch_hand_computed():
    # Vertex 0 at the origin (on the axis), vertex 1 at (1,0,0) half on the
    # turning bone: it goes to (0.5, 0.5, 0), so the edge shrinks from 1 to
    # sqrt(0.5): stretch 1 - sqrt(0.5). Weights (0.1, 0.1) pose it the same.
    skeleton = two_root_skeleton()
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    pose = quarter_turn_of_first_of_two()
    stretch = posed_edge_stretch(vertices, [[0, 1]], [[1.0, 0.0], [0.5, 0.5]], skeleton, pose)
    assert stretch["max"] == pytest.approx(1.0 - np.sqrt(0.5))
    unnormalised = posed_edge_stretch(vertices, [[0, 1]], [[1.0, 0.0], [0.1, 0.1]], skeleton, pose)
    assert unnormalised["max"] == pytest.approx(1.0 - np.sqrt(0.5))
