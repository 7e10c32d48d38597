"""Triangle areas and unit normals of triangle meshes.

Conventions (as in gpytoolbox): ``V`` is an (n, 3) float64 array of
positions, ``F`` an (m, 3) int array of triangles whose corners run
counter-clockwise seen from the side the normal points to.
"""

from __future__ import annotations

import numpy as np


def triangle_area_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m, 3) float64 un-normalised triangle normals, ``(v1 - v0) x (v2 - v0)``.

    Each is as long as twice its triangle's area, so summing them around a
    vertex weights the faces by area.
    """
    return np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])


def triangle_double_areas(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m,) float64: twice the area of each triangle."""
    return np.linalg.norm(triangle_area_normals(V, F), axis=1)


def _unit_rows(vectors: np.ndarray) -> np.ndarray:
    """``vectors`` (k, 3) scaled to unit length; zero rows stay zero."""
    length = np.linalg.norm(vectors, axis=1, keepdims=True)
    return np.divide(vectors, length, out=np.zeros_like(vectors), where=length > 0)


def triangle_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m, 3) float64 unit normals (zero for degenerate triangles)."""
    return _unit_rows(triangle_area_normals(V, F))


def vertex_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(n, 3) float64 area-weighted unit vertex normals (zero where no face)."""
    area_normals = np.repeat(triangle_area_normals(V, F), 3, axis=0)  # one row per corner, as F.ravel()
    corners = np.asarray(F).ravel()
    normals = np.stack([np.bincount(corners, weights=area_normals[:, k], minlength=len(V)) for k in range(3)], axis=1)
    return _unit_rows(normals)
