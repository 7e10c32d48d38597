"""Message passing kernels in torch, differentiable: the training twins of
:mod:`autorig_addon.core.nn.aggregation` (same names, signatures and
conventions: a node that receives no edge gets 0 from every reduction).

Gather is ``index_select``; sums ``index_add``; max and min
``scatter_reduce(..., include_self=False)`` into zeros, so empty segments
keep their 0. Where several values tie for a segment's max or min, torch
shares the gradient among them.
"""

from __future__ import annotations

import torch

from ..aggregation import STD_VARIANCE_FLOOR


def gather(x: torch.Tensor, index: torch.Tensor) -> torch.Tensor:
    """Rows of ``x`` picked by ``index``: (n, ...) and (e,) give (e, ...)."""
    return x.index_select(0, index)


def segment_counts(index: torch.Tensor, segment_count: int) -> torch.Tensor:
    """(segment_count,) int64: how many values fall in each segment."""
    return torch.bincount(index, minlength=segment_count)


def segment_sum(values: torch.Tensor, index: torch.Tensor, segment_count: int) -> torch.Tensor:
    """Sum of the values of each segment; (n, ...), 0 for an empty segment."""
    return values.new_zeros((segment_count,) + tuple(values.shape[1:])).index_add(0, index, values)


def segment_mean(values: torch.Tensor, index: torch.Tensor, segment_count: int) -> torch.Tensor:
    """Mean of the values of each segment; (n, ...), 0 for an empty segment."""
    counts = segment_counts(index, segment_count).clamp(min=1).to(values.dtype)
    return segment_sum(values, index, segment_count) / counts.view((-1,) + (1,) * (values.dim() - 1))


def segment_max(values: torch.Tensor, index: torch.Tensor, segment_count: int) -> torch.Tensor:
    """Largest value of each segment; (n, ...), 0 for an empty segment."""
    return _scatter_extreme(values, index, segment_count, "amax")


def segment_min(values: torch.Tensor, index: torch.Tensor, segment_count: int) -> torch.Tensor:
    """Smallest value of each segment; (n, ...), 0 for an empty segment."""
    return _scatter_extreme(values, index, segment_count, "amin")


def segment_std(values: torch.Tensor, index: torch.Tensor, segment_count: int) -> torch.Tensor:
    """Standard deviation of each segment from two sums, 0 where the
    variance is at or below ``STD_VARIANCE_FLOOR`` (see the numpy twin)."""
    mean = segment_mean(values, index, segment_count)
    variance = (segment_mean(values * values, index, segment_count) - mean * mean).clamp(min=0)
    return variance.clamp(min=STD_VARIANCE_FLOOR).sqrt().masked_fill(variance <= STD_VARIANCE_FLOOR, 0)


def segment_softmax(scores: torch.Tensor, index: torch.Tensor, segment_count: int) -> torch.Tensor:
    """Softmax over the scores of each segment; (e, ...) like ``scores``."""
    # The shift changes no result, so it needs no gradient.
    maxima = segment_max(scores.detach(), index, segment_count)
    shifted = torch.exp(scores - gather(maxima, index))
    return shifted / gather(segment_sum(shifted, index, segment_count), index)


#: Reductions by name, as in the numpy twin.
AGGREGATIONS = {
    "sum": segment_sum,
    "mean": segment_mean,
    "max": segment_max,
    "min": segment_min,
    "std": segment_std,
}


def _scatter_extreme(values: torch.Tensor, index: torch.Tensor, segment_count: int, reduce: str) -> torch.Tensor:
    expanded = index.view((-1,) + (1,) * (values.dim() - 1)).expand_as(values)
    empty = values.new_zeros((segment_count,) + tuple(values.shape[1:]))
    return empty.scatter_reduce(0, expanded, values, reduce=reduce, include_self=False)
