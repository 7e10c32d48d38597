"""Uniform Laplacian smoothing of per-vertex values along mesh edges."""

from __future__ import annotations

import numpy as np

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
