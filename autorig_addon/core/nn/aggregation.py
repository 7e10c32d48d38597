"""Segment reductions by name, for layers that take their aggregator as a
setting, and the one reduction built of others: the standard deviation.

Written once against an operations table (:mod:`.operations`), so numpy
and torch reduce alike; the sums, means, maxima and minima are the table's
kernels.
"""

from __future__ import annotations

from .operations import Array, Operations

#: Variance (feature units squared) at or below which :func:`segment_std`
#: reports 0. The two-sum variance E[x^2] - E[x]^2 carries float32 rounding
#: of about 1e-7 * E[x^2], so smaller values are noise; the floor also keeps
#: the square root's gradient finite in training. PyG's StdAggregation uses
#: the same 1e-5.
STD_VARIANCE_FLOOR = 1e-5
#: The reductions :func:`aggregate` knows.
AGGREGATION_NAMES = ("sum", "mean", "max", "min", "std")


def segment_std(ops: Operations, values: Array, index: Array, segment_count: int) -> Array:
    """Population standard deviation of each segment, from two sums:
    ``sqrt(E[x^2] - E[x]^2)``, the difference clamped at 0.

    A variance at or below :data:`STD_VARIANCE_FLOOR` (a constant segment,
    one value, an empty segment) gives exactly 0. Example: values 1 and 3
    have mean 2, E[x^2] = 5, standard deviation 1.

    Returns
    -------
    (n, ...) array like ``ops.segment_mean``.
    """
    mean = ops.segment_mean(values, index, segment_count)
    variance = ops.clamp_min(ops.segment_mean(values * values, index, segment_count) - mean * mean, 0.0)
    deviation = ops.sqrt(ops.clamp_min(variance, STD_VARIANCE_FLOOR))
    return ops.where(variance > STD_VARIANCE_FLOOR, deviation, 0.0)


def aggregate(ops: Operations, name: str, values: Array, index: Array, segment_count: int) -> Array:
    """The reduction ``name`` (one of :data:`AGGREGATION_NAMES`) of each
    segment's rows: (e, ...) values and (e,) index give (n, ...)."""
    if name == "std":
        return segment_std(ops, values, index, segment_count)
    if name not in AGGREGATION_NAMES:
        raise ValueError(f"Unknown aggregation {name!r}; choose from {AGGREGATION_NAMES}.")
    return getattr(ops, f"segment_{name}")(values, index, segment_count)
