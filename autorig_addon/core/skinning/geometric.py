"""Skin weights from vertex-to-bone distances through the shape.

In the spirit of Geodesic Voxel Binding (Dionne & de Lasa 2013) and of
Blender's own bone heat (Baran & Popovic 2007), without their failure modes:
bone heat needs every bone to be *visible* from the surface along a straight
line inside the mesh and gives up on meshes that are not closed; here the
distance is measured through the solid (:mod:`..distances.volumetric_geodesic`)
or through hollow space (:mod:`..distances.hollow_dist`), so an arm bone does not pull the
torso it almost touches through the air, and every vertex of any mesh gets
weights. Works with any armature, including one an artist built or edited:
only the deform bones and their positions are used.

Steps:

1. Distances ``d`` (n, b) from every vertex to every deform bone.
2. Heat sources: each vertex's nearest bone ``j*`` (ties within
   :data:`.heat_diffusion.NEAREST_TIE_FRACTION` share) heats it with strength
   ``H = falloff / d_min^2``, ``d_min`` its distance to that bone in units
   of the mesh diagonal, when the vertex *sees* that bone: its distance
   through the shape equals the straight one (as bone heat's visibility
   test, but read off the distances, so it never fails). Close to a bone the
   surface is held to it; far away, or behind another part, the heat is
   weak or absent and the surface takes what its neighbours have. A
   connected part that sees no bone at all is heated everywhere, so every
   part is bound.
3. Diffusion over the surface (:mod:`.heat_diffusion`): for every bone
   ``j`` solve ``(-L + M H) w_j = M H p_j`` (cotangent Laplacian ``L``,
   lumped mass ``M``, ``p_j`` the indicator of vertices whose nearest bone
   is ``j``) on the mesh welded at its seams, with one sparse factorisation
   for all bones. This is the steady state of heat flowing along the
   surface, so weights blend smoothly across joints; ``falloff`` sets how
   sharply (higher: narrower blends).
4. Optional extra passes of uniform surface smoothing, then at most
   ``max_influences`` bones per vertex, rows normalised
   (:func:`..weights.limit_influences`). Every row is non-empty: loose parts
   take their nearest bone.

Big meshes (more than :data:`PROXY_VERTEX_THRESHOLD` vertices, e.g. sculpt
resolution) run steps 1 to 3 and the smoothing on a simplified proxy of
about :data:`PROXY_VERTICES` vertices (:mod:`..geometry.proxy`: vertex
clustering that keeps every connected part), and the weights come back to
every vertex interpolated at its closest point on the proxy surface; the
influence limit, pruning and normalisation run last, on the full mesh
(smoothing passes run along the proxy's longer edges, so each reaches
further there). The threshold counts vertices as given, seam copies
included. The
cost of the distances and of the diffusion grows with the vertex count
times the bone count, so a 264k-vertex, 163-bone character drops from
minutes to seconds (``docs/benchmarks.md``). Smaller meshes are solved
vertex by vertex, as before.

On the training characters of ``data_split.json`` this halves bone heat's
mean deformation error; see ``docs/skinning.md`` for the validation table.
"""

from __future__ import annotations

import numpy as np

from ..distances.grid import DEFAULT_RESOLUTION
from ..distances.hollow_dist import hollow_distances
from ..distances.volumetric_geodesic import volumetric_geodesic_distances
from ..errors import InputError
from ..geometry.proxy import Proxy, simplified_proxy
from ..geometry.segments import paired_point_segment_distances
from ..geometry.smoothing import DEFAULT_SMOOTHING_STRENGTH, smooth_over_edges
from ..progress import ProgressCallback, report, sub_progress
from ..types import Mesh, Skeleton, Weights
from ..weights import empty_rows, limit_influences, prune_small
from .heat_diffusion import heat_diffusion_weights

#: Distance kinds: "geodesic" (through the solid; needs closed parts for an
#: interior, else paths follow the surface) and "hollow" (HollowDist,
#: through the space the mesh leaves empty; no watertightness needed).
DISTANCES = ("geodesic", "hollow")
#: HollowDist: best on the training characters (see docs/skinning.md).
DEFAULT_DISTANCE = "hollow"
#: Heat strength (Baran & Popovic's c, unitless): how fast a bone's
#: influence falls off away from the vertices it is nearest to. Higher gives
#: sharper transitions between bones. 4 was best on the training characters
#: (tried 0.5 to 8).
DEFAULT_FALLOFF = 4.0
#: Falloffs the panel and the command line offer (unitless): from blends
#: spanning whole limbs to a hard switch at the joint.
MIN_FALLOFF = 0.1
MAX_FALLOFF = 64.0
#: Bones per vertex kept (game engines commonly take 4; 0 keeps all).
DEFAULT_MAX_INFLUENCES = 4
#: Extra passes of uniform surface smoothing after the diffusion (0: none;
#: the diffusion is already smooth).
DEFAULT_SMOOTHING_ITERATIONS = 0
#: A vertex sees its nearest bone when its distance through the shape is at
#: most this much (relative) longer than the straight distance.
VISIBILITY_SLACK = 0.02
#: Meshes with more vertices than this are solved on a simplified proxy
#: (every validation character, at most 13k vertices, stays below it and is
#: solved vertex by vertex).
PROXY_VERTEX_THRESHOLD = 20_000
#: Vertices of that proxy, about (:func:`..geometry.proxy.simplified_proxy`).
PROXY_VERTICES = 10_000


def geometric_weights(
    mesh: Mesh,
    skeleton: Skeleton,
    *,
    distances: np.ndarray | None = None,
    distance: str = DEFAULT_DISTANCE,
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
        of the deform bones); computed with ``distance`` when omitted.
    distance : "geodesic" or "hollow", the distance kind (see :data:`DISTANCES`)
    resolution : int, voxel cells along the longest side of the mesh
    falloff : float > 0, heat strength: higher gives sharper blends between bones
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
    _check_options(distance, falloff, max_influences, smoothing_iterations, smoothing_strength)
    deform = deform_bones_of(mesh, skeleton)
    names = tuple(skeleton.names[j] for j in deform)
    heads, tails = skeleton.joints[deform], skeleton.tails[deform]
    if distances is not None:
        distances = _checked_distances(distances, mesh.vertex_count, len(deform))
    proxy = None
    if mesh.vertex_count > PROXY_VERTEX_THRESHOLD:
        report(progress, 0.0, "Simplifying the mesh")
        proxy = simplified_proxy(mesh, PROXY_VERTICES)
        progress = sub_progress(progress, 0.05, 1.0)
    solved = mesh if proxy is None else proxy.mesh
    if distances is None:
        compute = volumetric_geodesic_distances if distance == "geodesic" else hollow_distances
        distances = compute(solved, heads, tails, resolution=resolution, progress=sub_progress(progress, 0.0, 0.85))
    elif proxy is not None:
        distances = proxy.average(distances)
    report(progress, 0.9, "Diffusing bone heat")
    weights = heat_diffusion_weights(solved, distances, falloff,
                                     sees_nearest_bone(solved.vertices, distances, heads, tails))
    weights = smooth_over_edges(weights, solved.triangles, smoothing_iterations, smoothing_strength)
    if proxy is None:
        weights = _nearest_bone_where_empty(_limited(weights, max_influences), lambda empty: distances[empty])
    else:
        report(progress, 0.95, "Carrying the weights to every vertex")
        weights = _carried(proxy, weights, distances, max_influences)
    report(progress, 1.0, "Weights done")
    return Weights(weights, names)


def deform_bones_of(mesh: Mesh, skeleton: Skeleton) -> np.ndarray:
    """Indices of the deform bones of ``skeleton``, after the checks every
    skinning method makes.

    Raises
    ------
    InputError when there is no deform bone or the mesh has no vertices.
    """
    deform = np.flatnonzero(skeleton.deform)
    if not len(deform):
        raise InputError("The armature has no deform bones; enable Deform on the bones that should move the mesh.")
    if not mesh.vertex_count:
        raise InputError("The mesh has no vertices.")
    return deform


def sees_nearest_bone(vertices: np.ndarray, distances: np.ndarray, heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(n,) bool: vertices whose distance to their nearest bone is the
    straight-line one (within :data:`VISIBILITY_SLACK`), i.e. nothing of the
    shape stands between them and the bone.

    Parameters
    ----------
    vertices : (n, 3) float64 array
    distances : (n, b) float64 array, through-the-shape distances
    heads, tails : (b, 3) float64 arrays, the bones of ``distances``' columns
    """
    rows = np.arange(len(vertices))
    nearest = distances.argmin(axis=1)
    straight = paired_point_segment_distances(vertices, heads[nearest], tails[nearest])
    return distances[rows, nearest] <= straight * (1.0 + VISIBILITY_SLACK) + 1e-12


def _limited(weights: np.ndarray, max_influences: int) -> np.ndarray:
    """At most ``max_influences`` bones per row, negligible weights pruned, rows normalised."""
    return prune_small(limit_influences(weights, max_influences))


def _nearest_bone_where_empty(weights: np.ndarray, empty_distances) -> np.ndarray:
    """Give any row left without weight its nearest bone, in place (a guard:
    heat reaches every vertex of a connected part, but pruning could empty
    a row whose weights were all tiny). ``empty_distances(mask)`` gives the
    (k, b) distances of the masked rows."""
    empty = empty_rows(weights)
    if empty.any():
        weights[empty] = 0.0
        weights[np.flatnonzero(empty), empty_distances(empty).argmin(axis=1)] = 1.0
    return weights


def _carried(proxy: Proxy, weights: np.ndarray, distances: np.ndarray, max_influences: int) -> np.ndarray:
    """(n, b) finished weights of every original vertex from the proxy's
    unnormalised ``weights`` (p, b), batch by batch so the full mesh's rows
    exist once (:meth:`..geometry.proxy.Proxy.carry`); an empty row takes
    the nearest bone by the distances carried the same way."""

    def finish(rows: slice, carried: np.ndarray) -> np.ndarray:
        interpolation = proxy.interpolation[rows]
        limited = _limited(carried, max_influences)
        return _nearest_bone_where_empty(limited,
                                         lambda empty: np.asarray(interpolation[np.flatnonzero(empty)] @ distances))

    return proxy.carry(weights, finish)


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


def _check_options(distance, falloff, max_influences, smoothing_iterations, smoothing_strength) -> None:
    if distance not in DISTANCES:
        raise InputError(f"Unknown distance method {distance!r}; use one of {', '.join(DISTANCES)}.")
    if not (np.isfinite(falloff) and falloff > 0):
        raise InputError(f"Falloff must be a positive number, got {falloff}.")
    if int(max_influences) < 0:
        raise InputError(f"Max influences must be 0 (no limit) or more, got {max_influences}.")
    if int(smoothing_iterations) < 0:
        raise InputError(f"Smoothing iterations cannot be negative, got {smoothing_iterations}.")
    if not 0.0 <= smoothing_strength <= 1.0:
        raise InputError(f"Smoothing strength must lie in [0, 1], got {smoothing_strength}.")
