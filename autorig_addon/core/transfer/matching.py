"""Closest-point matching of target vertices onto a skinned source surface.

Stage 1 of robust weight transfer (Abdrashitov et al. 2023, section 3.1):
each target vertex takes the source weights at its closest point on the
source surface (barycentric interpolation, not the nearest vertex, which
picks the wrong side of a coarse body), and counts as matched only when
that point is near, the normals agree and the point carries weight.

Source vertices whose weights are unusable (none, or NaN, infinite or
negative entries: :func:`~autorig_addon.core.weights.usable_rows`) never
make a match: a target vertex whose closest point draws on them is left to
the inpainting, and its fallback row is that of the nearest source vertex
with usable weights, so no row is ever empty.

:func:`likely_unit_factor` tells, when little matches, whether the target
would fit the source at another unit scale (2.54, 100, ...) or at another
uniform scale (a wrong object scale: 1.8).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.bounding_box import bounding_box_diagonal
from ..types import Mesh, Weights
from .source import TransferSource

#: Scale factors a unit mix-up gives, target size over the size it should
#: have, with the units that differ by it; each is tried with its inverse.
UNIT_FACTORS = {
    2.54: "inches and centimetres",
    10.0: "millimetres and centimetres",
    100.0: "centimetres and metres",
    1000.0: "millimetres and metres",
    3.28084: "feet and metres",
    39.3701: "inches and metres",
}
#: Target vertices sampled when trying the unit factors (evenly spread over the vertex order).
UNIT_FACTOR_SAMPLES = 256
#: A unit factor is named only when, scaled by it, at least this share of the
#: sampled target vertices lies within the match distance of the source ...
UNIT_FACTOR_MIN_NEAR_SHARE = 0.5
#: ... and at least this many times the share that does at the current scale.
UNIT_FACTOR_MIN_GAIN = 2.0
#: Other uniform scales (a wrong object scale) are searched from this factor
#: away from 1 (a loose garment, 1.05, is never one) ...
OTHER_SCALE_MIN = 1.25
#: ... up to this one (farther, the unit factors or the size check answer) ...
OTHER_SCALE_MAX = 20.0
#: ... first in steps of this ratio, then around the best in steps of :data:`OTHER_SCALE_FINE_STEP`.
OTHER_SCALE_STEP = 1.08
OTHER_SCALE_FINE_STEP = 1.01
#: Scales whose share lies within this of the best fit about as well.
OTHER_SCALE_SHARE_TOLERANCE = 0.02
#: The wording of a scale that is no unit factor.
OTHER_SCALE_UNITS = ""


@dataclass(frozen=True)
class Matches:
    """Closest-point matching of target vertices onto the source.

    Attributes
    ----------
    weights : (n, b) float64 array, rows normalised and never empty: the
        source weights at the closest point where it carries usable weight,
        else those of the nearest source vertex that does
    distances : (n,) float64 array, distance to the closest point, scene units
    matched : (n,) bool array, near enough with agreeing (or, where allowed,
        opposite) normals, on weighted source: these weights can be copied
    flipped : (n,) bool array, matched through opposite normals (a subset of ``matched``)
    unweighted : (n,) bool array, near with agreeing normals but the closest
        point lies on source vertices without usable weights (not matched)
    """

    weights: np.ndarray
    distances: np.ndarray
    matched: np.ndarray
    flipped: np.ndarray
    unweighted: np.ndarray


def closest_point_weights(source: Mesh, source_weights: Weights, target: Mesh) -> Weights:
    """Every target vertex takes the source weights at its closest source
    surface point: plain copying, the baseline robust transfer improves on.

    Parameters
    ----------
    source : Mesh with n_s vertices and at least one triangle
    source_weights : Weights, (n_s, b), some row usable
    target : Mesh with n vertices

    Returns
    -------
    Weights, (n, b), rows normalised, bones as in ``source_weights``
    (where the closest point has no usable weight, the nearest weighted
    source vertex's)
    """
    prepared = TransferSource.prepare(source, source_weights)
    weights, _ = prepared.weights_at(prepared.query.closest(target.vertices), target.vertices)
    return Weights(weights, source_weights.bone_names)


def match_closest_points(
    source: TransferSource, target: Mesh, target_normals: np.ndarray,
    max_distance: float, max_normal_angle: float, accept_flipped_normals: bool,
) -> Matches:
    """Match target vertices whose closest source point is near, carries
    usable weight and has a normal agreeing with the target's.

    Parameters
    ----------
    source : TransferSource; rows without usable weights never match
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
    surface = source.query.closest(target.vertices)
    weights, weighted = source.weights_at(surface, target.vertices)
    candidate, flipped = _agreeing(surface.distances, source.interpolated_normals(surface), target_normals,
                                   max_distance, max_normal_angle, accept_flipped_normals)
    return Matches(weights, surface.distances, candidate & weighted, flipped & weighted, candidate & ~weighted)


def _agreeing(distances: np.ndarray, source_normals: np.ndarray, target_normals: np.ndarray, max_distance,
              max_normal_angle: float, accept_flipped_normals: bool) -> tuple[np.ndarray, np.ndarray]:
    """(q,) bool arrays: closest points within ``max_distance`` (a float, or
    one per point) whose interpolated source normal agrees with the (q, 3)
    ``target_normals`` (directly or, where accepted, opposite), and those
    that agree only through opposite normals."""
    length = np.linalg.norm(source_normals, axis=1)
    cosine = np.einsum("ij,ij->i", source_normals, target_normals) / np.maximum(length, 1e-300)
    cosine[length == 0] = 0.0
    cos_limit = np.cos(np.radians(max_normal_angle))
    near = distances <= max_distance
    flipped = near & (cosine <= -cos_limit) if accept_flipped_normals else np.zeros(len(near), dtype=bool)
    return (near & (cosine >= cos_limit)) | flipped, flipped


@dataclass(frozen=True)
class UnitFactor:
    """A unit scale at which the target would fit the source.

    Attributes
    ----------
    factor : float, the target's size over the size it should have (> 1: too large)
    units : str, the units that differ by this factor ("inches and centimetres"),
        empty for a scale no unit mix-up gives (a wrong object scale, 1.8)
    near_share : float in [0, 1], share of the sampled target vertices that
        would match (near, normals agreeing) once scaled by ``1 / factor``
    """

    factor: float
    units: str
    near_share: float

    def describe(self, target_name: str, source_name: str) -> str:
        """E.g. "'Skirt' looks 2.54 times too large for 'Body' (inches and
        centimetres mixed up?): scaled by 1/2.54, 96% of it would match the body.",
        or "'Dress' looks 1.8 times too large for 'Body' (a wrong object
        scale?): scaled by 1/1.8, 90% of it would match the body."."""
        size = max(self.factor, 1.0 / self.factor)
        large = self.factor > 1.0
        digits = ".4g" if self.units else ".3g"
        scale = f"1/{size:{digits}}" if large else f"{size:{digits}}"
        cause = f"{self.units} mixed up?" if self.units else "a wrong object scale?"
        return (f"'{target_name}' looks {size:{digits}} times too {'large' if large else 'small'} for "
                f"'{source_name}' ({cause}): scaled by {scale}, {100.0 * self.near_share:.0f}% of it would match "
                "the body.")


def likely_unit_factor(source: TransferSource, target: Mesh, target_normals: np.ndarray, distance_fraction: float,
                       max_normal_angle: float, accept_flipped_normals: bool) -> UnitFactor | None:
    """The unit factor, else the other uniform scale, at which ``target``
    best fits ``source``, if one fits much better than the current scale.

    Each factor of :data:`UNIT_FACTORS` and its inverse scales a sample of
    the target's vertices about the world origin (a file in other units)
    and about the target's own centre (a wrong object scale); a scale fits
    as well as the share of scaled vertices that would match: within
    ``distance_fraction`` of the scaled target's diagonal of the source
    surface, normals agreeing (a uniform scale keeps the normals).

    When no unit factor fits, other scales from :data:`OTHER_SCALE_MIN` to
    :data:`OTHER_SCALE_MAX` (and their inverses) are searched the same way,
    about the origin, the target's centre and the source's centre: a grid
    of ratio :data:`OTHER_SCALE_STEP`, then a finer one around the best,
    whose best-fitting range gives the factor named.

    Parameters
    ----------
    source : TransferSource
    target : Mesh, world space, finite
    target_normals : (n, 3) float64 array, unit normals of the target's vertices
    distance_fraction : float > 0, match distance as a fraction of the target's diagonal
    max_normal_angle : float, degrees; accept_flipped_normals : bool, as for :func:`match_closest_points`

    Returns
    -------
    UnitFactor, or None when no factor reaches :data:`UNIT_FACTOR_MIN_NEAR_SHARE`
    and :data:`UNIT_FACTOR_MIN_GAIN` times the current share.
    """
    picked = np.unique(np.linspace(0, target.vertex_count - 1, UNIT_FACTOR_SAMPLES).astype(np.int64))
    sample, normals = target.vertices[picked], target_normals[picked]
    match_distance = distance_fraction * bounding_box_diagonal(target.vertices)

    def match_shares(points: np.ndarray, distances: np.ndarray, near: np.ndarray) -> np.ndarray:
        """Share of each block of ``len(sample)`` scaled samples that would
        match, in one query; ``near``: the points not surely too far."""
        surface = source.query.closest(points[near])
        matched = np.zeros(len(points), dtype=bool)
        matched[near], _ = _agreeing(surface.distances, source.interpolated_normals(surface),
                                     np.tile(normals, (len(points) // len(sample), 1))[near], distances[near],
                                     max_normal_angle, accept_flipped_normals)
        return matched.reshape(-1, len(sample)).mean(axis=1)

    current_distances = np.full(len(sample), match_distance)
    current = float(match_shares(sample, current_distances,
                                 ~source.query.surely_farther(sample, current_distances))[0])
    needed = max(UNIT_FACTOR_MIN_NEAR_SHARE, UNIT_FACTOR_MIN_GAIN * current)
    if needed > 1.0:
        return None  # no scale can match twice as many
    centre = 0.5 * (target.vertices.min(axis=0) + target.vertices.max(axis=0))

    def best_of(trials: list[tuple[float, str, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
        """Indices of the ``trials`` (factor, units, pivot) that could reach
        the share needed, and their shares."""
        points = np.concatenate([pivot + (sample - pivot) / factor for factor, _, pivot in trials])
        distances = np.repeat([match_distance / factor for factor, _, _ in trials], len(sample))
        near = ~source.query.surely_farther(points, distances)
        # A scale whose samples mostly lie surely too far cannot reach the
        # share needed: only the others take the exact test.
        hopeful = np.flatnonzero(near.reshape(len(trials), len(sample)).mean(axis=1) >= needed)
        if not len(hopeful):
            return hopeful, np.zeros(0)
        rows = (hopeful[:, None] * len(sample) + np.arange(len(sample))).ravel()
        return hopeful, match_shares(points[rows], distances[rows], near[rows])

    trials = [(factor, units, pivot) for base, units in UNIT_FACTORS.items()
              for factor in (base, 1.0 / base) for pivot in (np.zeros(3), centre)]
    hopeful, shares = best_of(trials)
    if len(hopeful) and shares.max() >= needed:
        factor, units, _ = trials[hopeful[int(np.argmax(shares))]]
        return UnitFactor(factor, units, float(shares.max()))
    source_centre = 0.5 * (source.mesh.vertices.min(axis=0) + source.mesh.vertices.max(axis=0))
    return _other_scale(best_of, needed, (np.zeros(3), centre, source_centre))


def _other_scale(best_of, needed: float, pivots) -> UnitFactor | None:
    """The uniform scale, no unit factor, that fits best (see
    :func:`likely_unit_factor`), if it reaches the share ``needed``."""
    steps = int(np.ceil(np.log(OTHER_SCALE_MAX / OTHER_SCALE_MIN) / np.log(OTHER_SCALE_STEP)))
    sizes = OTHER_SCALE_MIN * OTHER_SCALE_STEP ** np.arange(steps + 1)
    trials = [(factor, OTHER_SCALE_UNITS, pivot) for size in sizes for factor in (size, 1.0 / size)
              for pivot in pivots]
    hopeful, shares = best_of(trials)
    if not len(hopeful) or shares.max() < needed:
        return None
    # Many scales fit a garment close to the body about as well (its
    # distance from the body allows some): the middle, in log scale, of the
    # run of scales about the best one's pivot that fit about as well as it
    # is the factor named, refined on a finer grid.
    chosen = hopeful[int(np.argmax(shares))]
    side = 1.0 if trials[chosen][0] > 1.0 else -1.0
    pivot_index = chosen % len(pivots)
    good = {int(i) // (2 * len(pivots)) for i, share in zip(hopeful, shares)
            if share >= shares.max() - OTHER_SCALE_SHARE_TOLERANCE and i % len(pivots) == pivot_index
            and (trials[i][0] > 1.0) == (side > 0)}
    low, high = _run_around(good, chosen // (2 * len(pivots)))
    pivot = pivots[pivot_index]
    count = int(np.ceil(np.log(sizes[high] / sizes[low] * OTHER_SCALE_STEP ** 2) / np.log(OTHER_SCALE_FINE_STEP)))
    fine = sizes[low] / OTHER_SCALE_STEP * OTHER_SCALE_FINE_STEP ** np.arange(count + 1)
    fine = fine[fine >= OTHER_SCALE_MIN] ** side
    hopeful, shares = best_of([(factor, OTHER_SCALE_UNITS, pivot) for factor in fine])
    if not len(hopeful) or shares.max() < needed:
        return None
    good = {int(i) for i, share in zip(hopeful, shares) if share >= shares.max() - OTHER_SCALE_SHARE_TOLERANCE}
    low, high = _run_around(good, int(hopeful[int(np.argmax(shares))]))
    factor = float(np.sqrt(fine[low] * fine[high]))
    return UnitFactor(factor, OTHER_SCALE_UNITS, float(shares.max()))


def _run_around(members: set[int], start: int) -> tuple[int, int]:
    """The first and last of the run of consecutive ``members`` holding ``start``."""
    low = high = start
    while low - 1 in members:
        low -= 1
    while high + 1 in members:
        high += 1
    return low, high
