"""Loose parts that move as one piece: each bound wholly to one bone.

A character built of separate pieces (a robot's plates, a mech's limbs, armour
pieces, a helmet, eyes, buttons) is rigged by artists one bone per piece, each
piece weighted 1 to its bone: a plate does not bend. Every skin method here
gives smooth weights, so a robot's head plate spread over the neck and the
head bends at its lower edge when the head turns. A loose part (connected
through its triangles once UV seams are joined, :func:`...geometry.weld.weld_mesh`)
whose weights already lie mostly on one bone (at least :data:`RIGID_SHARE`
of its area-weighted weight) is bound wholly to that bone. A part whose
weights spread over several bones (a whole leg, a sleeve, trousers, the body
of a one-piece character) keeps them: it spans a joint and must bend there.
"""

from __future__ import annotations

import numpy as np

from ..geometry.laplacian import voronoi_mass
from ..geometry.topology import connected_component_labels
from ..geometry.weld import weld_mesh
from ..types import Mesh

#: A loose part whose area-weighted weights hold at least this share on one
#: bone is bound wholly to it (see :func:`rigid_weights`). Chosen on every
#: third training character under HeterSkinNet's finished weights (sharpened,
#: ``..learned.predict.SHARPEN_POWER``; 2026-11-26): L1 0.4049, 0.4041,
#: 0.4042, 0.4045, 0.4012, 0.4018 at 0.7, 0.75, 0.8, 0.85, 0.9, 0.95 (0.4066
#: without), the deformation error lowest and equal from 0.75 to 0.95, recall
#: rising with the share (0.736 at 0.9, 0.728 at 0.85), precision falling
#: (0.831 and 0.835).
RIGID_SHARE = 0.9


def loose_parts(mesh: Mesh) -> np.ndarray:
    """(n,) int label of each vertex's loose part, UV seams joined first."""
    welded, to_welded = weld_mesh(mesh)
    return connected_component_labels(welded.triangles, welded.vertex_count)[to_welded]


def rigid_weights(mesh: Mesh, weights: np.ndarray, share: float = RIGID_SHARE) -> tuple[np.ndarray, int]:
    """``weights`` with every rigid loose part bound wholly to its bone.

    Parameters
    ----------
    mesh : Mesh with n vertices
    weights : (n, b) array, rows summing to 1 (or 0: a vertex left unweighted, which stays so)
    share : a part is rigid when one bone holds at least this share of its
        weight, each vertex counted by its area

    Returns
    -------
    (n, b) array and the number of parts made rigid (a mesh of one part: none).
    """
    weights = np.asarray(weights, dtype=np.float64)
    labels = loose_parts(mesh)
    count = int(labels.max()) + 1 if len(labels) else 0
    if count < 2:
        return weights, 0
    weighted = (weights > 0).any(axis=1)
    mass = np.zeros((count, weights.shape[1]))
    # Area-weighted, so a finely tessellated corner does not outvote the rest of the part.
    np.add.at(mass, labels, weights * np.maximum(voronoi_mass(mesh.vertices, mesh.triangles), 1e-30)[:, None])
    totals = mass.sum(axis=1)
    bone = mass.argmax(axis=1)
    rigid = (totals > 0) & (mass[np.arange(count), bone] >= share * totals)
    moved = rigid[labels] & weighted
    result = weights.copy()
    result[moved] = 0.0
    result[np.flatnonzero(moved), bone[labels[moved]]] = 1.0
    return result, int(np.count_nonzero(rigid))
