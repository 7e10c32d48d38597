"""Closest-point matching of target vertices onto a skinned source surface.

Stage 1 of robust weight transfer (Abdrashitov et al. 2023, section 3.1):
each target vertex takes the source weights at its closest point on the
source surface (barycentric interpolation, not the nearest vertex, which
picks the wrong side of a coarse body), and counts as matched only when
that point is near and the normals agree.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.closest_point import SurfacePoints, TriangleMeshQuery
from ..geometry.normals import vertex_normals
from ..types import Mesh, Weights
from ..weights import normalize_rows


@dataclass(frozen=True)
class Matches:
    """Closest-point matching of target vertices onto the source.

    Attributes
    ----------
    weights : (n, b) float64 array, source weights at the closest points
        (rows normalised), for every vertex, matched or not
    distances : (n,) float64 array, distance to the closest point, scene units
    matched : (n,) bool array, near enough with agreeing (or, where allowed,
        opposite) normals: these weights can be copied
    flipped : (n,) bool array, matched through opposite normals (a subset of ``matched``)
    """

    weights: np.ndarray
    distances: np.ndarray
    matched: np.ndarray
    flipped: np.ndarray


def _weights_at(surface: SurfacePoints, source: Mesh, source_weights: np.ndarray) -> np.ndarray:
    """(q, b) ``source_weights`` interpolated at ``surface``'s points, rows normalised."""
    return normalize_rows(surface.interpolate(source.triangles, source_weights))


def closest_point_weights(source: Mesh, source_weights: Weights, target: Mesh) -> Weights:
    """Every target vertex takes the source weights at its closest source
    surface point: plain copying, the baseline robust transfer improves on.

    Parameters
    ----------
    source : Mesh with n_s vertices and at least one triangle
    source_weights : Weights, (n_s, b)
    target : Mesh with n vertices

    Returns
    -------
    Weights, (n, b), rows normalised, bones as in ``source_weights``
    """
    surface = TriangleMeshQuery(source.vertices, source.triangles).closest(target.vertices)
    return Weights(_weights_at(surface, source, source_weights.matrix), source_weights.bone_names)


def match_closest_points(
    source: Mesh, source_weights: np.ndarray, target: Mesh, target_normals: np.ndarray,
    max_distance: float, max_normal_angle: float, accept_flipped_normals: bool,
) -> Matches:
    """Match target vertices whose closest source point is near and whose
    normal agrees with the source normal there.

    Parameters
    ----------
    source : Mesh with n_s vertices and at least one triangle
    source_weights : (n_s, b) float64 array
    target : Mesh with n vertices
    target_normals : (n, 3) float64 array, unit (zero where unknown)
    max_distance : float, scene units; farther points never match
    max_normal_angle : float in (0, 180], degrees; the largest angle between
        the target normal and the interpolated source normal for a match
    accept_flipped_normals : bool, also match where the normals are opposite
        within the angle (inner layers, cloth modelled facing inwards)

    Returns
    -------
    Matches
    """
    surface = TriangleMeshQuery(source.vertices, source.triangles).closest(target.vertices)
    weights = _weights_at(surface, source, source_weights)
    source_normals = surface.interpolate(source.triangles, vertex_normals(source.vertices, source.triangles))
    length = np.linalg.norm(source_normals, axis=1)
    cosine = np.einsum("ij,ij->i", source_normals, target_normals) / np.maximum(length, 1e-300)
    cosine[length == 0] = 0.0
    cos_limit = np.cos(np.radians(max_normal_angle))
    near = surface.distances <= max_distance
    flipped = near & (cosine <= -cos_limit) if accept_flipped_normals else np.zeros(len(near), dtype=bool)
    matched = (near & (cosine >= cos_limit)) | flipped
    return Matches(weights, surface.distances, matched, flipped)
