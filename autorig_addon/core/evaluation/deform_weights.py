"""Weights as the dense matrix the evaluation poses with: one column per deform bone."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..types import Skeleton, Weights


def deform_weight_matrix(weights, skeleton: Skeleton, vertex_count: int, what: str = "weights") -> np.ndarray:
    """Dense ``(n, d)`` weights whose columns are the deform bones of ``skeleton``.

    Parameters
    ----------
    weights : (n, d) float64 array or Weights
        An array is taken to be in deform-bone order already (the order of
        :meth:`Skeleton.deform_subset`); a :class:`Weights` is matched to
        the deform bones by name (a bone it lacks gets zeros, bones the
        skeleton lacks are dropped).
    skeleton : Skeleton
    vertex_count : int
        Expected number of rows ``n``.
    what : str
        Names the weights in error messages.

    Returns
    -------
    matrix : (n, d) float64 array

    Raises
    ------
    InputError
        For a matrix of another shape, or one holding NaN or infinite values.
    """
    deform = skeleton.deform_subset()
    if isinstance(weights, Weights):
        matrix = weights.select_bones(deform.names).matrix
    else:
        matrix = np.asarray(weights, dtype=np.float64)
    if matrix.shape != (vertex_count, deform.bone_count):
        raise InputError(
            f"The {what} have shape {matrix.shape} but the mesh has {vertex_count} vertices "
            f"and the skeleton {deform.bone_count} deform bones."
        )
    if not np.all(np.isfinite(matrix)):
        raise InputError(f"The {what} contain NaN or infinite values; clean them first.")
    return matrix
