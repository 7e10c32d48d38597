"""Mesh operators of core/geometry (normals, laplacian, topology, weld,
smoothing) against answers worked by hand."""

import numpy as np
import pytest
import scipy.sparse as sp

from autorig_addon.core.geometry.laplacian import AREA_GUARD, cotangent_laplacian, voronoi_mass
from autorig_addon.core.geometry.normals import triangle_double_areas, triangle_normals, vertex_normals
from autorig_addon.core.geometry.smoothing import smooth_over_edges
from autorig_addon.core.geometry.topology import (
    adjacency_matrix,
    connected_component_labels,
    edges,
    non_manifold_edge_count,
)
from autorig_addon.core.geometry.weld import (
    WELD_FRACTION,
    seam_tolerance,
    weld_mesh,
    weld_objects,
    weld_seams,
    weld_vertices,
)
from autorig_addon.core.types import Mesh, Weights
from geometry_fixtures import box_mesh, cylinder, grid

#: The unit right triangle: right angle at vertex 0, 45 degrees at 1 and 2.
RIGHT_TRIANGLE = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])


# --------------------------------------------------------------------------- normals


def test_triangle_areas_and_normals_by_hand():
    V = np.vstack([RIGHT_TRIANGLE, [[2, 0, 0]]])
    F = np.array([[0, 1, 2], [0, 2, 1], [0, 1, 3]])  # counter-clockwise, flipped, collinear
    np.testing.assert_allclose(triangle_double_areas(V, F), [1.0, 1.0, 0.0])
    np.testing.assert_allclose(triangle_normals(V, F), [[0, 0, 1], [0, 0, -1], [0, 0, 0]])


def test_vertex_normals_of_a_closed_cylinder_are_radial_on_the_side_and_axial_at_the_caps():
    # Each side vertex away from the caps lies in 3 triangles of the facet on
    # either side of it (the quads' diagonals alternate), so the area-weighted
    # mean of the two facet normals is exactly radial.
    segments, rings = 24, 21
    mesh = cylinder(segments=segments, rings=rings, capped=True)
    N = vertex_normals(mesh.vertices, mesh.triangles)
    side = np.arange(segments, (rings - 1) * segments)  # every ring but the two next to the caps
    radial = mesh.vertices[side] * np.array([1, 1, 0])
    np.testing.assert_allclose(N[side], radial / np.linalg.norm(radial, axis=1, keepdims=True), atol=1e-12)
    np.testing.assert_allclose(N[-2:], [[0, 0, -1], [0, 0, 1]], atol=1e-12)  # the two cap centres


def test_vertex_in_no_triangle_has_a_zero_normal():
    V = np.vstack([RIGHT_TRIANGLE, [[5, 5, 5]]])
    np.testing.assert_allclose(vertex_normals(V, np.array([[0, 1, 2]])), [[0, 0, 1]] * 3 + [[0, 0, 0]])


# --------------------------------------------------------------------------- laplacian


def test_right_triangle_cotangent_weights_by_hand():
    # cot(90) = 0 opposite edge 1-2; cot(45) = 1 opposite edges 0-1 and 0-2.
    L = cotangent_laplacian(RIGHT_TRIANGLE, np.array([[0, 1, 2]])).toarray()
    np.testing.assert_allclose(L, [[-1.0, 0.5, 0.5], [0.5, -0.5, 0.0], [0.5, 0.0, -0.5]], atol=1e-12)


def test_equilateral_triangle_weights_are_half_cot_60():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]])
    L = cotangent_laplacian(V, np.array([[0, 1, 2]])).toarray()
    w = 0.5 / np.sqrt(3)
    np.testing.assert_allclose(L, [[-2 * w, w, w], [w, -2 * w, w], [w, w, -2 * w]], atol=1e-12)


def test_laplacian_rows_sum_to_zero_and_is_symmetric_negative_semidefinite():
    mesh = cylinder()
    L = cotangent_laplacian(mesh.vertices, mesh.triangles)
    np.testing.assert_allclose(np.asarray(L.sum(axis=1)).ravel(), 0.0, atol=1e-10)
    assert abs(L - L.T).max() == 0.0
    # Negative semi-definite with exactly one zero eigenvalue (one connected part).
    eigenvalues = np.linalg.eigvalsh(L.toarray())
    assert eigenvalues.max() == pytest.approx(0.0, abs=1e-10)
    assert eigenvalues[-2] < -1e-3


def test_laplacian_of_linear_function_vanishes_inside_flat_grid():
    mesh = grid(6, 6)
    L = cotangent_laplacian(mesh.vertices, mesh.triangles)
    f = 2.0 * mesh.vertices[:, 0] - 3.0 * mesh.vertices[:, 1]
    interior = np.all((mesh.vertices[:, :2] > 1e-9) & (mesh.vertices[:, :2] < 1 - 1e-9), axis=1)
    np.testing.assert_allclose((L @ f)[interior], 0.0, atol=1e-12)


def test_voronoi_mass_of_a_regular_grid_is_each_vertex_dual_cell():
    # Unit squares: the dual cell is 1 inside, 1/2 on an edge, 1/4 at a corner.
    mesh = grid(3, 3, size=2.0)
    np.testing.assert_allclose(voronoi_mass(mesh.vertices, mesh.triangles),
                               [0.25, 0.5, 0.25, 0.5, 1.0, 0.5, 0.25, 0.5, 0.25])


def test_voronoi_mass_of_a_right_and_an_obtuse_triangle():
    # Right triangle: 1/8 (1 cot 45 + 1 cot 45) = 1/4 at the right angle,
    # 1/8 (2 cot 90 + 1 cot 45) = 1/8 at each 45 degree corner.
    np.testing.assert_allclose(voronoi_mass(RIGHT_TRIANGLE, np.array([[0, 1, 2]])), [0.25, 0.125, 0.125])
    # Obtuse at vertex 2 (area 0.6): half to the obtuse corner, a quarter to each other.
    V = np.array([[0.0, 0, 0], [4, 0, 0], [2, 0.3, 0]])
    np.testing.assert_allclose(voronoi_mass(V, np.array([[0, 1, 2]])), [0.15, 0.15, 0.3])


def test_degenerate_triangles_give_the_guarded_finite_operators():
    # Collinear corners: the cross product is floored at AREA_GUARD (|a|^2 + |b|^2),
    # so cot(180) at vertex 1 is -1 / (2 AREA_GUARD), cot(0) at 0 is 2 / (5 AREA_GUARD)
    # and at 2 also 2 / (5 AREA_GUARD); the area (and so the mass) is zero.
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    F = np.array([[0, 1, 2]])
    L = cotangent_laplacian(V, F).toarray()
    cot_end, cot_middle = 2 / (5 * AREA_GUARD), -1 / (2 * AREA_GUARD)
    np.testing.assert_allclose([L[0, 2], L[0, 1], L[1, 2]], [0.5 * cot_middle, 0.5 * cot_end, 0.5 * cot_end],
                               rtol=1e-12)
    np.testing.assert_allclose(L.sum(axis=1), 0.0, atol=1e-12 * np.abs(L).max())
    np.testing.assert_array_equal(voronoi_mass(V, F), [0.0, 0.0, 0.0])
    # Two coincident corners: the angle between them is read as 90 degrees (cot 0).
    V = np.vstack([RIGHT_TRIANGLE, [[1, 0, 0]]])
    L = cotangent_laplacian(V, np.array([[1, 3, 2]])).toarray()
    np.testing.assert_allclose(L[[1, 1, 3], [2, 3, 2]], [0.0, 0.5 * 2 / (4 * AREA_GUARD), 0.0], rtol=1e-12)
    np.testing.assert_array_equal(voronoi_mass(V, np.array([[1, 3, 2]])), [0.0, 0.0, 0.0, 0.0])


# --------------------------------------------------------------------------- topology


def test_edges_adjacency_and_parts_of_a_quad_and_a_loose_vertex():
    # grid(2, 2): vertices (0,0) (0,1) (1,0) (1,1), triangles [0 2 3] and [0 3 1].
    quad = grid(2, 2)
    np.testing.assert_array_equal(edges(quad.triangles), [[0, 1], [0, 2], [0, 3], [1, 3], [2, 3]])
    adjacency = adjacency_matrix(quad.triangles, 5)
    assert sp.issparse(adjacency)
    np.testing.assert_array_equal(
        adjacency.toarray(),
        [[0, 1, 1, 1, 0], [1, 0, 0, 1, 0], [1, 0, 0, 1, 0], [1, 1, 1, 0, 0], [0, 0, 0, 0, 0]],
    )
    labels = connected_component_labels(quad.triangles, 5)
    assert len(set(labels[:4])) == 1 and labels[4] != labels[0]


def test_a_closed_surface_has_three_halves_of_an_edge_per_triangle():
    mesh = cylinder(segments=24, rings=21, capped=True)
    # V - E + F = 2 for a sphere-like surface.
    assert len(edges(mesh.triangles)) == 3 * len(mesh.triangles) // 2
    assert mesh.vertex_count - len(edges(mesh.triangles)) + len(mesh.triangles) == 2
    assert non_manifold_edge_count(mesh.triangles) == 0


def test_non_manifold_edges_are_those_in_three_or_more_triangles():
    quad = grid(2, 2).triangles  # diagonal 0-3 in two triangles
    fins = np.vstack([quad, [[0, 3, 4], [0, 3, 5], [1, 3, 6]]])  # two more on 0-3, one more on 1-3
    assert non_manifold_edge_count(quad) == 0
    assert non_manifold_edge_count(fins) == 1
    assert non_manifold_edge_count(np.vstack([fins, [[1, 3, 7]]])) == 2


# --------------------------------------------------------------------------- weld


def test_weld_joins_seam_copies_and_components_follow():
    mesh = grid(3, 3)
    # Split the grid into two triangle soups by duplicating every vertex of the second half.
    F = mesh.triangles.copy()
    half = len(F) // 2
    V = np.vstack([mesh.vertices, mesh.vertices])
    F[half:] += mesh.vertex_count
    assert len(np.unique(connected_component_labels(F, len(V))[np.unique(F)])) == 2
    welded_V, welded_F, to_welded = weld_vertices(V, F, 1e-9)
    assert len(welded_V) == 9
    np.testing.assert_allclose(welded_V[to_welded], V)
    # The welded triangles are the grid's own, renumbered.
    np.testing.assert_array_equal(np.sort(to_welded[mesh.triangles].ravel()), np.sort(welded_F.ravel()))
    assert len(np.unique(connected_component_labels(welded_F, len(welded_V)))) == 1


def test_weld_tolerance_is_inclusive_and_collapsed_triangles_are_dropped():
    # Coordinates exact in binary, so the distances are exactly 0.125 and 0.25.
    V = np.array([[0.0, 0, 0], [4, 0, 0], [0, 4, 0], [4.125, 0, 0], [4.375, 0, 0]])
    F = np.array([[0, 1, 2], [1, 3, 2], [0, 4, 2]])
    welded_V, welded_F, to_welded = weld_vertices(V, F, 0.25)
    # 1 and 3 are 0.125 apart; 4 is exactly the tolerance from 3 and joins
    # through it (chains merge) at their mean; triangle [1 3 2] collapses.
    np.testing.assert_array_equal(to_welded, [0, 1, 2, 1, 1])
    np.testing.assert_allclose(welded_V, [[0, 0, 0], [12.5 / 3, 0, 0], [0, 4, 0]])
    np.testing.assert_array_equal(welded_F, [[0, 1, 2], [0, 1, 2]])
    _, _, apart = weld_vertices(V, F, 0.1)
    np.testing.assert_array_equal(apart, [0, 1, 2, 3, 4])


def test_weld_mesh_uses_a_millionth_of_the_diagonal():
    mesh = Mesh(np.vstack([RIGHT_TRIANGLE, [[1 + 1e-7, 0, 0]], [[0, 1 + 3e-6, 0]]]), [[0, 1, 2], [0, 3, 4]],
                object_names=("shirt",))
    assert WELD_FRACTION == 1e-6
    assert seam_tolerance(mesh) == pytest.approx(WELD_FRACTION * np.hypot(1 + 1e-7, 1 + 3e-6), rel=1e-12)
    welded, to_welded = weld_mesh(mesh)
    # 1e-7 apart welds, 3e-6 apart (above 1.4e-6) does not.
    np.testing.assert_array_equal(to_welded, [0, 1, 2, 1, 3])
    assert welded.object_names == ("shirt",)
    np.testing.assert_array_equal(welded.triangles, [[0, 1, 2], [0, 1, 3]])


def test_weld_seams_averages_the_weights_of_copies():
    mesh = Mesh(np.vstack([RIGHT_TRIANGLE, RIGHT_TRIANGLE[1:]]), [[0, 1, 2], [0, 3, 4]])
    weights = Weights(np.array([[1.0, 0], [0.2, 0.8], [0, 1], [0.6, 0.4], [0, 1]]), ("a", "b"))
    welded, welded_weights = weld_seams(mesh, weights)
    assert welded.vertex_count == 3
    np.testing.assert_allclose(welded_weights.matrix, [[1.0, 0.0], [0.4, 0.6], [0.0, 1.0]])
    assert welded_weights.bone_names == ("a", "b")


def test_weld_objects_welds_each_object_alone():
    # Two objects that touch at vertex (1, 0, 0): copies inside each object
    # weld, copies across objects do not.
    first = Mesh(np.vstack([RIGHT_TRIANGLE, RIGHT_TRIANGLE[:1]]), [[0, 1, 2], [3, 2, 1]], object_names=("a",))
    second = Mesh(RIGHT_TRIANGLE + [1, 0, 0], [[0, 1, 2]], object_names=("b",))
    parts, to_welded = weld_objects(Mesh.concatenate([first, second]))
    assert [part.object_names for part in parts] == [("a",), ("b",)]
    assert [part.vertex_count for part in parts] == [3, 3]
    np.testing.assert_array_equal(to_welded, [0, 1, 2, 0, 3, 4, 5])


# --------------------------------------------------------------------------- smoothing


def test_one_smoothing_pass_by_hand():
    # grid(2, 2): vertex 0 has neighbours 1, 2, 3; vertices 1 and 2 have 0 and 3.
    quad = grid(2, 2)
    values = np.array([[1.0], [0.0], [0.0], [0.0]])
    smoothed = smooth_over_edges(values, quad.triangles, iterations=1, strength=0.5)
    np.testing.assert_allclose(smoothed.ravel(), [0.5, 0.25, 0.25, 1 / 6])
    only_first = smooth_over_edges(values, quad.triangles, iterations=1, strength=0.5,
                                   rows=np.array([True, False, False, False]))
    np.testing.assert_allclose(only_first.ravel(), [0.5, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(values.ravel(), [1, 0, 0, 0])  # the input is left alone


def test_smoothing_keeps_loose_vertices_and_zero_passes_change_nothing():
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]], [[0, 1, 2]])
    values = np.array([[1.0], [0.0], [0.0], [7.0]])
    np.testing.assert_allclose(smooth_over_edges(values, mesh.triangles, 1, 0.5).ravel(), [0.5, 0.25, 0.25, 7.0])
    np.testing.assert_array_equal(smooth_over_edges(values, mesh.triangles, 0, 0.5), values)


def test_smoothing_a_welded_box_converges_to_the_degree_weighted_mean():
    # The box's six faces share no vertex until welded: 26 vertices, 72 edges.
    box = box_mesh([0, 0, 0], [1, 1, 1], 0.5)
    welded_V, welded_F, _ = weld_vertices(box.vertices, box.triangles, 1e-9)
    assert len(welded_V) == 26 and len(edges(welded_F)) == 72
    # A pass is a lazy random walk; its limit from a spike at vertex 0 is
    # deg(0) / sum(deg) everywhere (the walk's stationary distribution).
    values = np.zeros((26, 1))
    values[0] = 1.0
    degree = np.asarray(adjacency_matrix(welded_F, 26).sum(axis=1)).ravel()
    smoothed = smooth_over_edges(values, welded_F, iterations=400, strength=0.5)
    np.testing.assert_allclose(smoothed.ravel(), degree[0] / degree.sum(), rtol=1e-9)
    assert degree.sum() == 2 * 72
