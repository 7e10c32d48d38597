"""The skinning networks' inputs (core/skinning/learned/features.py) on
hand-made characters whose every feature is worked out by hand."""

import numpy as np
import pytest

from autorig_addon.core.skinning.learned.features import (
    BONE_FEATURES,
    CANDIDATE_BONES,
    DISTANCE_FLOOR,
    PAIR_FEATURES,
    PRIOR_FLOOR,
    VERTEX_FEATURES,
    SkinGraph,
    candidate_targets,
    skin_graph,
)
from autorig_addon.core.types import Mesh, Skeleton
from geometry_fixtures import grid, small_humanoid

F = DISTANCE_FLOOR


def chain_character():
    """A two-bone chain up z (0-1, 1-2) under a non-deform root, a triangle
    in the plane x = 1 (normal +x) and a vertex in no triangle above the
    chain's top; distances and prior given by hand.

    Vertex 0 is nearer bone 0, vertex 1 nearer bone 1, vertex 2 ties (the
    lower index first), vertex 3 is nearer bone 1.
    """
    vertices = [[1.0, 0, 0.5], [1, 1, 0.5], [1, 0, 1.5], [0, 0, 3]]
    mesh = Mesh(vertices, [[0, 1, 2]])
    skeleton = Skeleton([[0.0, 0, -1], [0, 0, 0], [0, 0, 1]], [-1, 0, 1], ("root", "lower", "upper"),
                        [[0.0, 0, 0], [0, 0, 1], [0, 0, 2]], [False, True, True])
    distances = np.array([[1.0, 1.5], [2.0, 1.5], [1.2, 1.2], [2.5, 1.0]])
    prior = np.array([[0.8, 0.2], [0.3, 0.7], [0.5, 0.5], [0.0, 1.0]])
    return mesh, skeleton, distances, prior


def pair_row(head, tail, closest, through, straight, nearest, rank, along, leaf, prior, cosine):
    """One row of pair features for a bone of length 1."""
    return [*head, *tail, *closest, through, straight, np.log((through + F) / (straight + F)),
            np.log((through + F) / (nearest + F)), rank / (CANDIDATE_BONES - 1), along, 1.0, leaf, prior,
            np.log(prior + PRIOR_FLOOR), cosine]


def test_candidates_are_nearest_first_ties_to_the_lower_bone_and_missing_slots_invalid():
    graph = skin_graph(*chain_character())
    assert graph.candidates.tolist() == [[0, 1, 0, 0, 0], [1, 0, 0, 0, 0], [0, 1, 0, 0, 0], [1, 0, 0, 0, 0]]
    assert graph.valid.tolist() == [[True, True, False, False, False]] * 4
    np.testing.assert_allclose(graph.prior, [[0.8, 0.2, 0, 0, 0], [0.7, 0.3, 0, 0, 0], [0.5, 0.5, 0, 0, 0],
                                             [1, 0, 0, 0, 0]], atol=1e-7)
    assert graph.vertex_count == 4 and graph.bone_count == 2


def test_pair_features_by_hand():
    graph = skin_graph(*chain_character())
    assert graph.pair_features.shape == (4, CANDIDATE_BONES, PAIR_FEATURES)
    assert graph.pair_features.dtype == np.float32
    r = np.sqrt(1.25)  # from a point 1 off the axis to a bone end 0.5 along it
    expected = [
        # Vertex 0 (1, 0, 0.5), normal +x: bone 0 beside it (halfway), bone 1 above (before its head).
        [pair_row([-1, 0, -0.5], [-1, 0, 0.5], [-1, 0, 0], 1.0, 1.0, 1.0, 0, 0.5, 0, 0.8, -1),
         pair_row([-1, 0, 0.5], [-1, 0, 1.5], [-1, 0, 0.5], 1.5, r, 1.0, 1, 0.0, 1, 0.2, -1 / r)],
        # Vertex 1 (1, 1, 0.5): bone 1 first by distance, then bone 0.
        [pair_row([-1, -1, 0.5], [-1, -1, 1.5], [-1, -1, 0.5], 1.5, 1.5, 1.5, 0, 0.0, 1, 0.7, -1 / 1.5),
         pair_row([-1, -1, -0.5], [-1, -1, 0.5], [-1, -1, 0], 2.0, np.sqrt(2), 1.5, 1, 0.5, 0, 0.3,
                  -1 / np.sqrt(2))],
        # Vertex 2 (1, 0, 1.5): beyond bone 0's tail, beside bone 1.
        [pair_row([-1, 0, -1.5], [-1, 0, -0.5], [-1, 0, -0.5], 1.2, r, 1.2, 0, 1.0, 0, 0.5, -1 / r),
         pair_row([-1, 0, -0.5], [-1, 0, 0.5], [-1, 0, 0], 1.2, 1.0, 1.2, 1, 0.5, 1, 0.5, -1)],
        # Vertex 3 (0, 0, 3), in no triangle (normal 0, cosine 0): beyond both tails.
        [pair_row([0, 0, -2], [0, 0, -1], [0, 0, -1], 1.0, 1.0, 1.0, 0, 1.0, 1, 1.0, 0),
         pair_row([0, 0, -3], [0, 0, -2], [0, 0, -2], 2.5, 2.0, 1.0, 1, 1.0, 0, 0.0, 0)],
    ]
    np.testing.assert_allclose(graph.pair_features[:, :2], expected, atol=1e-6)
    # Missing candidates are all zero.
    assert not graph.pair_features[:, 2:].any()


def test_vertex_and_bone_features_and_edges_by_hand():
    graph = skin_graph(*chain_character())
    assert graph.vertex_features.shape == (4, VERTEX_FEATURES)
    np.testing.assert_allclose(graph.vertex_features, [[1, 0, 0.5, 1, 0, 0], [1, 1, 0.5, 1, 0, 0],
                                                       [1, 0, 1.5, 1, 0, 0], [0, 0, 3, 0, 0, 0]])
    # Only the deform bones: the root is gone, so 'lower' is a root of depth 0.
    # Head, tail, direction, length, leaf, depth / deepest, children.
    np.testing.assert_allclose(graph.bone_features, [[0, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1],
                                                     [0, 0, 1, 0, 0, 2, 0, 0, 1, 1, 1, 1, 0]])
    # One-ring and self loops by receiver then sender; the lone vertex has its loop only.
    assert graph.mesh_edges.tolist() == [[0, 1, 2, 0, 1, 2, 0, 1, 2, 3], [0, 0, 0, 1, 1, 1, 2, 2, 2, 3]]
    # The triangle's sides (1 and more) are longer than the ball radius: self loops only.
    assert graph.ball_edges.tolist() == [[0, 1, 2, 3], [0, 1, 2, 3]]
    assert graph.bone_edges.tolist() == [[0, 1, 0, 1], [0, 0, 1, 1]]


def test_bone_features_of_a_branching_skeleton_without_its_chest():
    # small_humanoid with the chest not deforming: head and both arms hang off the hips.
    full = small_humanoid()
    skeleton = Skeleton(full.joints, full.parents, full.names, full.tails,
                        [True, False, True, True, True, True, True, True, True])
    mesh = grid(3, 3)
    graph = skin_graph(mesh, skeleton, np.random.default_rng(0).uniform(0.1, 1, (9, 8)), np.full((9, 8), 1 / 8))
    assert graph.bone_features.shape == (8, BONE_FEATURES)
    # Bones: hips, head, arm L, forearm L, arm R, forearm R, shin L, shin R.
    leaf, depth, children = graph.bone_features[:, 10], graph.bone_features[:, 11], graph.bone_features[:, 12]
    assert leaf.tolist() == [0, 1, 0, 1, 0, 1, 1, 1]
    np.testing.assert_allclose(depth, [0, 0.5, 0.5, 1, 0.5, 1, 0.5, 0.5])
    assert children.tolist() == [5, 0, 1, 0, 1, 0, 0, 0]
    kept = [0, 2, 3, 4, 5, 6, 7, 8]
    np.testing.assert_allclose(graph.bone_features[:, 9], full.bone_lengths[kept], rtol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(graph.bone_features[:, 6:9], axis=1), 1, rtol=1e-6)
    # Every vertex has all 5 candidates: the rank column runs 0, 1/4, ..., 1.
    assert graph.valid.all()
    np.testing.assert_allclose(graph.pair_features[0, :, 13], [0, 0.25, 0.5, 0.75, 1])


def test_candidate_targets_renormalise_over_the_candidates():
    graph = skin_graph(*chain_character())
    weights = np.array([[0.6, 0.2], [0.5, 0.5], [0.0, 0.0], [0.0, 1.0]])
    # Rows follow each vertex's candidate order; the unweighted vertex stays 0.
    np.testing.assert_allclose(candidate_targets(graph, weights), [[0.75, 0.25, 0, 0, 0], [0.5, 0.5, 0, 0, 0],
                                                                   [0, 0, 0, 0, 0], [1, 0, 0, 0, 0]], atol=1e-7)


def test_candidate_targets_leave_out_weight_on_bones_that_are_not_candidates():
    # Seven bones in a row; vertex 0's candidates are bones 0-4, vertex 1's bones 2-6.
    skeleton = Skeleton(np.column_stack([np.zeros(7), np.zeros(7), np.arange(7.0)]), [-1, 0, 1, 2, 3, 4, 5],
                        tuple(f"b{k}" for k in range(7)))
    mesh = Mesh([[0.1, 0, 0], [0.1, 0, 6], [0.2, 0, 6]], [[0, 1, 2]])
    distances = np.array([np.arange(7.0), np.arange(7.0)[::-1], np.arange(7.0)[::-1]])
    graph = skin_graph(mesh, skeleton, distances, np.full((3, 7), 1 / 7))
    assert graph.candidates.tolist() == [[0, 1, 2, 3, 4], [6, 5, 4, 3, 2], [6, 5, 4, 3, 2]]
    weights = np.array([[0.2, 0, 0, 0, 0.2, 0.6, 0], [1.0, 0, 0, 0, 0, 0, 0], [0, 0, 0.1, 0, 0, 0, 0.3]])
    # 0.6 on bone 5 is not a candidate of vertex 0; vertex 1's only bone is not one either.
    np.testing.assert_allclose(candidate_targets(graph, weights), [[0.5, 0, 0, 0, 0.5], [0, 0, 0, 0, 0],
                                                                   [0.75, 0, 0, 0, 0.25]], atol=1e-7)


def test_graph_arrays_round_trip_through_npz(tmp_path):
    graph = skin_graph(*chain_character())
    np.savez(tmp_path / "graph.npz", **graph.arrays())
    with np.load(tmp_path / "graph.npz") as data:
        loaded = SkinGraph.from_arrays(data)
    for name, array in graph.arrays().items():
        stored = getattr(loaded, name)
        assert stored.dtype == array.dtype and np.array_equal(stored, array), name


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_dtypes_of_the_graph(dtype):
    mesh, skeleton, distances, prior = chain_character()
    graph = skin_graph(mesh, skeleton, distances.astype(dtype), prior.astype(dtype))
    assert {graph.vertex_features.dtype, graph.pair_features.dtype, graph.prior.dtype,
            graph.bone_features.dtype} == {np.dtype(np.float32)}
    assert {graph.candidates.dtype, graph.mesh_edges.dtype, graph.ball_edges.dtype,
            graph.bone_edges.dtype} == {np.dtype(np.int64)}
    assert graph.valid.dtype == bool
