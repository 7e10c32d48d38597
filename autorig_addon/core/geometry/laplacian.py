"""The cotangent Laplacian and the lumped (mixed Voronoi) mass of a triangle mesh.

Both are built from the cotangents of the triangles' corner angles, so they
share :func:`corner_cotangents`. Conventions (as in gpytoolbox): ``V`` is an
(n, 3) float64 array of positions, ``F`` an (m, 3) int array of triangles;
sparse results are ``scipy.sparse.csr_matrix``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .normals import triangle_double_areas

#: Relative guard on triangle doubled areas: below ``AREA_GUARD * edge_length^2``
#: a triangle counts as degenerate, so cotangents stay finite.
AREA_GUARD = 1e-12


def corner_cotangents(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m, 3) float64: cotangent of the angle at corner k of each triangle.

    Finite even for degenerate triangles (their area is floored at
    :data:`AREA_GUARD` times the squared lengths of the corner's edges).
    """
    cot = np.empty((len(F), 3))
    for k in range(3):
        a = V[F[:, (k + 1) % 3]] - V[F[:, k]]
        b = V[F[:, (k + 2) % 3]] - V[F[:, k]]
        dot = np.einsum("ij,ij->i", a, b)
        cross = np.linalg.norm(np.cross(a, b), axis=1)
        guard = AREA_GUARD * (np.einsum("ij,ij->i", a, a) + np.einsum("ij,ij->i", b, b))
        cot[:, k] = dot / np.maximum(cross, np.maximum(guard, 1e-300))
    return cot


def cotangent_laplacian(V: np.ndarray, F: np.ndarray, cot: np.ndarray | None = None) -> sp.csr_matrix:
    """Cotangent Laplacian ``L`` (n, n), negative semi-definite.

    ``L[i, j] = (cot a_ij + cot b_ij) / 2`` for each edge, diagonal minus the
    row sum, so rows sum to zero and ``-L`` is the Dirichlet energy matrix.
    Degenerate triangles contribute finite (possibly large) entries, never NaN.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    cot : (m, 3) float64 array, :func:`corner_cotangents` when the caller has them

    Returns
    -------
    L : (n, n) scipy.sparse.csr_matrix, symmetric
    """
    n = len(V)
    cot = corner_cotangents(V, F) if cot is None else cot
    # The angle at corner k is opposite the edge between corners k+1 and k+2.
    rows = np.concatenate([F[:, (k + 1) % 3] for k in range(3)])
    cols = np.concatenate([F[:, (k + 2) % 3] for k in range(3)])
    values = 0.5 * np.concatenate([cot[:, k] for k in range(3)])
    diagonal = -(np.bincount(rows, weights=values, minlength=n) + np.bincount(cols, weights=values, minlength=n))
    every = np.arange(n)
    # One conversion sums the duplicate entries of shared edges.
    return sp.coo_matrix(
        (np.concatenate([values, values, diagonal]),
         (np.concatenate([rows, cols, every]), np.concatenate([cols, rows, every]))),
        shape=(n, n),
    ).tocsr()


def voronoi_mass(V: np.ndarray, F: np.ndarray, cot: np.ndarray | None = None) -> np.ndarray:
    """(n,) float64 lumped mass: each vertex's mixed Voronoi area (Meyer et al. 2003).

    Obtuse triangles give half their area to the obtuse corner and a quarter
    to the others. Vertices in no triangle get zero. The masses sum to the
    surface area. ``cot``: :func:`corner_cotangents`, when the caller has them.
    """
    area = 0.5 * triangle_double_areas(V, F)
    cot = corner_cotangents(V, F) if cot is None else cot
    corner_area = np.zeros((len(F), 3))
    for k in range(3):
        e_next = np.sum((V[F[:, (k + 2) % 3]] - V[F[:, k]]) ** 2, axis=1)  # edge k -> k+2
        e_prev = np.sum((V[F[:, (k + 1) % 3]] - V[F[:, k]]) ** 2, axis=1)  # edge k -> k+1
        # Voronoi part: 1/8 (|e_prev|^2 cot(angle at k+2) + |e_next|^2 cot(angle at k+1))
        corner_area[:, k] = 0.125 * (e_prev * cot[:, (k + 2) % 3] + e_next * cot[:, (k + 1) % 3])
    obtuse = cot < 0
    any_obtuse = obtuse.any(axis=1)
    corner_area[any_obtuse] = np.where(obtuse[any_obtuse], 0.5, 0.25) * area[any_obtuse, None]
    # Degenerate triangles: split their (tiny) area evenly, never negative.
    bad = ~np.isfinite(corner_area).all(axis=1) | (corner_area < 0).any(axis=1)
    corner_area[bad] = area[bad, None] / 3.0
    return np.bincount(F.ravel(), weights=corner_area.ravel(), minlength=len(V))


@dataclass(frozen=True)
class SurfaceOperators:
    """The cotangent Laplacian and the lumped mass of one mesh, built
    together (:func:`surface_operators`) for callers that need both at
    several scales: the Laplacian does not change with scale, the mass grows
    with its square.

    Attributes
    ----------
    laplacian : (n, n) scipy.sparse.csr_matrix (:func:`cotangent_laplacian`)
    mass : (n,) float64 array (:func:`voronoi_mass`), at the mesh's own scale
    """

    laplacian: sp.csr_matrix
    mass: np.ndarray

    def mass_scaled(self, factor: float) -> np.ndarray:
        """The mass of the mesh scaled by ``factor`` (> 0)."""
        return self.mass * (factor * factor)


def surface_operators(V: np.ndarray, F: np.ndarray) -> SurfaceOperators:
    """:class:`SurfaceOperators` of the mesh ``(V, F)``, its cotangents computed once."""
    cot = corner_cotangents(V, F)
    return SurfaceOperators(cotangent_laplacian(V, F, cot), voronoi_mass(V, F, cot))
