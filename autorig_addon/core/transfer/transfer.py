"""Robust skin weight transfer (Abdrashitov et al., SIGGRAPH Asia 2023).

Two stages, and two of ours:

1. **Matching** (:mod:`.matching`). Each target vertex looks up the closest
   point on the source surface. Its weights are copied (barycentric
   interpolation) only when the point is closer than ``D`` and the normals
   agree within an angle; a second pass accepts opposite normals, for inner
   garment layers.
2. **Inpainting** (:mod:`.inpainting`). The remaining weights minimise
   ``trace(W^T Q W)`` with ``Q = -L + L M^-1 L`` (cotangent Laplacian ``L``,
   lumped Voronoi mass ``M``) with the matched rows fixed, i.e.
   ``Q_UU W_U = -Q_UI W_I``, one sparse factorisation for every bone.
3. **Smoothing** (:func:`~autorig_addon.core.geometry.smoothing.smooth_over_surface`).
   Every row, copied or inpainted, takes one implicit heat-diffusion step
   whose reach is ``smoothing_length`` times the source's size (1 cm on a
   2 m body by default): the body's weights change abruptly from one bone
   to the next (toes, spine segments) and cloth copying them stretches
   where they do. Measured against the published implementation, which
   smooths the inpainted band by uniform passes, this gives less stretch
   for less deformation error (docs/transfer.md).
4. **A rigid accessory** (:func:`rigid_accessory_bone`). A target whose
   weights lie mostly on one bone (a hat on the head, a bracer on a forearm),
   as skinning judges loose parts (:mod:`..skinning.rigid_parts`), and that
   touches the body only where the body's weights lie mostly on that bone,
   is bound wholly to it: the rest is the blur at its edge (a hat's brim
   reaching toward the neck), which bent it when the head turned.

This module runs them: beyond the paper, seams are welded before inpainting
(glTF and FBX split vertices at UV seams, which would cut the Laplacian into
patches); parts of the target with no match at all are seeded at their
closest point so they move rigidly with the body; an artist mask forces
inpainting and a protected set keeps existing weights as fixed rows.

Bad input: source vertices without usable weights (none, NaN, infinite or
negative) never make a match and the summary counts the vertices inpainted
near them; a transfer that would mostly guess (few copies, another unit
scale fitting much better, copies far from the body) is refused by
:func:`check_match_quality` unless ``allow_poor_match``; and no returned row
is ever empty or unnormalised (checked before returning).
"""

from __future__ import annotations

import enum
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry.laplacian import surface_operators
from ..geometry.normals import vertex_normals
from ..geometry.outliers import require_finite_positions
from ..geometry.smoothing import smooth_over_edges, smooth_over_surface
from ..geometry.topology import connected_component_labels, non_manifold_edge_count
from ..geometry.weld import weld_mesh
from ..progress import ProgressCallback, report
from ..skinning.rigid_parts import RIGID_SHARE, dominant_bones
from ..types import Mesh, Weights
from ..weights import empty_rows, limit_influences, normalize_rows, prune_small
from .inpainting import inpaint_weights, inpainting_operator
from .matching import Matches, UnitFactor, likely_unit_factor, match_closest_points
from .options import MAX_SMOOTHING_LENGTH, MIN_SMOOTHING_LENGTH, TransferOptions
from .source import TransferSource, prepared_source

#: A target larger than this many source diagonals is taken as a unit mismatch.
MAX_SCALE_RATIO = 5.0
#: Unless poor matches are allowed, a transfer is refused when fewer than this
#: share of the target's vertices (those neither masked nor protected) copy
#: weights: the rest would be guessed by inpainting (a unit mix-up, a garment
#: off the body, or a body weighted only elsewhere).
MIN_COPIED_SHARE = 0.1
#: When fewer than this share copy, the transfer is also refused if the target
#: would fit the source much better at another unit scale
#: (:func:`.matching.likely_unit_factor`): a garment at 2.54 times the body's
#: scale still copies a little where it crosses the body.
UNIT_CHECK_SHARE = 0.5
#: Unless poor matches are allowed, a transfer is refused when the copied
#: vertices lie farther from the source surface than this fraction of the
#: source's bounding-box diagonal (median): a garment matched to a body it is
#: not on, after the match distance was raised.
MAX_MEDIAN_MATCH_FRACTION = 0.1
#: How a refusal for a poor match tells the user to transfer anyway: the
#: ``allow_poor_match`` option, in the panel and on the command line.
ALLOW_POOR_MATCH_HINT = "To transfer anyway, turn on Allow Poor Match (--allow-poor-match on the command line)."
#: Largest difference from one of a written row's sum (rows are normalised in float64).
ROW_SUM_TOLERANCE = 1e-6


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
    source_name : str, the source's (first) object, for the summary
    unweighted_source_vertices : int, source vertices without usable weights
        (no weight, or NaN, infinite or negative entries)
    invalid_source_vertices : int, those of them with NaN, infinite or negative entries
    near_unweighted : int, target vertices that would have copied weights
        but whose closest source point has none usable: inpainted instead
    unprotected : int, protected vertices with no weight to keep on the
        source's bones: they were transferred instead
    rigid_bone : str, the bone the target was bound wholly to as a rigid
        accessory (:func:`rigid_accessory_bone`); "" when it was not
    """

    weights: Weights
    status: np.ndarray
    max_distance: float
    timings: dict = field(default_factory=dict)
    welded_vertices: int = 0
    non_manifold_edges: int = 0
    source_name: str = "source"
    unweighted_source_vertices: int = 0
    invalid_source_vertices: int = 0
    near_unweighted: int = 0
    unprotected: int = 0
    rigid_bone: str = ""

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
        if self.near_unweighted:
            invalid = (f" ({self.invalid_source_vertices} with NaN, infinite or negative weights)"
                       if self.invalid_source_vertices else "")
            parts.append(f"{self.unweighted_source_vertices} vertices of '{self.source_name}' have no usable "
                         f"weight{invalid}; {self.near_unweighted} vertices near them were inpainted")
        if self.unprotected:
            parts.append(f"{self.unprotected} protected vertices had no weight to keep and were transferred")
        if self.rigid_bone:
            parts.append(f"bound wholly to bone '{self.rigid_bone}' (a rigid accessory: {RIGID_SHARE:.0%} or more of "
                         "its weight lay there)")
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
    prepared: TransferSource | None = None,
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
    prepared : TransferSource made from these ``source`` and
        ``source_weights`` objects (:meth:`TransferSource.prepare`), to
        reuse its checks and index over many targets; made here when None

    Returns
    -------
    TransferResult; raises :class:`InputError` on unusable input.
    """
    timings: dict[str, float] = {}
    clock = time.perf_counter()
    if not len(target.triangles):
        raise InputError(f"The target '{target.object_names[0]}' has no faces; it needs a surface to inpaint over.")
    source = prepared_source(source, source_weights, prepared)
    timings["source"] = time.perf_counter() - clock
    clock = time.perf_counter()
    _check_inputs(source, target, options)
    n = target.vertex_count
    inpaint_mask = _optional_mask(inpaint_mask, n, "inpaint mask")
    protected = _optional_mask(protected, n, "protected set")
    if protected.any() and protected_weights is None:
        raise InputError("Protected vertices were given without their weights.")
    if protected.any():
        kept = normalize_rows(protected_weights.select_bones(source_weights.bone_names).matrix)
        # A protected vertex with nothing to keep would be written empty: transfer it.
        unprotected = protected & empty_rows(kept)
        protected = protected & ~unprotected
    else:
        unprotected = protected

    target_diagonal = target.bounding_box_diagonal
    max_distance = (options.max_distance if options.max_distance is not None
                    else options.distance_fraction * target_diagonal)
    # Everything runs on the welded mesh (seams joined) and is expanded at the end.
    welded, to_welded = weld_mesh(target)
    welded_V, welded_F, count = welded.vertices, welded.triangles, welded.vertex_count
    masked = _any_copy(inpaint_mask, to_welded, count)
    protected_welded = _any_copy(protected, to_welded, count)
    timings["prepare"] = time.perf_counter() - clock
    report(progress, 0.05, "Matching closest points")

    clock = time.perf_counter()
    welded_normals = vertex_normals(welded_V, welded_F)
    matches = match_closest_points(
        source, welded, welded_normals, max_distance, options.max_normal_angle, options.accept_flipped_normals,
    )
    timings["match"] = time.perf_counter() - clock
    matched = matches.matched
    if not matched.any() and not protected.any() and not options.allow_poor_match:
        raise InputError(_no_match_message(source, welded, welded_normals, matches, max_distance, options))
    if not options.allow_poor_match:
        clock = time.perf_counter()
        check_match_quality(source, welded, welded_normals, matches, ~masked & ~protected_welded, max_distance, options)
        timings["check"] = time.perf_counter() - clock
    report(progress, 0.35, "Building the inpainting system")

    clock = time.perf_counter()
    status = np.full(count, VertexStatus.INPAINTED, dtype=np.int8)
    status[matched] = VertexStatus.COPIED
    status[matches.flipped] = VertexStatus.COPIED_FLIPPED
    status[masked] = VertexStatus.MASKED
    known = matched & ~masked
    # Only bones that weigh somewhere here are solved for and carried to the end.
    weighing = matches.weights.any(axis=0)
    if protected.any():
        weighing |= kept[protected].any(axis=0)
    bones = np.flatnonzero(weighing)
    fallback = matches.weights[:, bones]
    known_weights = fallback.copy()
    if protected.any():
        known_weights[protected_welded] = _mean_over_copies(
            kept[:, bones], protected, to_welded, count)[protected_welded]
        known |= protected_welded
        status[protected_welded] = VertexStatus.PROTECTED
    labels = connected_component_labels(welded_F, count)
    seeds = _seed_unmatched_parts(labels, known, matches.distances)
    if len(seeds):
        status[np.isin(labels, labels[seeds]) & ~known] = VertexStatus.UNMATCHED_PART
        known[seeds] = True
    operators = surface_operators(welded_V, welded_F)
    Q = inpainting_operator(welded_V, welded_F, operators)
    timings["system"] = time.perf_counter() - clock
    report(progress, 0.5, "Inpainting weights")

    clock = time.perf_counter()
    solved = normalize_rows(inpaint_weights(Q, known, known_weights))
    empty = ~(solved.sum(axis=1) > 0)
    solved[empty] = fallback[empty]
    timings["inpaint"] = time.perf_counter() - clock
    report(progress, 0.75, "Smoothing weights")

    clock = time.perf_counter()
    # Rows stay summing to one; limit_influences below clamps the slight dips
    # that non-Delaunay edges can give and renormalises.
    solved = smooth_over_surface(
        solved, welded_V, welded_F, options.smoothing_length * source.diagonal, fixed=protected_welded,
        operators=operators,
    )
    solved = smooth_over_edges(solved, welded_F, options.smoothing_iterations, options.smoothing_strength, rows=~known)
    solved = prune_small(limit_influences(solved, options.max_influences))
    copied = (status == VertexStatus.COPIED) | (status == VertexStatus.COPIED_FLIPPED)
    rigid = None
    if options.rigid_accessory:
        rigid = rigid_accessory_bone(solved, operators.mass, ~protected_welded, copied, fallback)
    if rigid is not None:
        solved[~protected_welded] = 0.0
        solved[~protected_welded, rigid] = 1.0
    timings["smooth"] = time.perf_counter() - clock
    report(progress, 0.9, "Writing results")

    clock = time.perf_counter()
    _require_normalised_rows(solved)
    welded_weights = np.zeros((count, len(source_weights.bone_names)))
    welded_weights[:, bones] = solved
    weights = welded_weights[to_welded]
    if protected.any():
        weights[protected] = kept[protected]
    near_unweighted = matches.unweighted[to_welded] & (status[to_welded] != VertexStatus.MASKED) & ~protected
    timings["finish"] = time.perf_counter() - clock
    report(progress, 1.0, "Done")
    return TransferResult(
        Weights(weights, source_weights.bone_names), status[to_welded], float(max_distance), timings,
        welded_vertices=n - count, non_manifold_edges=non_manifold_edge_count(welded_F),
        source_name=source.name,
        unweighted_source_vertices=int(np.count_nonzero(~source.usable)),
        invalid_source_vertices=source.invalid_count,
        near_unweighted=int(np.count_nonzero(near_unweighted)),
        unprotected=int(np.count_nonzero(unprotected)),
        rigid_bone=source_weights.bone_names[bones[rigid]] if rigid is not None else "",
    )


def rigid_accessory_bone(weights: np.ndarray, areas: np.ndarray, rows: np.ndarray, copied: np.ndarray,
                         body_weights: np.ndarray) -> int | None:
    """The bone (column of ``weights``, (n, b), rows summing to one) a
    target is bound wholly to as a rigid accessory, or None.

    It is the bone holding at least :data:`..skinning.rigid_parts.RIGID_SHARE`
    of the weight of the ``rows`` ((n,) bool: the vertices being transferred,
    not protected), each counted by its area (``areas``, (n,)), when no row
    ``copied`` from the body ((n,) bool) had more of ``body_weights`` (the
    body's, (n, b), as matched, before inpainting and smoothing) on another
    bone: where the target touches the body, the body says it all belongs
    to that bone, and the rest of its weight is what the inpainting and
    smoothing spread (the fedora's brim). None too when no row is
    transferred or they lie wholly on the bone already (nothing to bind).

    Artists bind a hat, a helmet or a bracer wholly to one bone. A head of
    its own with its neck (Quaternius' modular characters: 92 to 99 % head)
    reaches across the neck joint, and copies the neck's weights there: it
    bends. Only the target as a whole is judged: a small part sewn on cloth
    (a shoe's eyelets, a button) follows the cloth under it, and bound
    rigidly to one bone it parts from it (on the makehuman shoes03, its 8
    eyelet parts so bound raise the deformation error from 0.0461 to 0.0477 %
    of the body's height).
    """
    if not rows.any():
        return None
    bone = int(dominant_bones(np.zeros(int(rows.sum()), dtype=np.int64), weights[rows], areas[rows])[0])
    if bone < 0 or np.all(weights[rows, bone] == 1.0):
        return None
    touching = rows & copied
    if np.any(body_weights[touching, bone] < body_weights[touching].max(axis=1)):
        return None
    return bone


def check_match_quality(source: TransferSource, target: Mesh, target_normals: np.ndarray, matches: Matches,
                        eligible: np.ndarray, max_distance: float, options: TransferOptions) -> None:
    """Refuse a transfer that would mostly guess: fewer than
    :data:`MIN_COPIED_SHARE` of the ``eligible`` target vertices copy
    weights, or fewer than :data:`UNIT_CHECK_SHARE` while another unit scale
    fits much better, or the copied ones lie farther than
    :data:`MAX_MEDIAN_MATCH_FRACTION` of the source's size from it (median).

    The message gives the reason, the likely cause (:func:`poor_match_cause`)
    and how to transfer anyway (``options.allow_poor_match``).

    Parameters
    ----------
    source : TransferSource
    target : Mesh, welded as matched
    target_normals : (n, 3) float64 array, unit normals of the target's vertices
    matches : Matches of the target's vertices
    eligible : (n,) bool array, vertices that may copy (neither masked nor protected)
    max_distance : float, the match distance used, scene units
    options : TransferOptions
    """
    candidates = int(np.count_nonzero(eligible))
    copied = matches.matched & eligible
    if not candidates:
        return
    source_name, target_name = source.name, target.object_names[0]
    share = np.count_nonzero(copied) / candidates
    reason = (
        f"Only {100.0 * share:.0f}% of '{target_name}' ({np.count_nonzero(copied)} of {candidates} vertices) "
        f"lies within {max_distance:.3g} of '{source_name}' with agreeing normals on weighted parts; "
        "the rest would be guessed by inpainting."
    )
    if share < MIN_COPIED_SHARE:
        cause = poor_match_cause(source, target, target_normals, matches, eligible, max_distance, options)
        raise InputError(f"{reason} {cause} {ALLOW_POOR_MATCH_HINT}")
    if share < UNIT_CHECK_SHARE:
        factor = _unit_factor(source, target, target_normals, options)
        if factor is not None:
            raise InputError(f"{reason} {_unit_cause(factor, source, target)} {ALLOW_POOR_MATCH_HINT}")
    median = float(np.median(matches.distances[copied]))
    source_size = source.diagonal
    if median > MAX_MEDIAN_MATCH_FRACTION * source_size:
        raise InputError(
            f"'{target_name}' would copy weights from points of '{source_name}' {median:.3g} away (median), "
            f"{median / source_size:.3g} times the size of '{source_name}': it is not on the body "
            f"(match distance {max_distance:.3g}). Move it onto the body or lower the match distance. "
            f"{ALLOW_POOR_MATCH_HINT}"
        )


def poor_match_cause(source: TransferSource, target: Mesh, target_normals: np.ndarray, matches: Matches,
                     eligible: np.ndarray, max_distance: float, options: TransferOptions) -> str:
    """Why few of the ``eligible`` vertices copy, as a sentence for the user,
    the surest cause first: another unit scale fits much better, most of
    them lie over parts of the body without weights, their normals disagree,
    or (otherwise) the objects are apart."""
    factor = _unit_factor(source, target, target_normals, options)
    if factor is not None:
        return _unit_cause(factor, source, target)
    source_name = source.name
    copied = np.count_nonzero(matches.matched & eligible)
    unweighted = np.count_nonzero(matches.unweighted & eligible)
    if unweighted > copied:
        return (f"{unweighted} of its vertices lie over parts of '{source_name}' without usable weights: "
                "weight those parts of the body first.")
    turned = np.count_nonzero((matches.distances <= max_distance) & eligible) - copied - unweighted
    if turned > copied:
        flipped = "" if options.accept_flipped_normals else ", turn on Flipped Normals"
        return (f"{turned} of its vertices lie that near but their normals differ from the body's by more than "
                f"{options.max_normal_angle:g} degrees: recalculate the normals (Shift+N){flipped} or raise the "
                "normal angle.")
    return ("Are the objects far apart or at different scales? Apply their transforms (Ctrl+A) "
            "or raise the match distance.")


def _unit_factor(source: TransferSource, target: Mesh, target_normals: np.ndarray,
                 options: TransferOptions) -> UnitFactor | None:
    return likely_unit_factor(source, target, target_normals, options.distance_fraction,
                              options.max_normal_angle, options.accept_flipped_normals)


def _unit_cause(factor: UnitFactor, source: TransferSource, target: Mesh) -> str:
    return (f"{factor.describe(target.object_names[0], source.name)} "
            "Fix the units or the object scale, then apply it (Ctrl+A).")


def _no_match_message(source: TransferSource, target: Mesh, target_normals: np.ndarray, matches: Matches,
                      max_distance: float, options: TransferOptions) -> str:
    everything = np.ones(len(matches.matched), dtype=bool)
    cause = poor_match_cause(source, target, target_normals, matches, everything, max_distance, options)
    return (f"No vertex of '{target.object_names[0]}' lies within {max_distance:.4g} of "
            f"'{source.name}' with agreeing normals on weighted parts. {cause} {ALLOW_POOR_MATCH_HINT}")


def _require_normalised_rows(weights: np.ndarray) -> None:
    """Raise AssertionError unless every row is finite, non-negative and sums
    to one: a transfer never writes an empty or unnormalised row (a bug if it
    would, so not an :class:`InputError`)."""
    sums = weights.sum(axis=1)
    bad = ~(np.all(np.isfinite(weights) & (weights >= 0.0), axis=1) & (np.abs(sums - 1.0) <= ROW_SUM_TOLERANCE))
    if bad.any():
        raise AssertionError(f"Transfer produced {np.count_nonzero(bad)} empty or unnormalised rows "
                             f"(first: vertex {int(np.flatnonzero(bad)[0])}).")


def _check_inputs(source: TransferSource, target: Mesh, options: TransferOptions) -> None:
    """Raise :class:`InputError` for unusable options or a target that
    cannot be on the source (the source is checked by :meth:`TransferSource.prepare`)."""
    if not (options.max_normal_angle > 0 and options.max_normal_angle <= 180):
        raise InputError("The normal angle must lie in (0, 180] degrees.")
    if options.max_distance is None and not options.distance_fraction > 0:
        raise InputError("The match distance must be positive.")
    if options.max_distance is not None and not options.max_distance > 0:
        raise InputError("The match distance must be positive.")
    if not 0.0 <= options.smoothing_strength <= 1.0:
        raise InputError("Smoothing strength must lie in [0, 1].")
    # Compared in single precision, the panel's: its largest value, 0.05 as
    # a float32, is 0.0500000007.
    if not np.float32(MIN_SMOOTHING_LENGTH) <= np.float32(options.smoothing_length) <= np.float32(MAX_SMOOTHING_LENGTH):
        raise InputError(f"The smoothing length must lie in [{MIN_SMOOTHING_LENGTH:g}, {MAX_SMOOTHING_LENGTH:g}] "
                         "(a fraction of the source's size).")
    require_finite_positions(target.vertices, target.object_names, target.object_offsets)
    source_name, target_name = source.name, target.object_names[0]
    source_diagonal, target_diagonal = source.diagonal, target.bounding_box_diagonal
    if target_diagonal <= 0:
        raise InputError(f"The target '{target_name}' has zero size.")
    if target_diagonal > MAX_SCALE_RATIO * source_diagonal:
        factor = _unit_factor(source, target, vertex_normals(target.vertices, target.triangles), options)
        raise InputError(
            f"The target '{target_name}' is {target_diagonal / max(source_diagonal, 1e-300):.3g} times "
            f"larger than the source '{source_name}': they look like they are at different scales. "
            + (_unit_cause(factor, source, target) if factor is not None else
               "Apply their scale (Ctrl+A) or fix the units.")
        )
    margin = options.distance_fraction * target_diagonal if options.max_distance is None else options.max_distance
    source_vertices = source.mesh.vertices
    source_min, source_max = source_vertices.min(0) - margin, source_vertices.max(0) + margin
    target_min, target_max = target.vertices.min(0), target.vertices.max(0)
    if np.any(target_min > source_max) or np.any(target_max < source_min):
        raise InputError(
            f"'{target_name}' does not overlap the source '{source_name}': "
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
