"""Smoothing per-vertex values over a mesh.

Two operators: :func:`smooth_over_edges`, explicit passes of the uniform
(graph) Laplacian, whose reach is counted in edges; and
:func:`smooth_over_surface`, one implicit step of the heat equation with the
cotangent Laplacian, whose reach is a length on the surface, so a fine and a
coarse mesh of one shape are smoothed alike.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .laplacian import SurfaceOperators, surface_operators
from .sparse_solve import solve_positive_definite
from .topology import adjacency_matrix

#: Default share of the neighbours' mean blended into a row per pass, in [0, 1]
#: (the default of every feature that smooths weights: transfer and skinning).
DEFAULT_SMOOTHING_STRENGTH = 0.5
#: Most smoothing passes the panels and the command line offer (each pass
#: moves a row toward its neighbours' mean; a hundred flatten any weight ramp).
MAX_SMOOTHING_ITERATIONS = 100


def smooth_over_edges(values: np.ndarray, F: np.ndarray, iterations: int, strength: float,
                      rows: np.ndarray | None = None) -> np.ndarray:
    """Uniform Laplacian smoothing of per-vertex ``values`` along mesh edges.

    Each pass replaces a row by ``(1 - strength) * row + strength * mean of
    its edge neighbours' rows``. Only ``rows`` (bool mask, default all)
    change; vertices without edges keep their rows, so loose parts never
    exchange values.

    Parameters
    ----------
    values : (n, k) float64 array
    F : (m, 3) int array
    iterations : int >= 0
    strength : float in [0, 1]
    rows : (n,) bool array or None

    Returns
    -------
    (n, k) float64 array (a new one; ``values`` is not modified).
    """
    smoothed = np.array(values, dtype=np.float64, copy=True)
    if iterations <= 0 or strength <= 0 or not len(F):
        return smoothed
    adjacency = adjacency_matrix(F, len(smoothed))
    degree = np.asarray(adjacency.sum(axis=1)).ravel()
    moving = degree > 0 if rows is None else np.asarray(rows, dtype=bool) & (degree > 0)
    if not moving.any():
        return smoothed
    for _ in range(int(iterations)):
        mean = (adjacency @ smoothed)[moving] / degree[moving, None]
        smoothed[moving] = (1.0 - strength) * smoothed[moving] + strength * mean
    return smoothed


def smooth_over_surface(values: np.ndarray, V: np.ndarray, F: np.ndarray, length: float,
                        fixed: np.ndarray | None = None, operators: SurfaceOperators | None = None) -> np.ndarray:
    """Heat smoothing of per-vertex ``values`` over the surface, at a length scale.

    One implicit (backward Euler) step of the heat equation for the time
    ``length**2``: the result ``X`` solves ``(M - length^2 L) X = M X0``
    (``L`` the cotangent Laplacian, ``M`` the lumped Voronoi mass). Variation
    finer than ``length`` is damped, coarser variation kept; constants stay
    exactly, so rows summing to one still do. Rows in ``fixed``, and vertices
    without area (in no triangle, or only in degenerate ones), keep their
    values and act as boundary values for their neighbours.

    Where the mesh has non-Delaunay edges (a negative cotangent weight) the
    result may dip slightly outside the range of the input; callers that need
    non-negative values clamp.

    Parameters
    ----------
    values : (n, k) float64 array
    V : (n, 3) float64 array
    F : (m, 3) int array
    length : float >= 0, scene units; 0 returns a copy of ``values``
    fixed : (n,) bool array or None
    operators : SurfaceOperators of ``(V, F)`` when the caller has them

    Returns
    -------
    (n, k) float64 array (a new one; ``values`` is not modified).
    """
    smoothed = np.array(values, dtype=np.float64, copy=True)
    if not length > 0 or not len(F) or not smoothed.size:
        return smoothed
    operators = surface_operators(np.asarray(V, dtype=np.float64), F) if operators is None else operators
    # In units of ``length`` the system is (M - L) X = M X0, scaled near one
    # whatever the scene units.
    mass = operators.mass_scaled(1.0 / length)
    free = mass > 0
    if fixed is not None:
        free &= ~np.asarray(fixed, dtype=bool)
    # Columns that are zero everywhere stay zero: skip their solves.
    active = np.flatnonzero(np.any(smoothed != 0, axis=0))
    if not free.any() or not len(active):
        return smoothed
    laplacian = operators.laplacian
    inside, boundary = np.flatnonzero(free), np.flatnonzero(~free)
    system = (sp.diags(mass[inside]) - laplacian[inside][:, inside]).tocsc()
    rhs = mass[inside, None] * smoothed[np.ix_(inside, active)]
    if len(boundary):
        rhs += laplacian[inside][:, boundary] @ smoothed[np.ix_(boundary, active)]
    # M - L is symmetric positive definite: -L is the Dirichlet energy.
    smoothed[np.ix_(inside, active)] = solve_positive_definite(system, rhs)
    return smoothed
