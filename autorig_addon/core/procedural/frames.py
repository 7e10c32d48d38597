"""Directions, rotations and orthonormal frames for placing generated parts.

Conventions of the generator: metres, z up, characters face -y, their left
side at +x.
"""

from __future__ import annotations

import numpy as np

from ..skeleton.posing import axis_angle_matrices

#: World axes.
X = np.array([1.0, 0.0, 0.0])
Y = np.array([0.0, 1.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])
#: Multiplying a point by this mirrors it across the plane x = 0 (left <-> right).
MIRROR_X = np.array([-1.0, 1.0, 1.0])


def normalized(vectors: np.ndarray) -> np.ndarray:
    """Vectors scaled to unit length along the last axis (zero stays zero).

    Parameters
    ----------
    vectors : (..., 3) array_like

    Returns
    -------
    (..., 3) float64 array
    """
    vectors = np.asarray(vectors, dtype=np.float64)
    norms = np.linalg.norm(vectors, axis=-1, keepdims=True)
    return vectors / np.maximum(norms, 1e-300)


def rotation_matrix(axis: np.ndarray, angle: float) -> np.ndarray:
    """(3, 3) rotation by ``angle`` radians about ``axis`` (any length; right hand rule)."""
    return axis_angle_matrices(normalized(axis)[None, :], np.array([angle]))[0]


def axis_frame(axis: np.ndarray, hint: np.ndarray) -> np.ndarray:
    """(3, 3) right-handed frame with columns (x, y, z): z along ``axis``,
    x along the part of ``hint`` perpendicular to it (another axis when
    ``hint`` is parallel to ``axis``)."""
    z = normalized(axis)
    x = hint - np.dot(hint, z) * z
    if np.linalg.norm(x) < 1e-6 * max(np.linalg.norm(hint), 1e-300):
        other = X if abs(z[0]) < 0.9 else Y
        x = other - np.dot(other, z) * z
    x = normalized(x)
    return np.column_stack([x, np.cross(z, x), z])


def projected_normals(tangents: np.ndarray, up: np.ndarray) -> np.ndarray:
    """(r, 3) unit normals: ``up`` made perpendicular to each of the (r, 3)
    unit ``tangents``.

    When ``up`` comes close to a tangent, the coordinate axis most
    perpendicular to every tangent replaces it, so no ring degenerates.
    """
    candidates = np.vstack([normalized(up), np.eye(3)])
    sines = np.linalg.norm(np.cross(tangents[None, :, :], candidates[:, None, :]), axis=2).min(axis=1)
    reference = candidates[0] if sines[0] > 0.3 else candidates[int(np.argmax(sines))]
    normals = reference[None, :] - (tangents @ reference)[:, None] * tangents
    return normalized(normals)
