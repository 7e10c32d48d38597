"""Midpoint subdivision of triangle meshes, carrying per-vertex values along."""

from __future__ import annotations

import numpy as np

from .topology import triangle_edges


def subdivide_midpoints(vertices: np.ndarray, triangles: np.ndarray, values: np.ndarray) -> tuple:
    """Split every triangle into four at its edge midpoints.

    The shape does not change (new vertices lie on the old edges); values
    at a midpoint are the mean of the edge's two ends, i.e. linear
    interpolation.

    Parameters
    ----------
    vertices : (n, 3) float64 array
    triangles : (m, 3) int64 array
    values : (n, k) float64 array, per-vertex values (e.g. weights)

    Returns
    -------
    vertices : (n + e, 3) float64 array, the old vertices first, then one
        per edge
    triangles : (4 m, 3) int64 array, same orientation
    values : (n + e, k) float64 array
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    values = np.asarray(values, dtype=np.float64).reshape(len(vertices), -1)
    # triangle_edges lists edges (0, 1), (1, 2), (2, 0) of every triangle in
    # three blocks, so the inverse reshaped to (3, m) names each midpoint.
    edges, edge_of_half = np.unique(triangle_edges(triangles), axis=0, return_inverse=True)
    middle = len(vertices) + edge_of_half.reshape(3, -1)  # middle[k]: midpoint of edge (k, k+1)
    new_vertices = np.vstack([vertices, vertices[edges].mean(axis=1)])
    new_values = np.vstack([values, values[edges].mean(axis=1)])
    a, b, c = triangles.T
    ab, bc, ca = middle
    new_triangles = np.concatenate([
        np.stack([a, ab, ca], axis=1), np.stack([ab, b, bc], axis=1),
        np.stack([ca, bc, c], axis=1), np.stack([ab, bc, ca], axis=1),
    ])
    return new_vertices, new_triangles, new_values
