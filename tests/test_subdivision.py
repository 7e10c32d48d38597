"""Midpoint subdivision (autorig_addon.core.geometry.subdivision)."""

import numpy as np

from autorig_addon.core.geometry.subdivision import subdivide_midpoints


def test_subdivide_midpoints_keeps_the_shape_and_interpolates():
    vertices = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 2.0, 0.0]])
    triangles = np.array([[0, 1, 2], [1, 3, 2]])
    values = np.array([[0.0], [1.0], [2.0], [3.0]])  # = x / 2 + y, linear
    new_vertices, new_triangles, new_values = subdivide_midpoints(vertices, triangles, values)
    assert len(new_vertices) == 4 + 5 and len(new_triangles) == 8  # five edges, four children each
    np.testing.assert_array_equal(new_vertices[:4], vertices)
    # The five midpoints, one per edge in sorted edge order (0,1) (0,2) (1,2) (1,3) (2,3).
    np.testing.assert_allclose(new_vertices[4:], [[1, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0], [1, 2, 0]])
    np.testing.assert_allclose(new_values[:, 0], new_vertices[:, 0] / 2 + new_vertices[:, 1])
    a, b, c = (new_vertices[new_triangles[:, k]] for k in range(3))
    normals = np.cross(b - a, c - a)
    # Each child is a quarter of its parent (area 2): area 0.5, so |cross| = 1, facing +z like the parent.
    np.testing.assert_allclose(normals[:, 2], 1.0)
    np.testing.assert_allclose(normals[:, :2], 0.0)


def test_subdividing_one_triangle_names_its_children():
    # Corners 0, 1, 2; midpoints 3 = (0,1), 4 = (0,2), 5 = (1,2) in sorted edge
    # order. Corner children first, then the middle one, all counter-clockwise.
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    _, triangles, values = subdivide_midpoints(vertices, [[0, 1, 2]], np.eye(3))
    np.testing.assert_array_equal(triangles, [[0, 3, 4], [3, 1, 5], [4, 5, 2], [3, 5, 4]])
    np.testing.assert_allclose(values[3:], [[0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]])
