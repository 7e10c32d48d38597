"""Bone heat diffused over a surface, from vertex-to-bone distances.

Baran & Popovic's bone heat (2007), with the distances supplied rather than
measured along straight lines: each vertex is heated by its nearest bone
with strength ``H = falloff / d_min^2`` (``d_min`` in units of the mesh
diagonal), and for every bone ``j`` the steady state of heat flowing along
the surface solves ``(-L + M H) w_j = M H p_j`` (cotangent Laplacian ``L``,
lumped mass ``M``, ``p_j`` the indicator of the vertices whose nearest bone
is ``j``), one sparse factorisation for all bones. Weights blend smoothly
across joints; ``falloff`` sets how sharply (higher: narrower blends).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from ..geometry.laplacian import surface_operators
from ..geometry.topology import connected_component_labels
from ..geometry.weld import weld_mesh
from ..types import Mesh

#: Bones within this relative margin of a vertex's nearest distance heat it together.
NEAREST_TIE_FRACTION = 1e-3
#: Distances are floored at this fraction of the mesh's bounding-box
#: diagonal, so a vertex lying on a bone does not divide by zero.
DISTANCE_FLOOR_FRACTION = 1e-4
#: Mass given to vertices in no triangle, relative to the largest mass: they
#: then keep their nearest bone instead of making the system singular.
LOOSE_VERTEX_MASS_FRACTION = 1e-12


def heat_diffusion_weights(mesh: Mesh, distances: np.ndarray, falloff: float,
                           heated: np.ndarray | None = None) -> np.ndarray:
    """Unnormalised weights: bone heat diffused over the surface.

    The surface is welded at its seams (:func:`..geometry.weld.weld_mesh`) so
    heat flows across UV seams; copies of a vertex take the distances of the
    nearest copy and share its result.

    Parameters
    ----------
    mesh : Mesh with n vertices (any scale; it is normalised to unit diagonal)
    distances : (n, b) float64 array, finite, >= 0, scene units
    falloff : float > 0, the heat strength (Baran & Popovic's c, unitless)
    heated : (n,) bool array, vertices their nearest bone heats (default all);
        parts with no heated vertex are heated everywhere

    Returns
    -------
    (n, b) float64 array, non-negative. A vertex in no triangle keeps its
    nearest bone alone; so does every vertex of a part whose vertices all
    have one nearest bone.
    """
    diagonal = max(mesh.bounding_box_diagonal, 1e-300)
    welded, to_welded = weld_mesh(mesh)
    count, welded_F = welded.vertex_count, welded.triangles
    relative = np.full((count, distances.shape[1]), np.inf)
    np.minimum.at(relative, to_welded, np.asarray(distances, dtype=np.float64) / diagonal)
    relative = np.maximum(relative, DISTANCE_FLOOR_FRACTION)
    nearest = relative.min(axis=1)
    sources = relative <= nearest[:, None] * (1.0 + NEAREST_TIE_FRACTION)
    sources = sources / sources.sum(axis=1, keepdims=True)
    unit_V = welded.vertices / diagonal
    operators = surface_operators(unit_V, welded_F)
    mass = np.maximum(operators.mass, LOOSE_VERTEX_MASS_FRACTION * max(operators.mass.max(initial=0.0), 1e-300))
    heat = mass * float(falloff) / nearest**2
    if heated is not None:
        welded_heated = np.zeros(count, dtype=bool)
        welded_heated[to_welded[np.asarray(heated, dtype=bool)]] = True
        labels = connected_component_labels(welded_F, count)
        part_heated = np.zeros(labels.max() + 1, dtype=bool)
        part_heated[labels[welded_heated]] = True
        heat = np.where(welded_heated | ~part_heated[labels], heat, 0.0)
    system = (-operators.laplacian + sp.diags(heat)).tocsc()
    weights = splu(system, permc_spec="MMD_AT_PLUS_A").solve(np.asfortranarray(heat[:, None] * sources))
    return np.maximum(weights, 0.0)[to_welded]
