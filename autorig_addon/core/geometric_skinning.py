"""Skin weights from vertex-to-bone distances through the shape.

In the spirit of Geodesic Voxel Binding (Dionne & de Lasa 2013): a bone's
influence on a vertex falls off with their distance measured through the
solid (:mod:`.volumetric_geodesic`) or through hollow space
(:mod:`.hollow_dist`), so an arm bone does not pull the torso it almost
touches through the air. Works with any armature, including one an artist
built or edited: only the deform bones and their positions are used.

Steps:

1. Distances ``d`` (n, b) from every vertex to every deform bone.
2. Falloff: ``w = (1 + (d - d_min) / s) ** -falloff`` where ``d_min`` is the
   vertex's distance to its nearest bone and ``s = min(d_min,
   FAR_SCALE_FACTOR * typical)``, ``typical`` being the median of ``d_min``
   over the mesh. Close to the bones this is ``(d_min / d) ** falloff``
   (scale-free inverse-distance weights); for loose parts far from every
   bone (a prop, a hat floating above the head) the scale stops growing, so
   they bind to their nearest bone instead of an even mix of all bones.
   The nearest bone always gets 1 before normalisation, so no row is empty.
3. Smoothing over the surface: a few passes of uniform Laplacian smoothing
   (each vertex moves towards the mean of its edge neighbours), which
   removes the voxel staircase from the transitions.
4. At most ``max_influences`` bones per vertex (0: no limit), rows
   normalised to sum to 1 (:func:`.weights.limit_influences`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .errors import InputError
from .hollow_dist import hollow_distances
from .mesh_ops import adjacency_matrix
from .progress import ProgressCallback, report, sub_progress
from .types import Mesh, Skeleton, Weights
from .volumetric_geodesic import volumetric_geodesic_distances
from .voxelize import DEFAULT_RESOLUTION
from .weights import empty_rows, limit_influences

#: Distance kinds: "geodesic" (through the solid; needs closed parts for an
#: interior, else paths follow the surface) and "hollow" (HollowDist,
#: through the space the mesh leaves empty; no watertightness needed).
METHODS = ("geodesic", "hollow")
DEFAULT_METHOD = "geodesic"
#: Exponent of the inverse-distance falloff (unitless). Higher gives sharper
#: transitions between bones, lower gives softer, wider blends.
DEFAULT_FALLOFF = 8.0
#: Bones per vertex kept (game engines commonly take 4; 0 keeps all).
DEFAULT_MAX_INFLUENCES = 4
#: Passes of surface smoothing (0 disables it).
DEFAULT_SMOOTHING_ITERATIONS = 3
#: Share of the neighbour mean blended into a vertex per pass, in [0, 1].
DEFAULT_SMOOTHING_STRENGTH = 0.5
#: Beyond this many times the typical vertex-to-nearest-bone distance, the
#: falloff scale stops growing (loose parts bind to their nearest bone).
FAR_SCALE_FACTOR = 2.0
#: Distances are floored at this fraction of the mesh's bounding-box
#: diagonal, so a vertex lying on a bone does not divide by zero.
DISTANCE_FLOOR_FRACTION = 1e-4


def geometric_weights(
    mesh: Mesh,
    skeleton: Skeleton,
    *,
    distances: np.ndarray | None = None,
    method: str = DEFAULT_METHOD,
    resolution: int = DEFAULT_RESOLUTION,
    falloff: float = DEFAULT_FALLOFF,
    max_influences: int = DEFAULT_MAX_INFLUENCES,
    smoothing_iterations: int = DEFAULT_SMOOTHING_ITERATIONS,
    smoothing_strength: float = DEFAULT_SMOOTHING_STRENGTH,
    progress: ProgressCallback | None = None,
) -> Weights:
    """Skin weights of ``mesh`` for the deform bones of ``skeleton``.

    Parameters
    ----------
    mesh : Mesh
    skeleton : Skeleton; only bones with ``deform`` set get weights
    distances : (n, d) float64 array, optional
        Vertex-to-deform-bone distances in scene units (columns in the order
        of the deform bones); computed with ``method`` when omitted.
    method : "geodesic" or "hollow", the distance kind (see :data:`METHODS`)
    resolution : int, voxel cells along the longest side of the mesh
    falloff : float > 0, exponent of the inverse-distance falloff
    max_influences : int >= 0, bones kept per vertex (0: no limit)
    smoothing_iterations : int >= 0, passes of surface smoothing
    smoothing_strength : float in [0, 1], neighbour share per pass
    progress : optional ProgressCallback

    Returns
    -------
    Weights with one column per deform bone (in skeleton order); every row
    is non-negative, sums to 1 and has at most ``max_influences`` non-zeros
    (when that is above 0).
    """
    _check_options(method, falloff, max_influences, smoothing_iterations, smoothing_strength)
    deform = np.flatnonzero(skeleton.deform)
    if not len(deform):
        raise InputError("The armature has no deform bones; enable Deform on the bones that should move the mesh.")
    if not mesh.vertex_count:
        raise InputError("The mesh has no vertices.")
    names = tuple(skeleton.names[j] for j in deform)
    heads, tails = skeleton.joints[deform], skeleton.tails[deform]
    if distances is None:
        compute = volumetric_geodesic_distances if method == "geodesic" else hollow_distances
        distances = compute(mesh, heads, tails, resolution=resolution, progress=sub_progress(progress, 0.0, 0.85))
    else:
        distances = _checked_distances(distances, mesh.vertex_count, len(deform))
    report(progress, 0.9, "Weighting bones")
    floor = DISTANCE_FLOOR_FRACTION * max(mesh.bounding_box_diagonal, 1e-12)
    weights = falloff_weights(distances, falloff, floor)
    weights = smooth_over_surface(weights, mesh, smoothing_iterations, smoothing_strength)
    weights = limit_influences(weights, max_influences)
    weights = _nearest_bone_where_empty(weights, distances)
    report(progress, 1.0, "Weights done")
    return Weights(weights, names)


def falloff_weights(distances: np.ndarray, falloff: float, floor: float) -> np.ndarray:
    """Unnormalised weights from distances (see the module docstring).

    Parameters
    ----------
    distances : (n, b) float64 array, finite, >= 0, scene units
    falloff : float > 0, the exponent
    floor : float > 0, smallest distance scale, scene units

    Returns
    -------
    (n, b) float64 array in (0, 1], exactly 1 at each row's nearest bone.
    """
    distances = np.asarray(distances, dtype=np.float64)
    nearest = distances.min(axis=1, keepdims=True)
    typical = max(float(np.median(nearest)), floor)
    scale = np.clip(nearest, floor, FAR_SCALE_FACTOR * typical)
    return (1.0 + (distances - nearest) / scale) ** (-float(falloff))


def smooth_over_surface(weights: np.ndarray, mesh: Mesh, iterations: int, strength: float) -> np.ndarray:
    """Uniform Laplacian smoothing of per-vertex values along mesh edges.

    Each pass replaces a vertex's row by ``(1 - strength) * row + strength *
    mean of its neighbours' rows``. Vertices without edges keep their rows;
    loose parts never exchange values.

    Parameters
    ----------
    weights : (n, b) float64 array
    mesh : Mesh with n vertices
    iterations : int >= 0
    strength : float in [0, 1]

    Returns
    -------
    (n, b) float64 array.
    """
    if iterations <= 0 or strength <= 0 or not len(mesh.triangles):
        return np.asarray(weights, dtype=np.float64)
    adjacency = adjacency_matrix(mesh.triangles, mesh.vertex_count)
    degree = np.asarray(adjacency.sum(axis=1)).ravel()
    has_neighbours = degree > 0
    mean_of_neighbours = sp.diags(np.divide(1.0, degree, out=np.zeros_like(degree), where=has_neighbours)) @ adjacency
    blend = np.where(has_neighbours, strength, 0.0)[:, None]
    smoothed = np.asarray(weights, dtype=np.float64)
    for _ in range(int(iterations)):
        smoothed = (1.0 - blend) * smoothed + blend * (mean_of_neighbours @ smoothed)
    return smoothed


def _nearest_bone_where_empty(weights: np.ndarray, distances: np.ndarray) -> np.ndarray:
    """Give any row left without weight its nearest bone (a guard: the
    falloff gives every row a weight of 1 somewhere)."""
    empty = empty_rows(weights)
    if not empty.any():
        return weights
    fixed = weights.copy()
    fixed[empty] = 0.0
    fixed[np.flatnonzero(empty), distances[empty].argmin(axis=1)] = 1.0
    return fixed


def _checked_distances(distances, vertex_count: int, bone_count: int) -> np.ndarray:
    distances = np.asarray(distances, dtype=np.float64)
    if distances.shape != (vertex_count, bone_count):
        raise InputError(
            f"Distances must have one row per vertex and one column per deform bone "
            f"({vertex_count} x {bone_count}), got {distances.shape}."
        )
    if not np.all(np.isfinite(distances)) or np.any(distances < 0):
        raise InputError("Distances must be finite and non-negative; recompute them.")
    return distances


def _check_options(method, falloff, max_influences, smoothing_iterations, smoothing_strength) -> None:
    if method not in METHODS:
        raise InputError(f"Unknown distance method {method!r}; use one of {', '.join(METHODS)}.")
    if not (np.isfinite(falloff) and falloff > 0):
        raise InputError(f"Falloff must be a positive number, got {falloff}.")
    if int(max_influences) < 0:
        raise InputError(f"Max influences must be 0 (no limit) or more, got {max_influences}.")
    if int(smoothing_iterations) < 0:
        raise InputError(f"Smoothing iterations cannot be negative, got {smoothing_iterations}.")
    if not 0.0 <= smoothing_strength <= 1.0:
        raise InputError(f"Smoothing strength must lie in [0, 1], got {smoothing_strength}.")
