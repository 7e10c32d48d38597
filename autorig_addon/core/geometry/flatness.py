"""Whether a surface is flat: a sheet or a pancake, not a body with depth.

A skeleton is predicted for a body with some depth. A character squashed
by an unapplied object scale of (1, 1, 0.019) is a pancake 2 cm thick,
and still got a 14-bone rig. A shape is flat when both hold:

- its thickness, the extent along its thinnest principal axis, is under
  :data:`FLAT_THICKNESS_RATIO` of its width (the middle extent; a snake
  stretched out is thin along two axes, and not flat), and
- most of its surface (:data:`MIN_FACING_SHARE` of the area) faces along
  that axis, within :data:`FACING_ANGLE_DEGREES`: a snake coiled on the
  ground is as thin as a pancake, but its surface turns all around the
  tube.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: A shape whose thickness is under this share of its width may be flat ...
FLAT_THICKNESS_RATIO = 0.1
#: ... when at least this share of its surface area ...
MIN_FACING_SHARE = 0.75
#: ... faces along its thinnest axis within this angle.
FACING_ANGLE_DEGREES = 15.0


@dataclass(frozen=True)
class Flatness:
    """How flat a surface is.

    Attributes
    ----------
    thickness, width, length : float, extents along its principal axes, thinnest first
    axis : (3,) float64 unit vector, the thinnest principal axis
    facing_share : float, share of the surface area whose normal lies within
        :data:`FACING_ANGLE_DEGREES` of ``axis`` (either way)
    """

    thickness: float
    width: float
    length: float
    axis: np.ndarray
    facing_share: float

    @property
    def thickness_ratio(self) -> float:
        """Thickness over width (1 for a round shape, 0 for a sheet)."""
        return self.thickness / self.width if self.width > 0 else 1.0

    @property
    def is_flat(self) -> bool:
        """Thin along one axis and facing along it (module docstring)."""
        return self.thickness_ratio < FLAT_THICKNESS_RATIO and self.facing_share >= MIN_FACING_SHARE


def flatness(vertices: np.ndarray, triangles: np.ndarray) -> Flatness:
    """The :class:`Flatness` of a triangle surface.

    Parameters
    ----------
    vertices : (n, 3) float array
    triangles : (m, 3) int array; their areas weigh the principal axes, so
        the density of the vertices does not tilt them

    Examples
    --------
    >>> square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    >>> flatness(square, np.array([[0, 1, 2], [0, 2, 3]])).is_flat
    True
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    corners = vertices[np.asarray(triangles, dtype=np.int64)]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    doubled_areas = np.linalg.norm(cross, axis=1)
    total = doubled_areas.sum()
    if total <= 0:
        return Flatness(0.0, 0.0, 0.0, np.array([0.0, 0.0, 1.0]), 1.0)
    centroids = corners.mean(axis=1)
    centre = (doubled_areas[:, None] * centroids).sum(axis=0) / total
    # The covariance of a point spread evenly over the surface: over one
    # triangle, E[x x^T] = (sum of its corners' v v^T + 9 g g^T) / 12 (g: centroid).
    local = corners - centre
    moments = np.einsum("tci,tcj->tij", local, local) + 9.0 * np.einsum("ti,tj->tij", centroids - centre,
                                                                       centroids - centre)
    covariance = (doubled_areas[:, None, None] * moments).sum(axis=0) / (12.0 * total)
    _, axes = np.linalg.eigh(covariance)
    projected = (vertices - centre) @ axes
    extents = projected.max(axis=0) - projected.min(axis=0)
    order = np.argsort(extents, kind="stable")
    thin_axis = axes[:, order[0]]
    normals = cross[doubled_areas > 0] / doubled_areas[doubled_areas > 0, None]
    facing = np.abs(normals @ thin_axis) >= np.cos(np.radians(FACING_ANGLE_DEGREES))
    facing_share = float(doubled_areas[doubled_areas > 0][facing].sum() / total)
    thickness, width, length = (float(extents[i]) for i in order)
    return Flatness(thickness, width, length, thin_axis, facing_share)
