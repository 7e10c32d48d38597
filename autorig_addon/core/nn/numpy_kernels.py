"""The kernels of the networks in numpy: the operations table Blender runs
every forward pass with (:data:`NUMPY`, an
:class:`~.operations.Operations`).

Their torch twins, with the same names, signatures and conventions, are in
the training package (``autorig_addon/training/nn/torch_kernels.py``); a
test checks each pair on random graphs.

Segment reductions: row ``k`` of a reduction summarises the values whose
``index`` is ``k``; a node that receives no edge (an empty segment) gets 0
from every reduction, so isolated vertices read as "no neighbours" rather
than as -inf or NaN. Sums are a sparse (segments x values) 0/1 matrix times
the values; max and min lay each segment's values out in a padded
(segments, widest segment, ...) block and reduce its middle axis, or, where
a hub segment would make that block too big, sort the values and reduce
each run with ``ufunc.reduceat`` (two to four times slower on a 5k-vertex
mesh graph, but never larger than the values).
"""

from __future__ import annotations

from typing import Optional

import numpy as np
import scipy.sparse as sp

from .operations import Operations

#: Slope of leaky ReLU for negative inputs (torch's default).
LEAKY_RELU_SLOPE = 0.01
#: How many times the values' size the padded block of :func:`segment_max`
#: and :func:`segment_min` may take before they fall back to ``reduceat``.
#: A mesh graph's widest segment is about 1.5 times its mean degree, so
#: mesh neighbourhoods stay padded; a hub (one bone receiving thousands of
#: vertices) does not.
PADDED_BLOCK_SIZE_LIMIT = 4


def concat(arrays, axis: int) -> np.ndarray:
    return np.concatenate(arrays, axis=axis)


def column_max(x: np.ndarray) -> np.ndarray:
    """(r, c) gives (1, c): the largest value of each column."""
    return x.max(axis=0, keepdims=True)


def repeat_rows(row: np.ndarray, count: int) -> np.ndarray:
    """(1, c) gives (count, c)."""
    return np.repeat(row, count, axis=0)


def gather(x: np.ndarray, index: np.ndarray) -> np.ndarray:
    """Rows of ``x`` picked by ``index``: (n, ...) and (e,) give (e, ...)."""
    return x[index]


def segment_counts(index: np.ndarray, segment_count: int) -> np.ndarray:
    """(segment_count,) int64: how many values fall in each segment."""
    return np.bincount(_checked_index(index, segment_count), minlength=segment_count).astype(np.int64)


def segment_sum(values: np.ndarray, index: np.ndarray, segment_count: int) -> np.ndarray:
    """Sum of the values of each segment.

    Parameters
    ----------
    values : (e, ...) array, one row per edge
    index : (e,) int array in ``0..segment_count-1``, the segment of each row
    segment_count : int, number of segments (nodes) ``n``

    Returns
    -------
    (n, ...) array of ``values``' dtype; 0 for an empty segment.
    """
    values, index = _checked(values, index, segment_count)
    membership = sp.csr_matrix(
        (np.ones(len(index), dtype=values.dtype), np.argsort(index, kind="stable"),
         np.concatenate([[0], np.cumsum(np.bincount(index, minlength=segment_count))])),
        shape=(segment_count, len(index)),
    )
    flat = membership @ values.reshape(len(index), int(np.prod(values.shape[1:])))
    return np.asarray(flat, dtype=values.dtype).reshape((segment_count,) + values.shape[1:])


def segment_mean(values: np.ndarray, index: np.ndarray, segment_count: int) -> np.ndarray:
    """Mean of the values of each segment; (n, ...) like :func:`segment_sum`,
    0 for an empty segment."""
    values = np.asarray(values)
    totals = segment_sum(values, index, segment_count)
    counts = np.maximum(segment_counts(index, segment_count), 1).astype(totals.dtype)
    return totals / counts.reshape((-1,) + (1,) * (values.ndim - 1))


def segment_max(values: np.ndarray, index: np.ndarray, segment_count: int) -> np.ndarray:
    """Largest value of each segment; (n, ...), 0 for an empty segment."""
    return _segment_extreme(values, index, segment_count, np.maximum)


def segment_min(values: np.ndarray, index: np.ndarray, segment_count: int) -> np.ndarray:
    """Smallest value of each segment; (n, ...), 0 for an empty segment."""
    return _segment_extreme(values, index, segment_count, np.minimum)


def linear(x: np.ndarray, weight: np.ndarray, bias: Optional[np.ndarray] = None) -> np.ndarray:
    """``x @ weight.T + bias``: (r, in), (out, in) and (out,) give (r, out)."""
    y = x @ weight.T
    return y if bias is None else y + bias


def relu(x: np.ndarray) -> np.ndarray:
    return np.maximum(x, 0)


def leaky_relu(x: np.ndarray, slope: float = LEAKY_RELU_SLOPE) -> np.ndarray:
    """``x`` where positive, ``slope * x`` elsewhere, for ``0 < slope < 1``:
    then it is the larger of the two, the same numbers as a ``where`` on
    ``x > 0`` (infinities, NaN and -0 too; at slope 0, ``0 * inf`` would
    be NaN) with one temporary instead of three: the networks' activations
    are large, see docs/benchmarks.md."""
    if not 0.0 < slope < 1.0:
        raise ValueError(f"leaky_relu takes a slope in (0, 1), got {slope}")
    scaled = np.asarray(x * np.asarray(slope, dtype=x.dtype))  # an array even for a 0-d x, to write into
    return np.maximum(x, scaled, out=scaled)


def identity(x: np.ndarray) -> np.ndarray:
    return x


def sigmoid(x: np.ndarray) -> np.ndarray:
    """The logistic function ``1 / (1 + exp(-x))``, written with ``tanh`` so
    that no ``exp`` overflows for large ``|x|``. Not in the table: the
    networks give logits, and their callers in numpy turn them into
    probabilities (torch trains on the logits)."""
    return 0.5 * (1.0 + np.tanh(0.5 * x))


def clamp_min(x: np.ndarray, floor: float) -> np.ndarray:
    return np.maximum(x, floor)


def where(mask: np.ndarray, a, b) -> np.ndarray:
    """``a`` where ``mask`` holds, else ``b``, in ``a``'s dtype."""
    return np.where(mask, a, b).astype(np.asarray(a).dtype, copy=False)


def nonzero(mask: np.ndarray) -> np.ndarray:
    return np.flatnonzero(mask)


def scatter(values: np.ndarray, index: np.ndarray, size: int) -> np.ndarray:
    """(size,) zeros with ``values`` at ``index``."""
    result = np.zeros(size, dtype=values.dtype)
    result[index] = values
    return result


def masked_row_softmax(logits: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Softmax of each row over its ``valid`` entries, 0 at the others; the
    row maximum is subtracted first so that large logits do not overflow."""
    logits = np.where(valid, logits, -np.inf)
    logits = logits - logits.max(axis=1, keepdims=True)
    exponentials = np.exp(logits)
    return exponentials / exponentials.sum(axis=1, keepdims=True)


#: Activations by name, for layers that take theirs as a setting.
ACTIVATIONS = {"relu": relu, "leaky_relu": leaky_relu, "none": identity}

#: The numpy operations table (:class:`~.operations.Operations`).
def column_softmax(logits: np.ndarray) -> np.ndarray:
    """Softmax of each column over its rows; the column maximum is
    subtracted first so that large logits do not overflow."""
    exponentials = np.exp(logits - logits.max(axis=0, keepdims=True))
    return exponentials / exponentials.sum(axis=0, keepdims=True)


NUMPY = Operations(
    name="numpy", concat=concat, column_max=column_max, repeat_rows=repeat_rows, gather=gather,
    segment_sum=segment_sum, segment_mean=segment_mean, segment_max=segment_max, segment_min=segment_min,
    linear=linear, activations=ACTIVATIONS, log=np.log, sqrt=np.sqrt, clamp_min=clamp_min, where=where,
    nonzero=nonzero, scatter=scatter, masked_row_softmax=masked_row_softmax, column_softmax=column_softmax,
)


def _checked_index(index, segment_count: int) -> np.ndarray:
    index = np.asarray(index, dtype=np.int64).reshape(-1)
    if len(index) and (index.min() < 0 or index.max() >= segment_count):
        raise ValueError(f"A segment index lies outside 0..{segment_count - 1}.")
    return index


def _checked(values, index, segment_count: int) -> tuple[np.ndarray, np.ndarray]:
    values = np.asarray(values)
    index = _checked_index(index, segment_count)
    if len(index) != len(values):
        raise ValueError(f"{len(values)} values but {len(index)} segment indices.")
    return values, index


def _segment_extreme(values, index, segment_count: int, ufunc: np.ufunc) -> np.ndarray:
    """``ufunc`` (np.maximum or np.minimum) folded over each segment's rows;
    empty segments give 0."""
    values, index = _checked(values, index, segment_count)
    result = np.zeros((segment_count,) + values.shape[1:], dtype=values.dtype)
    if len(index) == 0:
        return result
    counts = np.bincount(index, minlength=segment_count)
    width = int(counts.max())
    order = np.argsort(index, kind="stable")
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    if segment_count * width <= PADDED_BLOCK_SIZE_LIMIT * len(index):
        # Each value's slot in its segment's row of the block; the padding is
        # the identity of the reduction, so it never wins.
        slot = np.empty(len(index), dtype=np.int64)
        slot[order] = np.arange(len(index)) - first[index[order]]
        if values.dtype.kind == "f":
            padding = -np.inf if ufunc is np.maximum else np.inf
        else:
            padding = np.iinfo(values.dtype).min if ufunc is np.maximum else np.iinfo(values.dtype).max
        block = np.full((segment_count * width,) + values.shape[1:], padding, dtype=values.dtype)
        block[index * width + slot] = values
        reduced = ufunc.reduce(block.reshape((segment_count, width) + values.shape[1:]), axis=1)
        filled = counts > 0
        result[filled] = reduced[filled]
        return result
    filled = np.flatnonzero(counts)
    result[filled] = ufunc.reduceat(values[order], first[filled], axis=0)
    return result
