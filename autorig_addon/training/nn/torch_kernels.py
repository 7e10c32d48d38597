"""The kernels of the networks in torch, differentiable: the operations
table every network trains with (:data:`TORCH`), twins of
:mod:`autorig_addon.core.nn.numpy_kernels` (same names, signatures and
conventions: a node that receives no edge gets 0 from every reduction).

Gather is ``index_select``; sums ``index_add``; max and min
``scatter_reduce(..., include_self=False)`` into zeros, so empty segments
keep their 0. Where several values tie for a segment's max or min, torch
shares the gradient among them.
"""

from __future__ import annotations

from typing import Optional

import torch
import torch.nn.functional as F

from ...core.nn.numpy_kernels import LEAKY_RELU_SLOPE
from ...core.nn.operations import Operations


def concat(tensors, axis: int) -> torch.Tensor:
    return torch.cat(list(tensors), dim=axis)


def column_max(x: torch.Tensor) -> torch.Tensor:
    """(r, c) gives (1, c): the largest value of each column."""
    return x.max(dim=0, keepdim=True).values


def repeat_rows(row: torch.Tensor, count: int) -> torch.Tensor:
    """(1, c) gives (count, c) (a view: the gradient sums over the rows)."""
    return row.expand(count, -1)


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


def linear(x: torch.Tensor, weight: torch.Tensor, bias: Optional[torch.Tensor] = None) -> torch.Tensor:
    """``x @ weight.T + bias``, as the numpy twin."""
    return F.linear(x, weight, bias)


def leaky_relu(x: torch.Tensor, slope: float = LEAKY_RELU_SLOPE) -> torch.Tensor:
    return F.leaky_relu(x, slope)


def identity(x: torch.Tensor) -> torch.Tensor:
    return x


def clamp_min(x: torch.Tensor, floor: float) -> torch.Tensor:
    return x.clamp(min=floor)


def where(mask: torch.Tensor, a: torch.Tensor, b) -> torch.Tensor:
    return torch.where(mask, a, b)


def nonzero(mask: torch.Tensor) -> torch.Tensor:
    return torch.nonzero(mask).reshape(-1)


def scatter(values: torch.Tensor, index: torch.Tensor, size: int) -> torch.Tensor:
    """(size,) zeros with ``values`` at ``index`` (differentiable in ``values``)."""
    return values.new_zeros(size).index_copy(0, index, values)


def masked_row_softmax(logits: torch.Tensor, valid: torch.Tensor) -> torch.Tensor:
    """Softmax of each row over its ``valid`` entries, 0 at the others."""
    return torch.softmax(logits.masked_fill(~valid, float("-inf")), dim=1)


def column_softmax(logits: torch.Tensor) -> torch.Tensor:
    """Softmax of each column over its rows."""
    return torch.softmax(logits, dim=0)


#: Activations by name, as in the numpy twin.
ACTIVATIONS = {"relu": F.relu, "leaky_relu": leaky_relu, "none": identity}

#: The torch operations table (:class:`~autorig_addon.core.nn.operations.Operations`).
TORCH = Operations(
    name="torch", concat=concat, column_max=column_max, repeat_rows=repeat_rows, gather=gather,
    segment_sum=segment_sum, segment_mean=segment_mean, segment_max=segment_max, segment_min=segment_min,
    linear=linear, activations=ACTIVATIONS, log=torch.log, sqrt=torch.sqrt, clamp_min=clamp_min, where=where,
    nonzero=nonzero, scatter=scatter, masked_row_softmax=masked_row_softmax, column_softmax=column_softmax,
)


def _scatter_extreme(values: torch.Tensor, index: torch.Tensor, segment_count: int, reduce: str) -> torch.Tensor:
    expanded = index.view((-1,) + (1,) * (values.dim() - 1)).expand_as(values)
    empty = values.new_zeros((segment_count,) + tuple(values.shape[1:]))
    return empty.scatter_reduce(0, expanded, values, reduce=reduce, include_self=False)
