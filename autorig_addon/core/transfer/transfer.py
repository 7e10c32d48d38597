"""Robust skin weight transfer (Abdrashitov et al., SIGGRAPH Asia 2023).

Two stages:

1. **Matching** (:mod:`.matching`). Each target vertex looks up the closest
   point on the source surface. Its weights are copied (barycentric
   interpolation) only when the point is closer than ``D`` and the normals
   agree within an angle; a second pass accepts opposite normals, for inner
   garment layers.
2. **Inpainting** (:mod:`.inpainting`). The remaining weights minimise
   ``trace(W^T Q W)`` with ``Q = -L + L M^-1 L`` (cotangent Laplacian ``L``,
   lumped Voronoi mass ``M``) with the matched rows fixed, i.e.
   ``Q_UU W_U = -Q_UI W_I``, one sparse factorisation for every bone.

This module runs them: beyond the paper, seams are welded before inpainting
(glTF and FBX split vertices at UV seams, which would cut the Laplacian into
patches); parts of the target with no match at all are seeded at their
closest point so they move rigidly with the body; an artist mask forces
inpainting and a protected set keeps existing weights as fixed rows.
"""

from __future__ import annotations

import enum
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry.normals import vertex_normals
from ..geometry.smoothing import smooth_over_edges
from ..geometry.topology import connected_component_labels, non_manifold_edge_count
from ..geometry.weld import weld_mesh
from ..progress import ProgressCallback, report
from ..types import Mesh, Weights
from ..weights import check_weights, limit_influences, normalize_rows, prune_small
from .inpainting import inpaint_weights, inpainting_operator
from .matching import match_closest_points
from .options import TransferOptions

#: A target larger than this many source diagonals is taken as a unit mismatch.
MAX_SCALE_RATIO = 5.0


class VertexStatus(enum.IntEnum):
    """How each target vertex got its weights (stored in the diagnostic attribute)."""

    COPIED = 0
    COPIED_FLIPPED = 1
    INPAINTED = 2
    MASKED = 3
    PROTECTED = 4
    UNMATCHED_PART = 5


@dataclass
class TransferResult:
    """Outcome of :func:`transfer_weights`.

    Attributes
    ----------
    weights : Weights, (n_target, b), rows non-negative and summing to one,
        columns in the source's bone order
    status : (n_target,) int8 array of :class:`VertexStatus`
    max_distance : float, the match distance used (scene units)
    timings : dict of stage name -> seconds
    welded_vertices : int, seam copies joined to another vertex before inpainting
    non_manifold_edges : int, edges shared by more than two triangles (handled, reported)
    """

    weights: Weights
    status: np.ndarray
    max_distance: float
    timings: dict = field(default_factory=dict)
    welded_vertices: int = 0
    non_manifold_edges: int = 0

    def summary(self) -> str:
        counts = np.bincount(self.status, minlength=len(VertexStatus))
        total = max(len(self.status), 1)
        copied = counts[VertexStatus.COPIED] + counts[VertexStatus.COPIED_FLIPPED]
        inpainted = total - copied - counts[VertexStatus.PROTECTED]
        parts = [f"{copied} copied", f"{inpainted} inpainted ({100.0 * inpainted / total:.0f}%)"]
        if counts[VertexStatus.PROTECTED]:
            parts.append(f"{counts[VertexStatus.PROTECTED]} protected")
        if counts[VertexStatus.UNMATCHED_PART]:
            parts.append(f"{counts[VertexStatus.UNMATCHED_PART]} on parts with no match")
        if self.welded_vertices:
            parts.append(f"{self.welded_vertices} seam duplicates welded")
        if self.non_manifold_edges:
            parts.append(f"{self.non_manifold_edges} non-manifold edges")
        return ", ".join(parts)


def transfer_weights(
    source: Mesh,
    source_weights: Weights,
    target: Mesh,
    options: TransferOptions = TransferOptions(),
    *,
    inpaint_mask: np.ndarray | None = None,
    protected: np.ndarray | None = None,
    protected_weights: Weights | None = None,
    progress: ProgressCallback | None = None,
) -> TransferResult:
    """Weights for ``target`` from a skinned ``source`` surface.

    Parameters
    ----------
    source : Mesh, the skinned body (world space)
    source_weights : Weights, (n_source, b)
    target : Mesh, the garment(s) to weight (world space)
    options : TransferOptions
    inpaint_mask : (n_target,) bool array, vertices forced to be inpainted
    protected : (n_target,) bool array, vertices that keep ``protected_weights``
    protected_weights : Weights over any bones, (n_target, b'); matched to the
        source's bones by name, other bones ignored
    progress : ProgressCallback, may raise Cancelled

    Returns
    -------
    TransferResult; raises :class:`InputError` on unusable input.
    """
    timings: dict[str, float] = {}
    clock = time.perf_counter()
    _check_inputs(source, source_weights, target, options)
    n = target.vertex_count
    inpaint_mask = _optional_mask(inpaint_mask, n, "inpaint mask")
    protected = _optional_mask(protected, n, "protected set")
    if protected.any() and protected_weights is None:
        raise InputError("Protected vertices were given without their weights.")

    target_diagonal = target.bounding_box_diagonal
    max_distance = options.max_distance if options.max_distance is not None else options.distance_fraction * target_diagonal
    # Everything runs on the welded mesh (seams joined) and is expanded at the end.
    welded, to_welded = weld_mesh(target)
    welded_V, welded_F, count = welded.vertices, welded.triangles, welded.vertex_count
    masked = _any_copy(inpaint_mask, to_welded, count)
    protected_welded = _any_copy(protected, to_welded, count)
    timings["prepare"] = time.perf_counter() - clock
    report(progress, 0.05, "Matching closest points")

    clock = time.perf_counter()
    matches = match_closest_points(
        source, source_weights.matrix, welded, vertex_normals(welded_V, welded_F),
        max_distance, options.max_normal_angle, options.accept_flipped_normals,
    )
    timings["match"] = time.perf_counter() - clock
    matched = matches.matched
    if not matched.any() and not protected.any():
        raise InputError(
            f"No vertex of '{target.object_names[0]}' lies within {max_distance:.4g} of the source surface "
            "with agreeing normals: are the objects far apart or at different scales? "
            "Apply their transforms or raise the match distance."
        )
    report(progress, 0.35, "Building the inpainting system")

    clock = time.perf_counter()
    status = np.full(count, VertexStatus.INPAINTED, dtype=np.int8)
    status[matched] = VertexStatus.COPIED
    status[matches.flipped] = VertexStatus.COPIED_FLIPPED
    status[masked] = VertexStatus.MASKED
    known = matched & ~masked
    known_weights = matches.weights.copy()
    if protected.any():
        kept = normalize_rows(protected_weights.select_bones(source_weights.bone_names).matrix)
        known_weights[protected_welded] = _mean_over_copies(kept, protected, to_welded, count)[protected_welded]
        known |= protected_welded
        status[protected_welded] = VertexStatus.PROTECTED
    labels = connected_component_labels(welded_F, count)
    seeds = _seed_unmatched_parts(labels, known, matches.distances)
    if len(seeds):
        status[np.isin(labels, labels[seeds]) & ~known] = VertexStatus.UNMATCHED_PART
        known[seeds] = True
    Q = inpainting_operator(welded_V, welded_F)
    timings["system"] = time.perf_counter() - clock
    report(progress, 0.5, "Inpainting weights")

    clock = time.perf_counter()
    solved = normalize_rows(inpaint_weights(Q, known, known_weights))
    empty = ~(solved.sum(axis=1) > 0)
    solved[empty] = matches.weights[empty]
    solved = smooth_over_edges(solved, welded_F, options.smoothing_iterations, options.smoothing_strength, rows=~known)
    solved = prune_small(limit_influences(solved, options.max_influences))
    timings["inpaint"] = time.perf_counter() - clock
    report(progress, 0.9, "Writing results")

    clock = time.perf_counter()
    weights = solved[to_welded]
    if protected.any():
        weights[protected] = kept[protected]
    timings["finish"] = time.perf_counter() - clock
    report(progress, 1.0, "Done")
    return TransferResult(
        Weights(weights, source_weights.bone_names), status[to_welded], float(max_distance), timings,
        welded_vertices=n - count, non_manifold_edges=non_manifold_edge_count(welded_F),
    )


def _check_inputs(source: Mesh, source_weights: Weights, target: Mesh, options: TransferOptions) -> None:
    if not len(source.triangles):
        raise InputError(f"The source '{source.object_names[0]}' has no faces; weights are transferred from a surface.")
    if not len(target.triangles):
        raise InputError(f"The target '{target.object_names[0]}' has no faces; it needs a surface to inpaint over.")
    if source_weights.vertex_count != source.vertex_count:
        raise InputError("The source weights do not have one row per source vertex.")
    check_weights(source_weights.matrix, "source weights")
    if not source_weights.bone_names or not np.any(source_weights.matrix > 0):
        raise InputError(f"The source '{source.object_names[0]}' carries no bone weights to transfer.")
    if not (options.max_normal_angle > 0 and options.max_normal_angle <= 180):
        raise InputError("The normal angle must lie in (0, 180] degrees.")
    if options.max_distance is None and not options.distance_fraction > 0:
        raise InputError("The match distance must be positive.")
    if options.max_distance is not None and not options.max_distance > 0:
        raise InputError("The match distance must be positive.")
    if not 0.0 <= options.smoothing_strength <= 1.0:
        raise InputError("Smoothing strength must lie in [0, 1].")
    if not (np.all(np.isfinite(source.vertices)) and np.all(np.isfinite(target.vertices))):
        raise InputError("A mesh has NaN or infinite vertex positions.")
    source_diagonal, target_diagonal = source.bounding_box_diagonal, target.bounding_box_diagonal
    if target_diagonal <= 0:
        raise InputError(f"The target '{target.object_names[0]}' has zero size.")
    if target_diagonal > MAX_SCALE_RATIO * source_diagonal:
        raise InputError(
            f"The target is {target_diagonal / max(source_diagonal, 1e-300):.0f} times larger than the source: "
            "the objects look like they are at different scales. Apply their scale (Ctrl+A) or fix the units."
        )
    margin = options.distance_fraction * target_diagonal if options.max_distance is None else options.max_distance
    source_min, source_max = source.vertices.min(0) - margin, source.vertices.max(0) + margin
    target_min, target_max = target.vertices.min(0), target.vertices.max(0)
    if np.any(target_min > source_max) or np.any(target_max < source_min):
        raise InputError(
            f"'{target.object_names[0]}' does not overlap the source '{source.object_names[0]}': "
            "move the garment onto the body (or apply the object transforms) before transferring."
        )


def _optional_mask(mask: np.ndarray | None, n: int, what: str) -> np.ndarray:
    if mask is None:
        return np.zeros(n, dtype=bool)
    mask = np.asarray(mask, dtype=bool).reshape(-1)
    if len(mask) != n:
        raise InputError(f"The {what} has {len(mask)} entries for {n} target vertices.")
    return mask


def _any_copy(mask: np.ndarray, to_welded: np.ndarray, count: int) -> np.ndarray:
    """(count,) bool: welded vertices with at least one original copy in ``mask``."""
    out = np.zeros(count, dtype=bool)
    out[to_welded[mask]] = True
    return out


def _mean_over_copies(rows: np.ndarray, mask: np.ndarray, to_welded: np.ndarray, count: int) -> np.ndarray:
    """(count, b): mean of ``rows`` over the original copies in ``mask`` of each welded vertex."""
    sums = np.zeros((count, rows.shape[1]))
    np.add.at(sums, to_welded[mask], rows[mask])
    return normalize_rows(sums)


def _seed_unmatched_parts(labels: np.ndarray, known: np.ndarray, distances: np.ndarray) -> np.ndarray:
    """For each connected part with no known vertex, its vertex closest to
    the source: fixing it there makes the part follow that point rigidly."""
    has_known = np.zeros(labels.max() + 1, dtype=bool)
    has_known[labels[known]] = True
    candidates = np.flatnonzero(~has_known[labels])
    if not len(candidates):
        return np.zeros(0, dtype=np.int64)
    ordered = candidates[np.lexsort((distances[candidates], labels[candidates]))]
    first = np.ones(len(ordered), dtype=bool)
    first[1:] = labels[ordered][1:] != labels[ordered][:-1]
    return ordered[first]
