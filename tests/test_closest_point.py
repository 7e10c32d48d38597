"""Closest points on triangles and triangle meshes (core/geometry/closest_point)."""

import numpy as np

from autorig_addon.core.geometry.closest_point import TriangleMeshQuery, closest_points_on_triangles
from autorig_addon.core.geometry.segments import point_segment_distances
from geometry_fixtures import cylinder, grid


def test_closest_point_regions_of_one_triangle():
    A, B, C = np.array([0.0, 0, 0]), np.array([1.0, 0, 0]), np.array([0.0, 1, 0])
    P = np.array([
        [0.2, 0.2, 1.0],    # above the interior
        [-1.0, -1.0, 0.0],  # beyond vertex A
        [0.5, -2.0, 0.0],   # beyond edge AB
        [2.0, 2.0, 0.0],    # beyond edge BC
        [3.0, -0.5, 0.0],   # beyond vertex B
    ])
    n = len(P)
    points, bary = closest_points_on_triangles(P, np.tile(A, (n, 1)), np.tile(B, (n, 1)), np.tile(C, (n, 1)))
    expected = np.array([[0.2, 0.2, 0], [0, 0, 0], [0.5, 0, 0], [0.5, 0.5, 0], [1, 0, 0]])
    np.testing.assert_allclose(points, expected, atol=1e-12)
    np.testing.assert_allclose(bary.sum(axis=1), 1.0)
    np.testing.assert_allclose(bary[0], [0.6, 0.2, 0.2], atol=1e-12)


def test_surface_point_beats_nearest_vertex_on_coarse_mesh():
    # Two big triangles: the nearest vertex is far, the surface point is right below.
    mesh = grid(2, 2, size=10.0)
    query = TriangleMeshQuery(mesh.vertices, mesh.triangles)
    result = query.closest(np.array([[5.0, 5.0, 0.3], [2.0, 7.0, -0.1]]))
    np.testing.assert_allclose(result.distances, [0.3, 0.1], atol=1e-12)
    np.testing.assert_allclose(result.points, [[5, 5, 0], [2, 7, 0]], atol=1e-12)


def test_distances_to_a_faceted_cylinder_are_those_to_its_polygon():
    # The side of the cylinder is a prism over a 64-gon: from a point beside
    # it (within its height) the closest point is level with it, at the
    # distance to the polygon in the point's horizontal plane.
    segments = 64
    mesh = cylinder(radius=0.1, segments=segments, capped=False)
    query = TriangleMeshQuery(mesh.vertices, mesh.triangles)
    rng = np.random.default_rng(1)
    angle, z = rng.uniform(0, 2 * np.pi, 200), rng.uniform(0.1, 0.9, 200)
    P = np.column_stack([0.13 * np.cos(angle), 0.13 * np.sin(angle), z])
    result = query.closest(P)
    corners = mesh.vertices[:segments] * [1, 1, 0]
    polygon = point_segment_distances(P * [1, 1, 0], corners, np.roll(corners, -1, axis=0)).min(axis=1)
    np.testing.assert_allclose(result.distances, polygon, atol=1e-12)
    np.testing.assert_allclose(result.points[:, 2], z, atol=1e-12)
    np.testing.assert_allclose(result.interpolate(mesh.triangles, mesh.vertices[:, 2]), z, atol=1e-12)
    # The facets lie inside the circle by at most r (1 - cos(pi / 64)).
    assert 0.03 - 1e-12 <= polygon.min() and polygon.max() <= 0.03 + 0.1 * (1 - np.cos(np.pi / segments)) + 1e-12


def test_brute_force_agreement_on_random_points():
    mesh = cylinder(radius=0.2, segments=12, rings=6)
    query = TriangleMeshQuery(mesh.vertices, mesh.triangles)
    P = np.random.default_rng(2).uniform(-0.5, 1.5, size=(300, 3))
    result = query.closest(P)
    F = mesh.triangles
    q, m = len(P), len(F)
    points, _ = closest_points_on_triangles(
        np.repeat(P, m, axis=0), *(np.tile(mesh.vertices[F[:, k]], (q, 1)) for k in range(3)))
    brute = np.linalg.norm(points - np.repeat(P, m, axis=0), axis=1).reshape(q, m).min(axis=1)
    np.testing.assert_allclose(result.distances, brute, atol=1e-12)


def test_closest_points_on_a_triangle_cover_every_region():
    a, b, c = np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    points = np.array([[0.2, 0.2, 1.0], [-1.0, -1.0, 0.0], [2.0, -1.0, 0.0], [-0.5, 3.0, 0.0], [0.5, -1.0, 0.0],
                       [-1.0, 0.5, 0.0], [1.0, 1.0, 0.0]])
    expected = np.array([[0.6, 0.2, 0.2], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5],
                         [0.0, 0.5, 0.5]])
    count = len(points)
    _, bary = closest_points_on_triangles(points, np.tile(a, (count, 1)), np.tile(b, (count, 1)),
                                          np.tile(c, (count, 1)))
    np.testing.assert_allclose(bary, expected, atol=1e-12)


def test_batches_and_empty_queries(monkeypatch):
    from autorig_addon.core.geometry import closest_point

    mesh = cylinder(radius=0.2, segments=12, rings=6)
    query = TriangleMeshQuery(mesh.vertices, mesh.triangles)
    P = np.random.default_rng(4).uniform(-0.5, 1.5, size=(50, 3))
    whole = query.closest(P)
    monkeypatch.setattr(closest_point, "BATCH_SIZE", 7)
    batched = query.closest(P)
    for name in ("points", "distances", "triangles", "barycentric"):
        np.testing.assert_array_equal(getattr(batched, name), getattr(whole, name))
    empty = query.closest(np.zeros((0, 3)))
    assert empty.points.shape == (0, 3) and empty.distances.shape == (0,) and empty.triangles.dtype == np.int64


def brute_force_distances(mesh, P):
    F = mesh.triangles
    q, m = len(P), len(F)
    points, _ = closest_points_on_triangles(
        np.repeat(P, m, axis=0), *(np.tile(mesh.vertices[F[:, k]], (q, 1)) for k in range(3)))
    return np.linalg.norm(points - np.repeat(P, m, axis=0), axis=1).reshape(q, m).min(axis=1)


def test_a_triangle_soup_finds_the_same_closest_points():
    # Every triangle with its own corners, as some exporters write a body:
    # candidates found twice (by centroid and by corner) are tested once.
    mesh = cylinder(radius=0.2, segments=12, rings=6)
    soup = mesh.vertices[mesh.triangles.ravel()]
    soup_triangles = np.arange(len(soup)).reshape(-1, 3)
    query = TriangleMeshQuery(soup, soup_triangles)
    P = np.random.default_rng(5).uniform(-0.5, 1.5, size=(300, 3))
    result = query.closest(P)
    np.testing.assert_allclose(result.distances, brute_force_distances(mesh, P), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(result.points - P, axis=1), result.distances, atol=1e-12)


def test_surely_farther_never_rules_out_a_point_within_the_distance():
    mesh = cylinder(radius=0.2, segments=12, rings=6)
    query = TriangleMeshQuery(mesh.vertices, mesh.triangles)
    P = np.random.default_rng(6).uniform(-3.0, 4.0, size=(2000, 3))
    exact = brute_force_distances(mesh, P)
    limits = np.where(np.arange(len(P)) % 2 == 0, 0.3, 1.0)  # two distances, as the unit check queries
    farther = query.surely_farther(P, limits)
    assert not (farther & (exact <= limits)).any()
    # It is a useful test: points far beyond the longest edge are ruled out.
    longest = max(np.linalg.norm(mesh.vertices[mesh.triangles[:, k]] - mesh.vertices[mesh.triangles[:, (k + 1) % 3]],
                                 axis=1).max() for k in range(3))
    clearly = exact > limits + 2 * longest
    assert clearly.sum() > 500 and farther[clearly].all()


def test_a_point_over_a_shared_edge_goes_to_the_triangle_with_the_nearest_centroid():
    # Two triangles of a soup meet along x; the query lies over their edge,
    # at the same distance from both. The small triangle, listed second, is
    # the one it lies nearer to: its normal is the one a faceted body shows there.
    V = np.array([[1.0, 0, 0], [0, 0, 0], [0.5, -2, 0], [0, 0, 0], [1.0, 0, 0], [0.5, 0.2, 0]])
    F = np.array([[0, 1, 2], [3, 4, 5]])
    result = TriangleMeshQuery(V, F).closest(np.array([[0.5, 0.0, 0.1], [0.3, 0.0, -0.2]]))
    np.testing.assert_allclose(result.distances, [0.1, 0.2], atol=1e-12)
    np.testing.assert_array_equal(result.triangles, [1, 1])
