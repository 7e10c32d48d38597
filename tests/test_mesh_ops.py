import numpy as np
import pytest

from autorig_addon.core.geometry.mesh_ops import (
    connected_component_labels,
    cotangent_laplacian,
    edges,
    vertex_normals,
    voronoi_mass,
    weld_vertices,
)
from geometry_fixtures import cylinder, grid


def test_laplacian_rows_sum_to_zero_and_is_symmetric_negative_semidefinite():
    mesh = cylinder()
    L = cotangent_laplacian(mesh.vertices, mesh.triangles)
    assert np.abs(np.asarray(L.sum(axis=1))).max() < 1e-10
    assert abs(L - L.T).max() < 1e-12
    x = np.random.default_rng(0).normal(size=mesh.vertex_count)
    assert x @ (L @ x) <= 1e-12


def test_laplacian_of_linear_function_vanishes_inside_flat_grid():
    mesh = grid(6, 6)
    L = cotangent_laplacian(mesh.vertices, mesh.triangles)
    f = 2.0 * mesh.vertices[:, 0] - 3.0 * mesh.vertices[:, 1]
    interior = np.all((mesh.vertices[:, :2] > 1e-9) & (mesh.vertices[:, :2] < 1 - 1e-9), axis=1)
    assert np.abs((L @ f)[interior]).max() < 1e-10


def test_right_triangle_cotangent_weights_by_hand():
    # Right angle at vertex 0: cot(90) = 0, the 45-degree corners have cot = 1.
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    L = cotangent_laplacian(V, np.array([[0, 1, 2]])).toarray()
    assert L[1, 2] == pytest.approx(0.0, abs=1e-12)  # opposite the right angle
    assert L[0, 1] == pytest.approx(0.5)
    assert L[0, 2] == pytest.approx(0.5)
    assert L[0, 0] == pytest.approx(-1.0)


def test_voronoi_mass_sums_to_surface_area():
    mesh = grid(7, 5, size=2.0)
    assert voronoi_mass(mesh.vertices, mesh.triangles).sum() == pytest.approx(4.0)
    # An obtuse triangle still splits its area exactly.
    V = np.array([[0.0, 0, 0], [4, 0, 0], [2, 0.3, 0]])
    mass = voronoi_mass(V, np.array([[0, 1, 2]]))
    assert mass.sum() == pytest.approx(0.6)
    assert mass[2] == pytest.approx(0.3)  # obtuse corner takes half


def test_degenerate_triangles_give_finite_operators():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 0, 0]])
    F = np.array([[0, 1, 2], [0, 1, 3], [1, 4, 3]])  # collinear and zero-area triangles
    assert np.all(np.isfinite(cotangent_laplacian(V, F).toarray()))
    assert np.all(np.isfinite(voronoi_mass(V, F)))
    assert np.all(voronoi_mass(V, F) >= 0)


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
    assert len(np.unique(connected_component_labels(welded_F, len(welded_V)))) == 1
    np.testing.assert_allclose(welded_V[to_welded], V)


def test_vertex_normals_of_closed_cylinder_point_outwards():
    mesh = cylinder(capped=True)
    N = vertex_normals(mesh.vertices, mesh.triangles)
    side = np.abs(mesh.vertices[:, 2] - 0.5) < 0.4
    radial = mesh.vertices[side] * np.array([1, 1, 0])
    cosine = np.einsum("ij,ij->i", N[side], radial / np.linalg.norm(radial, axis=1, keepdims=True))
    assert cosine.min() > 0.99
    assert len(edges(mesh.triangles)) == 3 * len(mesh.triangles) // 2  # closed: each edge in two triangles


def test_smoothing_moves_only_the_chosen_rows():
    from autorig_addon.core.geometry.mesh_ops import smooth_over_edges

    mesh = grid(2, 2)  # one quad, two triangles
    values = np.array([[1.0], [0.0], [0.0], [0.0]])
    smoothed = smooth_over_edges(values, mesh.triangles, iterations=1, strength=0.5, rows=np.array([True, False, False, False]))
    assert smoothed[0, 0] == pytest.approx(0.5)  # half its own value, half its neighbours' mean (0)
    np.testing.assert_array_equal(smoothed[1:], values[1:])
    all_rows = smooth_over_edges(values, mesh.triangles, iterations=1, strength=0.5)
    assert all_rows[1:].sum() > 0  # without a mask the neighbours take some of vertex 0's value
