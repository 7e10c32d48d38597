"""Message passing kernels in numpy: gather along edges, aggregate into nodes.

A graph layer is *message -> aggregate -> update*: :func:`gather` reads
each edge's sender and receiver features (``x[edges[0]]``,
``x[edges[1]]``), a message function turns them into one row per edge, and
a segment reduction folds the rows of every receiver into one row
(``segment_*(messages, edges[1], node_count)``). Row ``k`` of a reduction
summarises the values whose ``index`` is ``k``; a node that receives no
edge (an empty segment) gets 0 from every reduction, so isolated vertices
read as "no neighbours" rather than as -inf or NaN.

These are the inference twins of
:mod:`autorig_addon.core.nn.training.aggregation` (torch, same names and
signatures); a test checks both agree on random graphs. Sums are a sparse
(segments x values) 0/1 matrix times the values; max and min lay each
segment's values out in a padded (segments, widest segment, ...) block and
reduce its middle axis, or, where a hub segment would make that block too
big, sort the values and reduce each run with ``ufunc.reduceat`` (two to
four times slower on a 5k-vertex mesh graph, but never larger than the
values).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: Variance (feature units squared) at or below which :func:`segment_std`
#: reports 0. The two-sum variance E[x^2] - E[x]^2 carries float32 rounding
#: of about 1e-7 * E[x^2], so smaller values are noise; the floor also keeps
#: the square root's gradient finite in training (torch twin). PyG's
#: StdAggregation uses the same 1e-5.
STD_VARIANCE_FLOOR = 1e-5
#: How many times the values' size the padded block of :func:`segment_max`
#: and :func:`segment_min` may take before they fall back to ``reduceat``.
#: A mesh graph's widest segment is about 1.5 times its mean degree, so
#: mesh neighbourhoods stay padded; a hub (one bone receiving thousands of
#: vertices) does not.
PADDED_BLOCK_SIZE_LIMIT = 4


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


def segment_std(values: np.ndarray, index: np.ndarray, segment_count: int) -> np.ndarray:
    """Population standard deviation of each segment, from two sums:
    ``sqrt(E[x^2] - E[x]^2)``, the difference clamped at 0.

    A variance at or below :data:`STD_VARIANCE_FLOOR` (a constant segment,
    one value, an empty segment) gives exactly 0. Example: values 1 and 3
    have mean 2, E[x^2] = 5, standard deviation 1.

    Returns
    -------
    (n, ...) array like :func:`segment_mean`.
    """
    values = np.asarray(values)
    mean = segment_mean(values, index, segment_count)
    variance = np.maximum(segment_mean(values * values, index, segment_count) - mean * mean, 0)
    deviation = np.sqrt(np.maximum(variance, STD_VARIANCE_FLOOR)).astype(mean.dtype)
    return np.where(variance > STD_VARIANCE_FLOOR, deviation, 0).astype(mean.dtype)


def segment_softmax(scores: np.ndarray, index: np.ndarray, segment_count: int) -> np.ndarray:
    """Softmax over the scores of each segment (attention over a node's
    edges, a vertex's candidate bones).

    Parameters
    ----------
    scores : (e, ...) float array
    index : (e,) int array, the segment of each score
    segment_count : int

    Returns
    -------
    (e, ...) array: ``exp(s) / sum of exp over the segment``; each
    segment's entries sum to 1. The segment maximum is subtracted first,
    so large scores do not overflow.
    """
    scores = np.asarray(scores)
    index = np.asarray(index)
    shifted = np.exp(scores - gather(segment_max(scores, index, segment_count), index))
    return shifted / gather(segment_sum(shifted, index, segment_count), index)


#: Reductions by name, for layers that take their aggregator as a setting.
AGGREGATIONS = {
    "sum": segment_sum,
    "mean": segment_mean,
    "max": segment_max,
    "min": segment_min,
    "std": segment_std,
}


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
