import numpy as np
import pytest

from autorig_addon.core.evaluation.deformation import (
    axis_angle_matrices,
    character_size,
    deformation_error,
    edge_stretch,
    linear_blend_skinning,
    pose_matrices,
    posed_edge_stretch,
    random_poses,
    unique_edges,
)
from autorig_addon.core.errors import InputError
from autorig_addon.core.types import Skeleton, Weights

QUARTER_TURN_Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def chain_skeleton(count=3, deform=None):
    """Joints at (k, 0, 0), each the child of the previous."""
    joints = np.zeros((count, 3))
    joints[:, 0] = np.arange(count)
    return Skeleton(joints, np.arange(count) - 1, tuple(f"bone{k}" for k in range(count)), deform=deform)


def two_root_skeleton():
    """Two unrelated roots: one at the origin, one at (5, 0, 0)."""
    return Skeleton([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]], [-1, -1], ("turning", "still"))


def identity_pose(bone_count):
    return np.broadcast_to(np.eye(3), (bone_count, 3, 3)).copy()


def test_axis_angle_quarter_turn_about_z():
    rotation = axis_angle_matrices([[0.0, 0.0, 1.0]], [np.pi / 2])[0]
    np.testing.assert_allclose(rotation, QUARTER_TURN_Z, atol=1e-12)


def test_rest_pose_gives_identity_matrices():
    matrices = pose_matrices(chain_skeleton(), identity_pose(3))
    np.testing.assert_allclose(matrices, np.broadcast_to(np.eye(4), (3, 4, 4)), atol=1e-12)


def test_bone_turns_about_its_head():
    # A root bone with head at (1, 0, 0) turned half a turn about z sends
    # (2, 0, 0) to (0, 0, 0) and keeps its head in place.
    skeleton = Skeleton([[1.0, 0.0, 0.0]], [-1], ("only",))
    half_turn = axis_angle_matrices([[0.0, 0.0, 1.0]], [np.pi])
    matrix = pose_matrices(skeleton, half_turn)[0]
    np.testing.assert_allclose(matrix @ [2.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(matrix @ [1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], atol=1e-12)


def test_rotations_compose_down_the_chain():
    # Bones at x = 0, 1, 2; bones 0 and 1 each a quarter turn about z.
    # (2,0,0) under bone 1: about (1,0,0) -> (1,1,0); then bone 0 about the
    # origin -> (-1,1,0). Bone 2 (unrotated) follows: its head (2,0,0) also
    # lands at (-1,1,0), and as the chain has turned by half a turn in all,
    # (3,0,0) one unit further along -x, at (-2,1,0).
    rotations = identity_pose(3)
    rotations[0] = rotations[1] = QUARTER_TURN_Z
    matrices = pose_matrices(chain_skeleton(), rotations)
    np.testing.assert_allclose(matrices[1] @ [2.0, 0.0, 0.0, 1.0], [-1.0, 1.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(matrices[2] @ [2.0, 0.0, 0.0, 1.0], [-1.0, 1.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(matrices[2] @ [3.0, 0.0, 0.0, 1.0], [-2.0, 1.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(matrices[0] @ [1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], atol=1e-12)


def test_pose_matrices_keep_leading_pose_axis():
    rotations = np.stack([identity_pose(3), identity_pose(3)])
    rotations[1, 0] = QUARTER_TURN_Z
    matrices = pose_matrices(chain_skeleton(), rotations)
    assert matrices.shape == (2, 3, 4, 4)
    np.testing.assert_allclose(matrices[0], np.broadcast_to(np.eye(4), (3, 4, 4)), atol=1e-12)
    np.testing.assert_allclose(matrices[1, 2] @ [2.0, 0.0, 0.0, 1.0], [0.0, 2.0, 0.0, 1.0], atol=1e-12)


def test_non_deform_bones_are_left_out_of_poses():
    # The middle bone is a control bone: 2 deform bones remain, and bone 2
    # hangs directly under bone 0.
    skeleton = chain_skeleton(deform=[True, False, True])
    rotations = identity_pose(2)
    rotations[0] = QUARTER_TURN_Z
    matrices = pose_matrices(skeleton, rotations)
    assert matrices.shape == (2, 4, 4)
    np.testing.assert_allclose(matrices[1] @ [2.0, 0.0, 0.0, 1.0], [0.0, 2.0, 0.0, 1.0], atol=1e-12)
    with pytest.raises(InputError):
        pose_matrices(skeleton, identity_pose(3))


def test_lbs_half_half_gives_midpoint():
    # Vertex (1,0,0): the turning bone sends it to (0,1,0), the still bone
    # leaves it at (1,0,0); half of each is (0.5, 0.5, 0).
    rotations = identity_pose(2)
    rotations[0] = QUARTER_TURN_Z
    matrices = pose_matrices(two_root_skeleton(), rotations)
    posed = linear_blend_skinning([[1.0, 0.0, 0.0], [0.0, 0.0, 3.0]], [[0.5, 0.5], [1.0, 0.0]], matrices)
    np.testing.assert_allclose(posed, [[0.5, 0.5, 0.0], [0.0, 0.0, 3.0]], atol=1e-12)


def test_lbs_rejects_mismatched_weights():
    with pytest.raises(InputError):
        linear_blend_skinning(np.zeros((2, 3)), np.ones((2, 3)), np.broadcast_to(np.eye(4), (2, 4, 4)))


def test_random_poses_are_reproducible_and_seed_dependent():
    skeleton = chain_skeleton(10)
    first = random_poses(skeleton, count=4, seed=7)
    again = random_poses(skeleton, count=4, seed=7)
    other = random_poses(skeleton, count=4, seed=8)
    np.testing.assert_array_equal(first, again)
    assert not np.allclose(first, other)


def test_random_poses_rotate_thirty_percent_with_proper_rotations():
    skeleton = chain_skeleton(10)
    poses = random_poses(skeleton, count=50, seed=3)
    assert poses.shape == (50, 10, 3, 3)
    np.testing.assert_allclose(poses @ np.swapaxes(poses, -1, -2), np.broadcast_to(np.eye(3), poses.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(poses), 1.0, atol=1e-12)
    turned = ~np.all(np.isclose(poses, np.eye(3), atol=1e-15), axis=(2, 3))
    # 30 % of 10 bones = 3 per pose (an angle of exactly 0 has probability 0).
    np.testing.assert_array_equal(turned.sum(axis=1), 3)


def test_random_pose_angles_have_the_requested_spread():
    # Angle from the trace; the root mean square of N(0, 25 deg) angles is
    # 25 deg. 3 bones x 2000 poses = 6000 samples: standard error ~0.23 deg.
    poses = random_poses(chain_skeleton(10), count=2000, seed=11, sigma_degrees=25.0)
    traces = np.trace(poses, axis1=2, axis2=3)
    turned = traces < 3.0 - 1e-15
    angles = np.degrees(np.arccos(np.clip((traces[turned] - 1.0) / 2.0, -1.0, 1.0)))
    assert abs(np.sqrt(np.mean(angles**2)) - 25.0) < 1.0


def test_random_poses_only_for_deform_bones():
    poses = random_poses(chain_skeleton(4, deform=[True, False, True, True]), count=2)
    assert poses.shape == (2, 3, 3, 3)


def test_character_size_is_bounding_box_diagonal():
    assert character_size([[0.0, 0.0, 0.0], [3.0, 4.0, 0.0], [1.0, 1.0, 12.0]]) == pytest.approx(13.0)
    with pytest.raises(InputError):
        character_size(np.ones((4, 3)))


def test_deformation_error_zero_for_rest_pose_and_equal_weights():
    skeleton = two_root_skeleton()
    vertices = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [3.0, 0.0, 1.0]])
    pred = np.array([[1.0, 0.0], [0.0, 1.0], [0.3, 0.7]])
    ref = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5]])
    rest = deformation_error(vertices, pred, ref, skeleton, identity_pose(2)[None])
    assert rest["mean"] == pytest.approx(0.0, abs=1e-12)
    assert rest["max"] == pytest.approx(0.0, abs=1e-12)
    same = deformation_error(vertices, ref, ref, skeleton, random_poses(skeleton, count=5))
    assert same == {"mean": 0.0, "max": 0.0}


def test_deformation_error_hand_computed():
    # Vertex (2,0,0) fully on the turning bone goes to (0,2,0); fully on the
    # still bone it stays at (2,0,0): distance 2*sqrt(2). Vertex (0,0,0)
    # sits on the rotation axis: distance 0. Size = bbox diagonal = 2.
    # Mean = sqrt(2)*2/2/2 = sqrt(2)/2, max = 2*sqrt(2)/2 = sqrt(2).
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    pose = identity_pose(2)
    pose[0] = QUARTER_TURN_Z
    ref = np.array([[1.0, 0.0], [1.0, 0.0]])
    pred = np.array([[0.0, 1.0], [0.0, 1.0]])
    error = deformation_error(vertices, pred, ref, skeleton, pose[None])
    assert error["mean"] == pytest.approx(np.sqrt(2.0) / 2.0)
    assert error["max"] == pytest.approx(np.sqrt(2.0))
    # Two poses, the second the rest pose: the mean halves, the max stays.
    both = deformation_error(vertices, pred, ref, skeleton, np.stack([pose, identity_pose(2)]))
    assert both["mean"] == pytest.approx(np.sqrt(2.0) / 4.0)
    assert both["max"] == pytest.approx(np.sqrt(2.0))


def test_deformation_error_aligns_named_weights_to_deform_bones():
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    pose = identity_pose(2)
    pose[0] = QUARTER_TURN_Z
    # Columns in the opposite order to the skeleton, plus an unknown bone.
    ref = Weights(np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]]), ("still", "turning", "extra"))
    pred = Weights(np.array([[1.0], [1.0]]), ("still",))
    error = deformation_error(vertices, pred, ref, skeleton, pose[None])
    assert error["max"] == pytest.approx(np.sqrt(2.0))


def test_deformation_error_rejects_wrong_column_count():
    with pytest.raises(InputError):
        deformation_error(np.eye(3), np.ones((3, 3)), np.ones((3, 2)), two_root_skeleton())


def test_unique_edges_of_two_triangles():
    edges = unique_edges([[0, 1, 2], [2, 1, 3]])
    np.testing.assert_array_equal(edges, [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]])


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


def test_rigid_motion_does_not_stretch():
    # Every vertex on one bone: the mesh turns rigidly, edge lengths stay.
    skeleton = chain_skeleton(3)
    rng = np.random.default_rng(0)
    vertices = rng.normal(size=(30, 3))
    triangles = rng.integers(0, 30, size=(40, 3))
    weights = np.zeros((30, 3))
    weights[:, 1] = 1.0
    stretch = posed_edge_stretch(vertices, unique_edges(triangles), weights, skeleton, random_poses(skeleton, count=4))
    assert stretch["max"] < 1e-12


def test_posed_edge_stretch_hand_computed():
    # Vertex 0 at the origin (on the axis), vertex 1 at (1,0,0) half on the
    # turning bone: it goes to (0.5, 0.5, 0), so the edge grows from 1 to
    # sqrt(0.5): stretch 1 - sqrt(0.5).
    skeleton = two_root_skeleton()
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    pose = identity_pose(2)
    pose[0] = QUARTER_TURN_Z
    stretch = posed_edge_stretch(vertices, [[0, 1]], [[1.0, 0.0], [0.5, 0.5]], skeleton, pose[None])
    assert stretch["max"] == pytest.approx(1.0 - np.sqrt(0.5))
