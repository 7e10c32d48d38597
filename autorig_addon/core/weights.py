"""Operations on weight matrices: clean-up, which rows can be used,
influence limits, mixing.

Every function takes a dense ``(n, b)`` array and returns one, or an
``(n,)`` bool array for the row tests; none modifies its input.
"""

from __future__ import annotations

import numpy as np

from .errors import InputError

#: Weights at or below this are treated as no influence (RigNet's threshold).
INFLUENCE_EPSILON = 1e-4
#: Most bones per vertex the panels and the command line offer for
#: :func:`limit_influences` (0 there means no limit; game engines take 4 to 8).
MAX_INFLUENCES = 16


def normalize_rows(weights: np.ndarray) -> np.ndarray:
    """Clamp negatives and NaN to zero and scale each row to sum to one.

    Rows that are zero everywhere stay zero; callers decide how to fill
    them (see :func:`empty_rows`).
    """
    clean = np.asarray(weights, dtype=np.float64)
    if not np.isfinite(clean).all():  # checking first halves the time on big clean matrices
        clean = np.nan_to_num(clean, nan=0.0, posinf=0.0, neginf=0.0)
    clean = np.maximum(clean, 0.0)
    sums = clean.sum(axis=1, keepdims=True)
    return np.divide(clean, sums, out=np.zeros_like(clean), where=sums > 0)


def empty_rows(weights: np.ndarray) -> np.ndarray:
    """(n,) bool: rows with no weight above :data:`INFLUENCE_EPSILON`."""
    return ~(np.asarray(weights) > INFLUENCE_EPSILON).any(axis=1)


def invalid_rows(weights: np.ndarray) -> np.ndarray:
    """(n,) bool: rows with a NaN, infinite or negative entry (corrupt
    weights: Blender's vertex groups can hold NaN, and files anything).

    Examples
    --------
    >>> invalid_rows(np.array([[0.5, 0.5], [np.nan, 1.0], [1.0, -0.5], [0.0, 0.0]])).tolist()
    [False, True, True, False]
    """
    low, high = _row_extremes(weights)
    return _invalid_given(low, high)


def usable_rows(weights: np.ndarray) -> np.ndarray:
    """(n,) bool: rows that can be copied: valid (not :func:`invalid_rows`)
    and not empty (some weight above :data:`INFLUENCE_EPSILON`).

    Examples
    --------
    >>> usable_rows(np.array([[0.5, 0.5], [np.nan, 1.0], [0.0, 0.0], [1e-6, 0.0]])).tolist()
    [True, False, False, False]
    """
    low, high = _row_extremes(weights)
    # A row's largest weight tells whether it is empty (a row with NaN, whose
    # largest is NaN, is invalid anyway).
    return ~_invalid_given(low, high) & (high > INFLUENCE_EPSILON)


def _row_extremes(weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each row's smallest and largest entry, NaN where the row holds one:
    two reductions, far cheaper than element-wise tests on a big matrix."""
    weights = np.asarray(weights, dtype=np.float64)
    if not weights.shape[1]:
        return np.zeros(len(weights)), np.zeros(len(weights))
    return weights.min(axis=1), weights.max(axis=1)


def _invalid_given(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Rows with a NaN, infinite or negative entry, from their extremes."""
    with np.errstate(invalid="ignore"):
        return ~(low >= 0.0) | ~np.isfinite(high)


def limit_influences(weights: np.ndarray, max_influences: int) -> np.ndarray:
    """Keep the ``max_influences`` largest weights of each row, renormalised.

    ``max_influences <= 0`` means no limit (rows are still normalised).
    """
    weights = normalize_rows(weights)
    if max_influences <= 0 or max_influences >= weights.shape[1]:
        return weights
    drop = np.argpartition(-weights, max_influences - 1, axis=1)[:, max_influences:]
    limited = weights.copy()
    np.put_along_axis(limited, drop, 0.0, axis=1)
    return normalize_rows(limited)


def prune_small(weights: np.ndarray, threshold: float = INFLUENCE_EPSILON) -> np.ndarray:
    """Zero weights at or below ``threshold`` and renormalise, so vertex
    groups are not cluttered with negligible entries. Rows whose every
    weight is small keep their largest one."""
    weights = normalize_rows(weights)
    keep = weights > threshold
    rows = np.arange(len(weights))
    keep[rows, weights.argmax(axis=1)] |= weights.max(axis=1) > 0
    return normalize_rows(np.where(keep, weights, 0.0))


def sharpened(weights: np.ndarray, power: float) -> np.ndarray:
    """Each weight raised to ``power`` and the rows renormalised: above 1 a
    row's largest weights gain on its small ones (a blend narrows), zeros
    stay zero, and every row keeps its order of bones."""
    if power <= 0.0:
        raise ValueError(f"The sharpening power must be positive, got {power}.")
    weights = normalize_rows(weights)
    return weights if power == 1.0 else normalize_rows(weights ** power)


def mix_weights(existing: np.ndarray, incoming: np.ndarray, factor: float,
                columns: np.ndarray | None = None) -> np.ndarray:
    """Blend ``incoming`` into ``existing`` by ``factor`` in [0, 1].

    Only ``columns`` (indices, default all) change: those become
    ``(1 - factor) * existing + factor * incoming``; other columns keep their
    existing values. Rows are renormalised so the untouched bones keep their
    share relative to each other.
    """
    if existing.shape != incoming.shape:
        raise ValueError("existing and incoming weights must have the same shape")
    if not 0.0 <= factor <= 1.0:
        raise InputError(f"Mix factor must lie in [0, 1], got {factor}.")
    mixed = np.array(existing, dtype=np.float64, copy=True)
    cols = np.arange(existing.shape[1]) if columns is None else np.asarray(columns)
    mixed[:, cols] = (1.0 - factor) * existing[:, cols] + factor * incoming[:, cols]
    return normalize_rows(mixed)
