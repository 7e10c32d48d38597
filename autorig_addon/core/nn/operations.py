"""The operations table every network's forward pass is written against.

A network is written once, as a function of ``ops`` (an :class:`Operations`)
and ``params`` (its weights by ``state_dict`` name): numpy runs it inside
Blender with :data:`.numpy_kernels.NUMPY`, and torch trains it with the
table of the training package (``autorig_addon/training/nn/torch_kernels.py``),
whose kernels have the same names, signatures and conventions, so both give
the same outputs (tests check each pair and each network).

What the table holds are the kernels whose numpy and torch spellings differ;
everything else a forward pass needs reads the same on both kinds of array
(arithmetic, ``x.shape``, ``x.reshape(...)``, ``x[rows]``, ``x[:, 0]``),
and the layers built of the kernels (:mod:`.layers`, :mod:`.aggregation`,
:mod:`.convolution`) take ``ops`` too.

Conventions shared by both tables: ``x`` is (r, c) with one row per node
(vertex, bone, pair); an edge index is (2, e), senders then receivers; a
segment reduction folds the rows of every receiver into one row and gives 0
to a segment that receives nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

#: An array of either backend (numpy ndarray or torch Tensor).
Array = Any


@dataclass(frozen=True)
class Operations:
    """One backend's kernels (see the module docstring).

    Attributes
    ----------
    name : str, "numpy" or "torch"
    concat : (arrays, axis) -> array, the arrays joined along ``axis``
    column_max : (r, c) -> (1, c), the largest value of each column (a
        global max pool)
    repeat_rows : ((1, c), n) -> (n, c), the row repeated ``n`` times
    gather : ((n, ...), (e,) int) -> (e, ...), rows picked by index
    segment_sum, segment_mean, segment_max, segment_min :
        ((e, ...), (e,) int, n) -> (n, ...), the rows of each segment
        reduced; 0 for an empty segment
    linear : ((r, in), (out, in), (out,) or None) -> (r, out), ``x @ w.T + b``
    activations : name -> elementwise function (``"relu"``,
        ``"leaky_relu"``, ``"none"``)
    log, sqrt : elementwise
    clamp_min : (x, float) -> x with every value below the float raised to it
    where : (bool mask, a, b) -> a where the mask holds, else b (b may be a number)
    nonzero : (m,) bool -> (p,) int64, the indices where it holds
    scatter : ((p,), (p,) int, m) -> (m,), the values at those indices of zeros
    masked_row_softmax : ((n, k), (n, k) bool) -> (n, k), softmax of each
        row over its valid entries (0 at the others); a row needs one valid entry
    column_softmax : (n, k) -> (n, k), softmax of each column over its rows
        (weights over the vertices, one column per landmark)
    """

    name: str
    concat: Callable[[Sequence[Array], int], Array]
    column_max: Callable[[Array], Array]
    repeat_rows: Callable[[Array, int], Array]
    gather: Callable[[Array, Array], Array]
    segment_sum: Callable[[Array, Array, int], Array]
    segment_mean: Callable[[Array, Array, int], Array]
    segment_max: Callable[[Array, Array, int], Array]
    segment_min: Callable[[Array, Array, int], Array]
    linear: Callable[[Array, Array, Any], Array]
    activations: Mapping[str, Callable[[Array], Array]]
    log: Callable[[Array], Array]
    sqrt: Callable[[Array], Array]
    clamp_min: Callable[[Array, float], Array]
    where: Callable[[Array, Array, Any], Array]
    nonzero: Callable[[Array], Array]
    scatter: Callable[[Array, Array, int], Array]
    masked_row_softmax: Callable[[Array, Array], Array]
    column_softmax: Callable[[Array], Array]
