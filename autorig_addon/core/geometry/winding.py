"""Generalised winding numbers: whether a point lies inside a surface that may have holes.

A voxel solid filled from outside leaks through any hole wider than a voxel,
so an open game mesh (a 0 A.D. animal with open seams) has a solid one cell
deep, its shell, and every point inside reads as outside. The generalised
winding number (Jacobson, Kavan and Sorkine-Hornung 2013) does not leak: the
sum over the triangles of the solid angle each subtends at the point, over
4 pi, is 1 inside a closed outward-wound surface and 0 outside, and stays
near 1 inside one whose holes are small beside it.
"""

from __future__ import annotations

import numpy as np

#: Point-triangle pairs measured at once (memory: about 200 bytes each, so some 100 MB at once).
PAIRS_PER_CHUNK = 500_000


def winding_numbers(points: np.ndarray, vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The generalised winding number of each of ``points`` ((k, 3)) with respect to the triangles
    ((m, 3) indices into ``vertices``), outward wound: (k,) floats, 1 inside, 0 outside.

    Each triangle's signed solid angle is Van Oosterom and Strackee's
    ``2 atan2(a . (b x c), |a||b||c| + (a . b)|c| + (b . c)|a| + (c . a)|b|)``
    with ``a``, ``b``, ``c`` its corners seen from the point."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    corners = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles)]
    total = np.zeros(len(points))
    if not len(corners):
        return total
    step = max(1, PAIRS_PER_CHUNK // len(corners))
    for start in range(0, len(points), step):
        seen = corners[None, :, :, :] - points[start:start + step, None, None, :]
        a, b, c = seen[:, :, 0], seen[:, :, 1], seen[:, :, 2]
        length_a, length_b, length_c = (np.linalg.norm(corner, axis=2) for corner in (a, b, c))
        volume = np.einsum("ptk,ptk->pt", a, np.cross(b, c))
        denominator = (length_a * length_b * length_c + np.einsum("ptk,ptk->pt", a, b) * length_c
                       + np.einsum("ptk,ptk->pt", b, c) * length_a + np.einsum("ptk,ptk->pt", c, a) * length_b)
        total[start:start + step] = 2.0 * np.arctan2(volume, denominator).sum(axis=1)
    return total / (4.0 * np.pi)
