"""Arc length along polylines, and points placed by arc length.

A polyline is a (k + 1, 3) array of points joined in order (the joints of a
bone chain, the spine of a fish, a sampled curve).
"""

from __future__ import annotations

import numpy as np


def segment_lengths(polyline: np.ndarray) -> np.ndarray:
    """(k,) float64: length of each segment of a (k + 1, 3) polyline."""
    return np.linalg.norm(np.diff(polyline, axis=0), axis=1)


def cumulative_lengths(polyline: np.ndarray) -> np.ndarray:
    """(k + 1,) float64: arc length at each point (0 first, the total last)."""
    return np.concatenate([[0.0], np.cumsum(segment_lengths(polyline))])


def points_at_arc_lengths(polyline: np.ndarray, arc_lengths: np.ndarray) -> np.ndarray:
    """(m, 3) points at ``arc_lengths`` (m,) along a polyline (clamped to its ends)."""
    arc = cumulative_lengths(polyline)
    return np.column_stack([np.interp(arc_lengths, arc, polyline[:, k]) for k in range(3)])


def points_at_fractions(polyline: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    """(m, 3) points at ``fractions`` (m,) in [0, 1] of the length of a polyline."""
    return points_at_arc_lengths(polyline, fractions * cumulative_lengths(polyline)[-1])


def resample_polyline(polyline: np.ndarray, count: int) -> np.ndarray:
    """(count, 3) points evenly spaced by arc length from the first point to the last."""
    return points_at_arc_lengths(polyline, np.linspace(0.0, cumulative_lengths(polyline)[-1], count))
