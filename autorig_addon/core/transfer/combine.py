"""How transferred weights combine with a target's existing weights.

Three write modes, the identifiers the panel's "Write" menu and the
operator's ``replace_mode`` use:

``REPLACE``
    the transferred bones' weights replace the existing ones; other bones
    keep theirs, and every row is renormalised,
``MIX``
    the transferred bones' weights become ``(1 - f) * existing + f * transferred``
    for a mix factor ``f`` in [0, 1],
``REPLACE_ALL``
    the existing weights are dropped entirely.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..weights import limit_influences, mix_weights, normalize_rows, prune_small

REPLACE = "REPLACE"
MIX = "MIX"
REPLACE_ALL = "REPLACE_ALL"
#: Every write mode, in the order the panel lists them.
REPLACE_MODES = (REPLACE, MIX, REPLACE_ALL)
#: A transfer replaces the transferred bones' weights unless told otherwise.
DEFAULT_REPLACE_MODE = REPLACE
#: Share of the transferred weights when mixing, in [0, 1] (1: the transferred weights alone).
DEFAULT_MIX_FACTOR = 1.0


def check_write_mode(replace_mode: str, mix_factor: float) -> None:
    """Raise :class:`InputError` for an unknown mode or a mix factor outside [0, 1]."""
    if replace_mode not in REPLACE_MODES:
        raise InputError(f"Unknown write mode '{replace_mode}': use one of {', '.join(REPLACE_MODES)}.")
    if not 0.0 <= mix_factor <= 1.0:
        raise InputError(f"The mix factor must lie between 0 and 1, got {mix_factor}.")


def needs_existing_weights(replace_mode: str, transferred_count: int, bone_count: int) -> bool:
    """Whether the target's current weights enter the result (mixing, or a
    subset of the bones); a plain replace of every bone ignores them."""
    return replace_mode == MIX or transferred_count != bone_count


def combine_with_existing(existing: np.ndarray, incoming: np.ndarray, columns: np.ndarray, replace_mode: str,
                          mix_factor: float = DEFAULT_MIX_FACTOR, max_influences: int = 0) -> np.ndarray:
    """Final weights of a target from its existing and transferred weights.

    Parameters
    ----------
    existing : (n, b) float64 array, the target's current weights (raw)
    incoming : (n, b) float64 array, the transferred weights, rows
        normalised, influences limited and small weights pruned
    columns : (k,) int array, the transferred bones' columns
    replace_mode : one of :data:`REPLACE_MODES`
    mix_factor : float in [0, 1], used by :data:`MIX`
    max_influences : int, bones kept per vertex (0: no limit)

    Returns
    -------
    (n, b) float64 array: rows sum to one (or are zero where no bone of
    the written set has weight). ``incoming`` itself when the existing
    weights play no part (see :func:`needs_existing_weights`).

    Examples
    --------
    Mixing a quarter of a transferred (1, 0) into an existing (0, 1):

    >>> combine_with_existing(np.array([[0.0, 1.0]]), np.array([[1.0, 0.0]]), np.array([0, 1]), MIX, 0.25)
    array([[0.25, 0.75]])
    """
    check_write_mode(replace_mode, mix_factor)
    if not needs_existing_weights(replace_mode, len(columns), existing.shape[1]):
        return incoming
    factor = mix_factor if replace_mode == MIX else 1.0
    base = np.zeros_like(existing) if replace_mode == REPLACE_ALL else existing
    combined = mix_weights(normalize_rows(base), normalize_rows(incoming), factor, columns)
    return prune_small(limit_influences(combined, max_influences))


#: Largest distance of a written row's sum from 1 (float64 rounding after
#: normalising, limiting and pruning stays far below it).
ROW_SUM_TOLERANCE = 1e-6


def keep_existing_where_empty(final: np.ndarray, existing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows of ``final`` with no weight at all (a subset of bones, or a mix
    factor of 0, that leaves a vertex without any) take the vertex's
    existing row unchanged; rows without any existing weight either are
    reported, never written empty.

    Parameters
    ----------
    final : (n, b) float64 array, from :func:`combine_with_existing`
    existing : (n, b) float64 array, the target's current weights (raw)

    Returns
    -------
    weights : (n, b) float64 array, ``final`` with empty rows replaced by
        the existing ones
    unweighted : (n,) bool array, vertices with no weight in either (the
        caller refuses to write them)

    Raises
    ------
    ValueError when a written row is not finite or does not sum to one: a
    defect, never the user's input.

    Examples
    --------
    >>> weights, unweighted = keep_existing_where_empty(
    ...     np.array([[0.0, 0.0], [0.0, 0.0], [0.5, 0.5]]), np.array([[0.0, 0.3], [0.0, 0.0], [0.0, 1.0]]))
    >>> weights
    array([[0. , 0.3],
           [0. , 0. ],
           [0.5, 0.5]])
    >>> unweighted
    array([False,  True, False])
    """
    empty = ~np.any(final > 0, axis=1)
    had_weight = np.any(existing > 0, axis=1)
    weights = final.copy()
    weights[empty] = existing[empty]
    written = ~empty
    sums = weights[written].sum(axis=1)
    if not np.isfinite(weights[written]).all() or np.any(np.abs(sums - 1.0) > ROW_SUM_TOLERANCE):
        raise ValueError("Combined weights with rows that are not finite or do not sum to one.")
    return weights, empty & ~had_weight
