import numpy as np
import pytest
import scipy.sparse as sp

from autorig_addon.core.errors import InputError
from autorig_addon.core.geometry.bounding_box import bounding_box_diagonal, character_size, checked_size, largest_side
from autorig_addon.core.types import Mesh, Skeleton, Weights
from autorig_addon.core.weights import (
    empty_rows,
    invalid_rows,
    limit_influences,
    mix_weights,
    normalize_rows,
    prune_small,
    sharpened,
    usable_rows,
)


def test_skeleton_default_tails_follow_children_and_extend_leaves():
    skeleton = Skeleton(joints=[[0, 0, 0], [0, 0, 1], [0, 0, 3]], parents=[-1, 0, 1], names=("a", "b", "c"))
    np.testing.assert_allclose(skeleton.tails, [[0, 0, 1], [0, 0, 3], [0, 0, 4]])
    np.testing.assert_allclose(skeleton.bone_lengths, [1, 2, 1])


def test_lone_root_tails_point_up_a_tenth_of_the_joints_extent():
    # Two unrelated roots 5 apart (bounding-box diagonal of the joints):
    # each leaf root gets a tail 0.1 * 5 = 0.5 above its head.
    skeleton = Skeleton(joints=[[0, 0, 0], [3, 4, 0]], parents=[-1, -1], names=("a", "b"))
    np.testing.assert_allclose(skeleton.tails, [[0, 0, 0.5], [3, 4, 0.5]])


def test_skeleton_rejects_children_before_parents_and_duplicate_names():
    with pytest.raises(ValueError, match=r"parents must come before their children \(parents\[j\] < j\)"):
        Skeleton(joints=np.zeros((2, 3)), parents=[1, -1], names=("a", "b"))
    with pytest.raises(InputError, match="Bone names must be unique"):
        Skeleton(joints=np.zeros((2, 3)), parents=[-1, 0], names=("a", "a"))
    with pytest.raises(ValueError, match="joints, parents and names must have one entry per joint"):
        Skeleton(joints=np.zeros((2, 3)), parents=[-1], names=("a", "b"))


def test_deform_subset_relinks_to_the_nearest_deforming_ancestor():
    skeleton = Skeleton(joints=np.arange(12.0).reshape(4, 3), parents=[-1, 0, 1, 2], names=("root", "ik", "b", "c"),
                        deform=[True, False, True, True])
    subset = skeleton.deform_subset()
    assert subset.names == ("root", "b", "c")
    np.testing.assert_array_equal(subset.parents, [-1, 0, 1])


def test_mesh_concatenate_shifts_indices_and_records_objects():
    a = Mesh(np.zeros((3, 3)), [[0, 1, 2]], object_names=("a",))
    b = Mesh(np.ones((4, 3)), [[0, 1, 2], [1, 2, 3]], object_names=("b",))
    both = Mesh.concatenate([a, b])
    np.testing.assert_array_equal(both.triangles, [[0, 1, 2], [3, 4, 5], [4, 5, 6]])
    assert both.object_names == ("a", "b")
    assert both.object_slice(1) == slice(3, 7)
    np.testing.assert_array_equal(both.object_offsets, [0, 3, 7])
    with pytest.raises(InputError, match="A triangle refers to a vertex that does not exist"):
        Mesh(np.zeros((2, 3)), [[0, 1, 2]])


def test_bounding_box_diagonal_of_a_mesh_and_of_points():
    # Box from (0,0,0) to (3,4,12): diagonal sqrt(9 + 16 + 144) = 13.
    points = [[0.0, 0.0, 0.0], [3.0, 4.0, 0.0], [1.0, 1.0, 12.0]]
    assert bounding_box_diagonal(points) == pytest.approx(13.0)
    assert Mesh(points, [[0, 1, 2]]).bounding_box_diagonal == pytest.approx(13.0)
    assert character_size(points) == pytest.approx(13.0)
    assert bounding_box_diagonal(np.zeros((0, 3))) == 0.0
    assert Mesh(np.zeros((0, 3)), np.zeros((0, 3), int)).bounding_box_diagonal == 0.0


def test_largest_side_of_points():
    # The same box, 3 x 4 x 12: its largest side is 12 whichever axis holds it.
    points = np.array([[0.0, 0.0, 0.0], [3.0, 4.0, 0.0], [1.0, 1.0, 12.0]])
    assert largest_side(points) == 12.0
    assert largest_side(points[:, [2, 0, 1]] - 7.0) == 12.0
    assert largest_side(np.zeros((0, 3))) == 0.0
    assert largest_side(np.ones((4, 3))) == 0.0


def test_character_size_must_be_positive():
    with pytest.raises(InputError, match="The mesh has no vertices, so it has no size to measure errors against"):
        character_size(np.zeros((0, 3)))
    with pytest.raises(InputError, match="All vertices lie at one point, so the mesh has no size"):
        character_size(np.ones((4, 3)))
    assert checked_size(2) == 2.0
    for bad in (0.0, -1.0, float("inf"), float("nan")):
        with pytest.raises(InputError, match=f"The character size must be a positive length, got {bad}"):
            checked_size(bad)


def test_weights_select_bones_and_sparse_round_trip():
    weights = Weights(np.array([[0.2, 0.8], [1.0, 0.0]]), ("a", "b"))
    picked = weights.select_bones(["b", "missing", "a"])
    np.testing.assert_array_equal(picked.matrix, [[0.8, 0, 0.2], [0, 0, 1.0]])
    again = Weights.from_sparse(sp.csr_matrix(weights.matrix), weights.bone_names)
    np.testing.assert_array_equal(again.matrix, weights.matrix)
    assert weights.to_sparse().nnz == 3
    with pytest.raises(ValueError, match=r"matrix must be \(vertices, bones\) with one column per bone name"):
        Weights(np.ones((2, 3)), ("a", "b"))


def test_normalize_clamps_nan_and_negative_and_keeps_empty_rows_empty():
    raw = np.array([[2.0, 2.0, -1.0], [np.nan, 1.0, 3.0], [0.0, 0.0, 0.0]])
    out = normalize_rows(raw)
    np.testing.assert_allclose(out, [[0.5, 0.5, 0], [0, 0.25, 0.75], [0, 0, 0]])
    np.testing.assert_array_equal(empty_rows(out), [False, False, True])


def test_limit_influences_keeps_the_largest_and_renormalises():
    raw = np.array([[0.1, 0.4, 0.3, 0.2], [0.2, 0.3, 0.5, 0.0]])
    out = limit_influences(raw, 2)
    np.testing.assert_allclose(out, [[0, 4 / 7, 3 / 7, 0], [0, 3 / 8, 5 / 8, 0]], atol=1e-12)
    np.testing.assert_allclose(limit_influences(raw, 0), normalize_rows(raw))


def test_prune_small_drops_negligible_entries():
    out = prune_small(np.array([[1.0, 5e-5, 0.0], [0.0, 0.0, 0.0]]))
    np.testing.assert_allclose(out, [[1, 0, 0], [0, 0, 0]])


def test_sharpened_narrows_a_blend_and_keeps_zeros_and_empty_rows():
    raw = np.array([[0.8, 0.2, 0.0], [0.5, 0.5, 0.0], [0.0, 0.0, 0.0]])
    # 0.8 ** 2 = 0.64 and 0.2 ** 2 = 0.04: the blend narrows from 80/20 to 94/6.
    np.testing.assert_allclose(sharpened(raw, 2.0), [[0.64 / 0.68, 0.04 / 0.68, 0], [0.5, 0.5, 0], [0, 0, 0]])
    np.testing.assert_allclose(sharpened(raw * 3.0, 1.0), raw)
    with pytest.raises(ValueError, match="positive, got 0"):
        sharpened(raw, 0.0)


def test_mix_changes_only_the_chosen_columns():
    existing = np.array([[0.5, 0.5, 0.0]])
    incoming = np.array([[0.0, 0.0, 1.0]])
    np.testing.assert_allclose(mix_weights(existing, incoming, 0.5, [2]), [[1 / 3, 1 / 3, 1 / 3]])
    np.testing.assert_allclose(mix_weights(existing, incoming, 0.5), [[0.25, 0.25, 0.5]])
    np.testing.assert_allclose(mix_weights(existing, incoming, 0.0, [2]), existing)
    with pytest.raises(InputError, match=r"Mix factor must lie in \[0, 1\], got 1.5"):
        mix_weights(existing, incoming, 1.5)
    with pytest.raises(ValueError, match="existing and incoming weights must have the same shape"):
        mix_weights(existing, incoming[:, :2], 0.5)


def test_rows_with_nan_infinite_or_negative_weights_are_invalid_and_empty_ones_unusable():
    weights = np.array([[0.5, 0.5], [np.nan, 1.0], [np.inf, 0.0], [1.0, -0.5], [0.0, 0.0], [5e-5, 5e-5], [0.0, 0.2]])
    np.testing.assert_array_equal(invalid_rows(weights), [False, True, True, True, False, False, False])
    np.testing.assert_array_equal(usable_rows(weights), [True, False, False, False, False, False, True])
