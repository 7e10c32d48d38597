"""Ellipsoidal heads (and bodies) that eyes, horns and hats are placed on."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .frames import Y, Z, axis_frame, normalized
from .shapes import ellipsoid_geometry


@dataclass(frozen=True)
class Ellipsoid:
    """An ellipsoidal head or body.

    Attributes
    ----------
    centre : (3,) float64 array
    radii : (3,) float64 array
        Semi-axes along the columns of ``frame``.
    frame : (3, 3) float64 array
    """

    centre: np.ndarray
    radii: np.ndarray
    frame: np.ndarray

    def surface_point(self, direction: np.ndarray) -> np.ndarray:
        """Where the ray from the centre along world ``direction`` leaves the surface."""
        local = self.frame.T @ normalized(direction)
        return self.centre + self.frame @ (local / np.sqrt(((local / self.radii) ** 2).sum()))

    def geometry(self, spacing: float):
        """(vertices, triangles) of the closed surface (:func:`.shapes.ellipsoid_geometry`)."""
        return ellipsoid_geometry(self.centre, self.radii, self.frame, spacing)


def head_ellipsoid(rig, bone, radii_fraction, centre_fraction, unit_scale=1.0) -> Ellipsoid:
    """Ellipsoid around a head bone of ``rig`` (a :class:`.rig_builder.RigBuilder`):
    semi-axes ``radii_fraction`` (across, up, along) times the bone length
    (times ``unit_scale``), centred ``centre_fraction`` of the way from head
    to tail."""
    length = rig.length(bone)
    frame = axis_frame(rig.direction(bone), Z if abs(rig.direction(bone)[2]) < 0.9 else -Y)
    # frame columns: (up-ish, across, along); reorder radii to match.
    across, up, along = np.asarray(radii_fraction) * length * unit_scale
    return Ellipsoid(rig.point_along(bone, centre_fraction), np.array([up, across, along]), frame)


def vertical_head(rig, bone, radii_fraction, centre_fraction) -> Ellipsoid:
    """World-aligned ellipsoid for an upright head bone: semi-axes (x, y, z)
    ``radii_fraction`` times the bone length, centred ``centre_fraction`` of
    the way from head to tail."""
    return Ellipsoid(rig.point_along(bone, centre_fraction), np.asarray(radii_fraction) * rig.length(bone), np.eye(3))
