"""The axis-aligned bounding box of a point set (:func:`bounding_box`) and
its size: the diagonal, or its largest side.

Every length the add-on scales by the size of a character (error
measures, tolerances, weld distances) uses the diagonal, except where a
published measure fixes another unit: RigNet's skeleton metrics (``eval
rig``) and its normalisation use the largest side (:func:`largest_side`).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError


def bounding_box(vertices: np.ndarray) -> np.ndarray:
    """(2, 3): the lowest and the highest corner of ``vertices`` (n, 3)."""
    vertices = np.asarray(vertices, dtype=np.float64)
    return np.array([vertices.min(axis=0), vertices.max(axis=0)])


def bounding_box_diagonal(points: np.ndarray) -> float:
    """Length of the diagonal of the axis-aligned bounding box of ``points``.

    Parameters
    ----------
    points : (n, 3) float64 array

    Returns
    -------
    diagonal : float, in the units of ``points``; 0 for no points

    Examples
    --------
    >>> bounding_box_diagonal([[0, 0, 0], [3, 4, 0], [1, 1, 12]])
    13.0
    """
    return float(np.linalg.norm(_box_sides(points)))


def largest_side(points: np.ndarray) -> float:
    """Length of the longest side of the axis-aligned bounding box of ``points``.

    Parameters
    ----------
    points : (n, 3) float64 array

    Returns
    -------
    side : float, in the units of ``points``; 0 for no points

    Examples
    --------
    >>> largest_side([[0, 0, 0], [3, 4, 0], [1, 1, 12]])
    12.0
    """
    return float(_box_sides(points).max())


def _box_sides(points: np.ndarray) -> np.ndarray:
    """(3,) float64 side lengths of the axis-aligned bounding box of (n, 3)
    ``points`` along x, y, z; zeros for no points."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if not len(points):
        return np.zeros(3)
    return points.max(axis=0) - points.min(axis=0)


def character_size(vertices: np.ndarray) -> float:
    """Size of a character, the length its errors are measured against:
    :func:`bounding_box_diagonal` of its rest mesh, which must be positive.

    Parameters
    ----------
    vertices : (n, 3) float64 array

    Returns
    -------
    size : float > 0, in the units of ``vertices``

    Raises
    ------
    InputError
        When there are no vertices or they all lie at one point.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    if not len(vertices):
        raise InputError("The mesh has no vertices, so it has no size to measure errors against.")
    size = bounding_box_diagonal(vertices)
    if size <= 0.0:
        raise InputError("All vertices lie at one point, so the mesh has no size to measure errors against.")
    return size


def checked_size(size: float) -> float:
    """A size given by a caller (e.g. a :func:`character_size` computed
    earlier), checked to be a positive finite length.

    Parameters
    ----------
    size : float

    Returns
    -------
    size : float

    Raises
    ------
    InputError
        For zero, negative, infinite or NaN sizes.
    """
    size = float(size)
    if not np.isfinite(size) or size <= 0.0:
        raise InputError(f"The character size must be a positive length, got {size}.")
    return size
