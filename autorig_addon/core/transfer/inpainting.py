"""Weight inpainting: the smoothest weights that agree with the known rows.

Stage 2 of robust weight transfer (Abdrashitov et al. 2023, section 3.2):
the unknown rows minimise ``trace(W^T Q W)`` with ``Q = -L + L M^-1 L``
(cotangent Laplacian ``L``, lumped Voronoi mass ``M``) while the known rows
stay fixed, i.e. ``Q_UU W_U = -Q_UI W_I``, one sparse factorisation shared
by every bone.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from ..geometry.bounding_box import bounding_box_diagonal
from ..geometry.laplacian import SurfaceOperators, surface_operators


def inpainting_operator(V: np.ndarray, F: np.ndarray, operators: SurfaceOperators | None = None) -> sp.csr_matrix:
    """``Q = -L + L M^-1 L`` (n, n), symmetric positive semi-definite.

    The mesh is taken at unit bounding-box diagonal so the balance between
    the Dirichlet term and the Laplacian energy term does not depend on
    scene units.

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    operators : SurfaceOperators of ``(V, F)`` when the caller has them

    Returns
    -------
    Q : (n, n) scipy.sparse.csr_matrix; ``Q @ 1 = 0``
    """
    operators = surface_operators(V, F) if operators is None else operators
    L = operators.laplacian
    mass = operators.mass_scaled(1.0 / max(bounding_box_diagonal(V), 1e-300))
    inverse_mass = np.divide(1.0, mass, out=np.zeros_like(mass), where=mass > 0)
    return (-L + L @ sp.diags(inverse_mass) @ L).tocsr()


def inpaint_weights(Q: sp.spmatrix, known: np.ndarray, known_weights: np.ndarray) -> np.ndarray:
    """Solve ``Q_UU W_U = -Q_UI W_I`` for the unknown rows.

    Parameters
    ----------
    Q : (n, n) sparse SPD-on-unknowns matrix (see :func:`inpainting_operator`)
    known : (n,) bool array, rows whose weights are fixed
    known_weights : (n, b) float64 array, read on known rows only

    Returns
    -------
    (n, b) float64 array: known rows as given, unknown rows solved (raw, not
    clamped or normalised). Every connected part of the unknowns must touch
    a known row, or the system is singular.
    """
    Q = sp.csr_matrix(Q)
    unknown = np.flatnonzero(~known)
    fixed = np.flatnonzero(known)
    result = np.zeros_like(known_weights, dtype=np.float64)
    result[fixed] = known_weights[fixed]
    if not len(unknown):
        return result
    # Bones with no weight on any fixed row stay zero: skip their solves.
    active = np.flatnonzero(np.abs(known_weights[fixed]).max(axis=0) > 0) if len(fixed) else np.zeros(0, int)
    if not len(active):
        return result
    Q_uu = Q[unknown][:, unknown].tocsc()
    rhs = -(Q[unknown][:, fixed] @ known_weights[np.ix_(fixed, active)])
    factor = splu(Q_uu, permc_spec="MMD_AT_PLUS_A")
    result[np.ix_(unknown, active)] = factor.solve(np.asfortranarray(rhs))
    return result
