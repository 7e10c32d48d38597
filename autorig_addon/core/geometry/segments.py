"""Distances from points to line segments (bones, polylines).

Every distance to a bone in the project comes from here, in one convention:
segments are given by their ``heads`` and ``tails`` as two (b, 3) arrays, and a
zero-length segment is the point at its head. All-pairs queries work through
the points in chunks, so the (chunk, b, 3) temporaries stay under
:data:`CHUNK_BYTES` however many points there are.
"""

from __future__ import annotations

import numpy as np

#: Memory budget of the (chunk, b, 3) float64 temporaries of the all-pairs
#: queries: 64 MB keeps a 100k-vertex, 200-bone query within a few hundred MB.
CHUNK_BYTES = 64 * 2**20


def _as_points(array) -> np.ndarray:
    return np.asarray(array, dtype=np.float64).reshape(-1, 3)


def _point_chunks(point_count: int, segment_count: int):
    """Slices of the points whose (chunk, b, 3) float64 temporaries fit :data:`CHUNK_BYTES`."""
    chunk = max(1, CHUNK_BYTES // (24 * max(segment_count, 1)))
    return (slice(start, start + chunk) for start in range(0, point_count, chunk))


def segment_parameters(points: np.ndarray, heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(k, b) float64 in [0, 1]: where along each segment its nearest point to each point lies.

    ``head + t * (tail - head)`` is the nearest point; ``t = 0`` for a zero-length segment.

    Parameters
    ----------
    points : (k, 3) float64 array
    heads, tails : (b, 3) float64 arrays
    """
    points, heads, tails = _as_points(points), _as_points(heads), _as_points(tails)
    direction = tails - heads
    length_sq = np.einsum("bi,bi->b", direction, direction)
    projection = np.einsum("kbi,bi->kb", points[:, None, :] - heads[None, :, :], direction)
    t = np.divide(projection, length_sq, out=np.zeros_like(projection), where=length_sq > 0)
    return np.clip(t, 0.0, 1.0)


def nearest_points_on_segments(points: np.ndarray, heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(k, b, 3) float64: the point of each segment nearest to each point."""
    heads, tails = _as_points(heads), _as_points(tails)
    t = segment_parameters(points, heads, tails)
    return heads[None, :, :] + t[:, :, None] * (tails - heads)[None, :, :]


def point_segment_distances(points: np.ndarray, heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(k, b) float64 Euclidean distance from each point to each segment.

    Parameters
    ----------
    points : (k, 3) float64 array
    heads, tails : (b, 3) float64 arrays, segment ends (zero length allowed)
    """
    points, heads, tails = _as_points(points), _as_points(heads), _as_points(tails)
    out = np.empty((len(points), len(heads)))
    for rows in _point_chunks(len(points), len(heads)):
        gap = points[rows, None, :] - nearest_points_on_segments(points[rows], heads, tails)
        out[rows] = np.sqrt(np.einsum("kbi,kbi->kb", gap, gap))
    return out


def paired_segment_parameters(points: np.ndarray, heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(k,) float64 in [0, 1]: where along the segment ``heads[i]``-``tails[i]``
    its nearest point to ``points[i]`` lies (0 for a zero-length segment).

    Parameters
    ----------
    points, heads, tails : (k, 3) float64 arrays
    """
    points, heads, tails = _as_points(points), _as_points(heads), _as_points(tails)
    direction = tails - heads
    length_sq = np.einsum("ij,ij->i", direction, direction)
    projection = np.einsum("ij,ij->i", points - heads, direction)
    return np.clip(np.divide(projection, length_sq, out=np.zeros_like(projection), where=length_sq > 0), 0.0, 1.0)


def paired_point_segment_distances(points: np.ndarray, heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(k,) float64 distance from ``points[i]`` to the segment ``heads[i]``-``tails[i]``.

    Parameters
    ----------
    points, heads, tails : (k, 3) float64 arrays
    """
    points, heads, tails = _as_points(points), _as_points(heads), _as_points(tails)
    t = paired_segment_parameters(points, heads, tails)
    return np.linalg.norm(points - heads - t[:, None] * (tails - heads), axis=1)


def closest_segments(points: np.ndarray, heads: np.ndarray, tails: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index of and distance to the closest segment of every point.

    Parameters
    ----------
    points : (n, 3) float64 array
    heads, tails : (b, 3) float64 arrays, at least one segment

    Returns
    -------
    index : (n,) int64 array, closest segment per point; the lowest index wins ties
    distance : (n,) float64 array
    """
    points, heads, tails = _as_points(points), _as_points(heads), _as_points(tails)
    if not len(heads):
        raise ValueError("closest_segments needs at least one segment")
    index = np.empty(len(points), dtype=np.int64)
    distance = np.empty(len(points))
    for rows in _point_chunks(len(points), len(heads)):
        chunk = point_segment_distances(points[rows], heads, tails)
        index[rows] = np.argmin(chunk, axis=1)
        distance[rows] = chunk[np.arange(len(chunk)), index[rows]]
    return index, distance


def polyline_arc_lengths(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """(n,) float64: arc length along ``polyline`` (k + 1, 3) of its point nearest to each point."""
    polyline = _as_points(polyline)
    starts, ends = polyline[:-1], polyline[1:]
    lengths = np.linalg.norm(ends - starts, axis=1)
    best, _ = closest_segments(points, starts, ends)
    t = segment_parameters(points, starts, ends)[np.arange(len(best)), best]
    arc = np.concatenate([[0.0], np.cumsum(lengths)])
    return arc[best] + t * lengths[best]
