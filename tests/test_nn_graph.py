"""Edge indices of the graph networks (core/nn/graph.py), each checked
against a small graph whose edges were listed by hand."""

import numpy as np
import pytest

from autorig_addon.core.nn.graph import (
    geodesic_ball_edges,
    hierarchy_edges,
    mesh_edges,
    vertex_bone_edges,
    with_self_loops,
)

# Two triangles sharing the edge 0-2: undirected edges 01, 02, 03, 12, 23.
TWO_TRIANGLES = np.array([[0, 1, 2], [0, 2, 3]])


def zigzag_strip(vertex_count):
    """Vertex k at (3k, 4 * (k % 2), 0), triangles (k, k+1, k+2): edges k-(k+1)
    are 5 long (3-4-5 triangle), edges k-(k+2) 6 long, so the edge-path
    distance between k and k+d is 5, 6, 11, 12, 17, ... for d = 1, 2, 3, 4, 5."""
    vertices = np.array([[3.0 * k, 4.0 * (k % 2), 0.0] for k in range(vertex_count)])
    faces = np.array([[k, k + 1, k + 2] for k in range(vertex_count - 2)])
    return vertices, faces


def test_mesh_edges_of_two_triangles_are_each_edge_both_ways_sorted_by_receiver():
    edges = mesh_edges(TWO_TRIANGLES, 4)
    assert edges.dtype == np.int64
    assert edges.tolist() == [[1, 2, 3, 0, 2, 0, 1, 3, 0, 2],
                              [0, 0, 0, 1, 1, 2, 2, 2, 3, 3]]


def test_mesh_edges_with_self_loops_and_an_unused_vertex():
    edges = mesh_edges(TWO_TRIANGLES, 5, self_loops=True)
    assert edges.tolist() == [[0, 1, 2, 3, 0, 1, 2, 0, 1, 2, 3, 0, 2, 3, 4],
                              [0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 4]]


def test_mesh_edges_reject_a_triangle_outside_the_vertices():
    with pytest.raises(ValueError, match=r"outside 0\.\.2"):
        mesh_edges(TWO_TRIANGLES, 3)


def test_self_loops_are_added_once():
    edges = with_self_loops(np.array([[1, 0, 2], [0, 0, 1]]), 3)
    assert edges.tolist() == [[0, 1, 1, 2, 2], [0, 0, 1, 1, 2]]


def test_geodesic_ball_on_a_strip_holds_the_vertices_within_the_radius_along_edges():
    vertices, faces = zigzag_strip(6)
    # Radius 6: neighbours at offsets 1 (distance 5) and 2 (distance 6, exactly on the radius).
    edges, distances = geodesic_ball_edges(vertices, faces, 6.0)
    assert edges.tolist() == [[1, 2, 0, 2, 3, 0, 1, 3, 4, 1, 2, 4, 5, 2, 3, 5, 3, 4],
                              [0, 0, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 5, 5]]
    assert distances.tolist() == [5, 6, 5, 5, 6, 6, 5, 5, 6, 6, 5, 5, 6, 6, 5, 5, 6, 5]
    # Radius 11.5 reaches offset 3 (5 + 6 = 11) but not 4 (12).
    edges, distances = geodesic_ball_edges(vertices, faces, 11.5)
    assert edges[0][edges[1] == 0].tolist() == [1, 2, 3]
    assert distances[edges[1] == 0].tolist() == [5, 6, 11]
    assert edges[0][edges[1] == 3].tolist() == [0, 1, 2, 4, 5]
    assert distances[edges[1] == 3].tolist() == [11, 6, 5, 5, 6]


def test_geodesic_ball_keeps_the_nearest_neighbours_and_adds_self_loops():
    vertices, faces = zigzag_strip(6)
    edges, distances = geodesic_ball_edges(vertices, faces, 11.5, max_neighbours=2, self_loops=True)
    by_receiver = {i: (edges[0][edges[1] == i].tolist(), distances[edges[1] == i].tolist()) for i in range(6)}
    assert by_receiver[0] == ([0, 1, 2], [0, 5, 6])
    assert by_receiver[3] == ([2, 3, 4], [5, 0, 5])  # two at 5, the ones at 6 and 11 dropped
    assert by_receiver[5] == ([3, 4, 5], [6, 5, 0])


def test_geodesic_ball_does_not_depend_on_the_batch_size():
    rng = np.random.default_rng(3)
    vertices, faces = zigzag_strip(40)
    vertices = vertices + rng.normal(scale=0.3, size=vertices.shape)
    expected = geodesic_ball_edges(vertices, faces, 14.0)
    for batch in (1, 7, 1000):
        edges, distances = geodesic_ball_edges(vertices, faces, 14.0, sources_per_batch=batch)
        np.testing.assert_array_equal(edges, expected[0])
        np.testing.assert_array_equal(distances, expected[1])


def test_geodesic_ball_stays_on_its_own_part():
    # Two separate triangles 1 unit apart in space: no ball crosses the gap.
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1]], float)
    edges, _ = geodesic_ball_edges(vertices, [[0, 1, 2], [3, 4, 5]], 10.0)
    assert np.all((edges[0] < 3) == (edges[1] < 3))
    assert edges.shape == (2, 12)


def test_each_vertex_gets_its_k_nearest_bones_nearest_first():
    distances = np.array([[3.0, 1.0, 2.0],
                          [0.5, 0.5, 4.0],
                          [9.0, 8.0, 7.0]])
    edges, edge_distances = vertex_bone_edges(distances, 2)
    assert edges.tolist() == [[0, 0, 1, 1, 2, 2], [1, 2, 0, 1, 2, 1]]
    assert edge_distances.tolist() == [1.0, 2.0, 0.5, 0.5, 7.0, 8.0]
    # More candidates than bones: every bone, still nearest first.
    edges, edge_distances = vertex_bone_edges(distances, 5)
    assert edges.tolist() == [[0, 0, 0, 1, 1, 1, 2, 2, 2], [1, 2, 0, 0, 1, 2, 2, 1, 0]]
    with pytest.raises(ValueError, match="at least 1"):
        vertex_bone_edges(distances, 0)


def test_hierarchy_edges_of_a_chain_with_a_branch():
    # 0 -> 1 -> 2 -> 3 and a branch 1 -> 4.
    edges = hierarchy_edges([-1, 0, 1, 2, 1])
    assert edges.tolist() == [[0, 1, 2, 1, 1, 2, 3, 4],
                              [1, 2, 3, 4, 0, 1, 2, 1]]


def test_hierarchy_edges_take_any_order_and_several_roots():
    # Joint 1 is a root with children 0 and 2; joint 3 is a second root.
    assert hierarchy_edges([1, -1, 1, -1]).tolist() == [[1, 1, 0, 2], [0, 2, 1, 1]]
    with pytest.raises(ValueError, match="does not exist"):
        hierarchy_edges([-1, 5])
