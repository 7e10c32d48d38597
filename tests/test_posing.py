"""Posing and linear blend skinning (autorig_addon.core.skeleton.posing).

The last test checks the skinning against Blender's own Armature modifier;
the others need no Blender.
"""

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.skeleton.posing import (
    MIN_DEFORMING_TOTAL_WEIGHT,
    axis_angle_matrices,
    linear_blend_skinning,
    pose_matrices,
    posed_vertices,
    random_poses,
)
from autorig_addon.core.types import Skeleton

QUARTER_TURN_Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
#: Blender stores positions as float32: 2.5 units apart from the origin they
#: are spaced 2.4e-7, so posed positions agree to a few of those.
BLENDER_POSITION_TOLERANCE = 1e-6


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


def quarter_turn_of_first_of_two():
    """Matrices of :func:`two_root_skeleton` with 'turning' a quarter turn about z."""
    rotations = identity_pose(2)
    rotations[0] = QUARTER_TURN_Z
    return pose_matrices(two_root_skeleton(), rotations)


# --- rotations and pose matrices ---------------------------------------------


def test_axis_angle_quarter_turn_about_z():
    rotation = axis_angle_matrices([[0.0, 0.0, 1.0]], [np.pi / 2])[0]
    np.testing.assert_allclose(rotation, QUARTER_TURN_Z, atol=1e-12)


def test_axis_angle_third_of_a_turn_about_the_diagonal_permutes_the_axes():
    # 120 degrees about (1, 1, 1) / sqrt(3) sends x -> y -> z -> x.
    rotation = axis_angle_matrices([np.ones(3) / np.sqrt(3.0)], [2.0 * np.pi / 3.0])[0]
    np.testing.assert_allclose(rotation, [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], atol=1e-12)


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
    # Pose 0 is the rest pose; in pose 1 bone 0 turns a quarter about the
    # origin, carrying (2, 0, 0) on bone 2 to (0, 2, 0).
    rotations = np.stack([identity_pose(3), identity_pose(3)])
    rotations[1, 0] = QUARTER_TURN_Z
    matrices = pose_matrices(chain_skeleton(), rotations)
    np.testing.assert_allclose(matrices[0], np.broadcast_to(np.eye(4), (3, 4, 4)), atol=1e-12)
    np.testing.assert_allclose(matrices[1, 2] @ [2.0, 0.0, 0.0, 1.0], [0.0, 2.0, 0.0, 1.0], atol=1e-12)


def test_non_deform_bones_are_left_out_of_poses():
    # The middle bone is a control bone: 2 deform bones remain, and bone 2
    # hangs directly under bone 0, so turning bone 0 carries (2,0,0) to (0,2,0).
    skeleton = chain_skeleton(deform=[True, False, True])
    rotations = identity_pose(2)
    rotations[0] = QUARTER_TURN_Z
    matrices = pose_matrices(skeleton, rotations)
    np.testing.assert_allclose(matrices[1] @ [2.0, 0.0, 0.0, 1.0], [0.0, 2.0, 0.0, 1.0], atol=1e-12)
    with pytest.raises(InputError, match=r"one 3x3 rotation per deform bone \(2\), got an array of shape \(3, 3, 3\)"):
        pose_matrices(skeleton, identity_pose(3))


# --- random poses --------------------------------------------------------------


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
    np.testing.assert_allclose(poses @ np.swapaxes(poses, -1, -2), np.broadcast_to(np.eye(3), (50, 10, 3, 3)),
                               atol=1e-12)
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
    # 3 deform bones of 4; round(0.3 * 3) = 1 bone turns per pose.
    poses = random_poses(chain_skeleton(4, deform=[True, False, True, True]), count=2)
    assert poses.shape == (2, 3, 3, 3)
    turned = ~np.all(np.isclose(poses, np.eye(3), atol=1e-15), axis=(2, 3))
    np.testing.assert_array_equal(turned.sum(axis=1), [1, 1])


def test_random_poses_reject_bad_arguments():
    with pytest.raises(InputError, match="The number of poses must not be negative, got -1"):
        random_poses(chain_skeleton(), count=-1)
    with pytest.raises(InputError, match=r"The share of posed bones must lie in \[0, 1\], got 1.5"):
        random_poses(chain_skeleton(), fraction=1.5)


# --- linear blend skinning: Blender's Armature modifier -------------------------


def test_lbs_half_half_gives_midpoint():
    # Vertex (1,0,0): the turning bone sends it to (0,1,0), the still bone
    # leaves it at (1,0,0); half of each is (0.5, 0.5, 0). Vertex (0,0,3)
    # wholly on the turning bone lies on its axis and stays.
    posed = linear_blend_skinning([[1.0, 0.0, 0.0], [0.0, 0.0, 3.0]], [[0.5, 0.5], [1.0, 0.0]],
                                  quarter_turn_of_first_of_two())
    np.testing.assert_allclose(posed, [[0.5, 0.5, 0.0], [0.0, 0.0, 3.0]], atol=1e-12)


def test_lbs_divides_by_the_total_weight():
    # (0.25, 0.25) totals 0.5: (0.25 (0,1,0) + 0.25 (1,0,0)) / 0.5 = (0.5, 0.5, 0),
    # exactly where (0.5, 0.5) puts it. A lone weight of 0.3 on the turning
    # bone moves the vertex as fully as 1.0 does: to (0, 1, 0); weights
    # (3, 1) total 4: (3 (0,1,0) + (1,0,0)) / 4 = (0.25, 0.75, 0).
    vertices = np.array([[1.0, 0.0, 0.0]] * 4)
    weights = [[0.25, 0.25], [0.5, 0.5], [0.3, 0.0], [3.0, 1.0]]
    posed = linear_blend_skinning(vertices, weights, quarter_turn_of_first_of_two())
    np.testing.assert_allclose(posed, [[0.5, 0.5, 0.0], [0.5, 0.5, 0.0], [0.0, 1.0, 0.0], [0.25, 0.75, 0.0]],
                               atol=1e-12)


def test_lbs_leaves_vertices_without_weight_at_rest():
    # All zeros: the vertex stays at (1, 0, 0) (it would collapse onto the
    # origin without the division). Weights totalling exactly the bound,
    # 5e-5 + 5e-5 = 1e-4, stay too, as in Blender; twice that moves like (0.5, 0.5).
    assert MIN_DEFORMING_TOTAL_WEIGHT == 1e-4
    vertices = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    weights = [[0.0, 0.0], [5e-5, 5e-5], [1e-4, 1e-4]]
    posed = linear_blend_skinning(vertices, weights, quarter_turn_of_first_of_two())
    np.testing.assert_allclose(posed, [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.5, 0.0]], atol=1e-12)


def test_lbs_rejects_mismatched_weights():
    with pytest.raises(InputError, match=r"Weights of shape \(2, 3\) do not fit 2 vertices and 2 bones"):
        linear_blend_skinning(np.zeros((2, 3)), np.ones((2, 3)), np.broadcast_to(np.eye(4), (2, 4, 4)))


def test_posed_vertices_one_mesh_per_pose():
    # Pose 0 the rest pose, pose 1 the quarter turn: vertex (1,0,0) half on
    # each bone stays in pose 0 and goes to (0.5, 0.5, 0) in pose 1.
    skeleton = two_root_skeleton()
    poses = np.stack([identity_pose(2), identity_pose(2)])
    poses[1, 0] = QUARTER_TURN_Z
    posed = posed_vertices([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], [[0.5, 0.5], [1.0, 0.0]], skeleton, poses)
    np.testing.assert_allclose(posed, [[[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], [[0.5, 0.5, 0.0], [0.0, 2.0, 0.0]]],
                               atol=1e-12)


def test_lbs_agrees_with_blenders_armature_modifier(clean_scene):
    """A 4-bone armature with a branch, 30 vertices with random weights, one
    row (0.25, 0.25, 0, 0) that does not sum to one, one lone 0.3, one vertex
    with no weight, 3 random poses: Blender's evaluated mesh and ours agree
    to float32 precision."""
    import bpy
    import mathutils

    heads = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [0.3, 0.1, 1.9]])
    tails = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [0.0, 0.2, 2.8], [0.9, 0.3, 2.0]])
    skeleton = Skeleton(heads, [-1, 0, 1, 1], ("root", "spine", "neck", "arm"), tails)
    armature_data = bpy.data.armatures.new("Rig")
    armature = bpy.data.objects.new("Rig", armature_data)
    clean_scene.collection.objects.link(armature)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    for name, head, tail, parent in zip(skeleton.names, heads, tails, skeleton.parents):
        bone = armature_data.edit_bones.new(name)
        bone.head, bone.tail = head.tolist(), tail.tolist()
        if parent >= 0:
            bone.parent = armature_data.edit_bones[skeleton.names[parent]]
    bpy.ops.object.mode_set(mode="OBJECT")

    rng = np.random.default_rng(1)
    vertices = rng.uniform([-0.5, -0.5, 0.0], [0.5, 0.5, 2.5], size=(30, 3))
    weights = rng.random((30, 4)) * (rng.random((30, 4)) < 0.6)
    weights[0] = [0.25, 0.25, 0.0, 0.0]
    weights[1] = 0.0
    weights[2] = [0.0, 0.0, 0.3, 0.0]
    mesh = bpy.data.meshes.new("Points")
    mesh.from_pydata(vertices.tolist(), [], [])
    points = bpy.data.objects.new("Points", mesh)
    clean_scene.collection.objects.link(points)
    for column, name in enumerate(skeleton.names):
        group = points.vertex_groups.new(name=name)
        for vertex in np.flatnonzero(weights[:, column] > 0.0):
            group.add([int(vertex)], float(weights[vertex, column]), "REPLACE")
    points.modifiers.new("Armature", "ARMATURE").object = armature
    # Blender keeps positions and weights in float32: compare with those.
    stored_vertices = vertices.astype(np.float32).astype(np.float64)
    stored_weights = weights.astype(np.float32).astype(np.float64)

    for pose in random_poses(skeleton, count=3, seed=5, fraction=0.75, sigma_degrees=40.0):
        for name, rotation in zip(skeleton.names, pose):
            # Our rotations use the armature's axes, Blender's the bone's own.
            rest = np.array(armature_data.bones[name].matrix_local)[:3, :3]
            pose_bone = armature.pose.bones[name]
            pose_bone.rotation_mode = "QUATERNION"
            pose_bone.rotation_quaternion = mathutils.Matrix((rest.T @ rotation @ rest).tolist()).to_quaternion()
        bpy.context.view_layer.update()
        evaluated = points.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
        blender = np.array([vertex.co[:] for vertex in evaluated.vertices])
        ours = linear_blend_skinning(stored_vertices, stored_weights, pose_matrices(skeleton, pose))
        np.testing.assert_allclose(blender, ours, rtol=0.0, atol=BLENDER_POSITION_TOLERANCE)
        # The unweighted vertex has not moved; the unnormalised one has.
        np.testing.assert_allclose(blender[1], stored_vertices[1], rtol=0.0, atol=BLENDER_POSITION_TOLERANCE)
        assert np.linalg.norm(blender[0] - stored_vertices[0]) > 1e-3
