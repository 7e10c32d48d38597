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

Cards hanging from the head (hair cards, lashes, a beard: thin strips,
:mod:`...geometry.cards`) move with the head, however far down the back
they hang: each is bound wholly to the head bone
(:func:`cards_following_the_head`), unless the armature has bones of its own
for it below the head (ears, hair chains) that its weights already follow.
Weighted as body, a card hanging to the shoulders spread over the head, the
chest and the shoulders, and turning the head tore it at the neck. Artists
weight them so: of the 346 cards hanging from the head bone in the 416
cached development characters, 97 % carry the weights of the vertex they
hang from (mean L1 0.012); of the 117 hanging from other bones
(fingernails, a skirt's strips, a tail's tassel) only 21 % do, so those keep
their weights.
"""

from __future__ import annotations

import numpy as np

from ..geometry.cards import hanging_cards
from ..geometry.laplacian import voronoi_mass
from ..geometry.topology import connected_component_labels
from ..geometry.weld import weld_mesh
from ..skeleton.hierarchy import ancestors
from ..skeleton.key_joints import key_joints
from ..types import Mesh, Skeleton

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
    bone = dominant_bones(labels, weights, voronoi_mass(mesh.vertices, mesh.triangles), share)
    rigid = bone >= 0
    moved = rigid[labels] & weighted
    result = weights.copy()
    result[moved] = 0.0
    result[np.flatnonzero(moved), bone[labels[moved]]] = 1.0
    return result, int(np.count_nonzero(rigid))


def dominant_bones(labels: np.ndarray, weights: np.ndarray, areas: np.ndarray,
                   share: float = RIGID_SHARE) -> np.ndarray:
    """For each part (``labels``: (n,) int, 0 to k - 1), the bone (column of
    ``weights``, (n, b)) holding at least ``share`` of its weight, each
    vertex counted by its area (``areas``, (n,): its Voronoi mass); -1 where
    no bone does. (k,) int array."""
    count = int(labels.max()) + 1 if len(labels) else 0
    if not weights.shape[1]:
        return np.full(count, -1, dtype=np.int64)
    mass = np.zeros((count, weights.shape[1]))
    # Area-weighted, so a finely tessellated corner does not outvote the rest of the part.
    np.add.at(mass, labels, weights * np.maximum(areas, 1e-30)[:, None])
    totals = mass.sum(axis=1)
    bone = mass.argmax(axis=1)
    held = (totals > 0) & (mass[np.arange(count), bone] >= share * totals)
    return np.where(held, bone, -1)


#: Rigify's generated rig prefixes its deforming bones so (``DEF-spine.006``) ...
DEFORM_PREFIX = "DEF-"
#: ... and the bones they follow so (``ORG-spine.006``, ``MCH-...``).
RIGIFY_PREFIXES = (DEFORM_PREFIX, "ORG-", "MCH-")
#: A card whose weights lie at least this much on bones below the head (ears,
#: hair chains: bones made for it) keeps them.
OWN_BONES_SHARE = 0.5


def head_columns(skeleton: Skeleton) -> tuple[int | None, np.ndarray]:
    """The weight column of ``skeleton``'s head bone (its place among the
    deform bones), read from their names (:func:`...skeleton.key_joints.key_joints`,
    Rigify's ``DEF-`` prefix dropped), and the columns of the deform bones
    below it; (None, empty) when no deform bone is the head."""
    # Deform bones only: Rigify's generated rig also has a control bone called ``head``.
    deform = np.flatnonzero(skeleton.deform)
    names = [skeleton.names[index].removeprefix(DEFORM_PREFIX) for index in deform]
    head = key_joints(names, skeleton.joints[deform]).bones.get("head")
    if head is None:
        return None, np.zeros(0, dtype=np.int64)
    # By name: Rigify parents each DEF- bone to its ORG- or MCH- bone, so DEF-ear.L hangs from ORG-spine.006.
    head_name = _plain(names[head])
    below = [column for column, bone in enumerate(deform)
             if any(_plain(skeleton.names[above]) == head_name for above in ancestors(skeleton.parents, bone))]
    return head, np.asarray(below, dtype=np.int64)


def _plain(name: str) -> str:
    """A bone name without Rigify's prefixes (``DEF-``, ``ORG-``, ``MCH-``)."""
    for prefix in RIGIFY_PREFIXES:
        if name.startswith(prefix):
            return name[len(prefix):]
    return name


def cards_following_the_head(mesh: Mesh, weights: np.ndarray, head: int | None,
                             below_head: np.ndarray = ()) -> tuple[np.ndarray, int]:
    """``weights`` with every card hanging from the head (from a vertex
    whose largest weight is on column ``head``) bound wholly to the head, unless the
    card's own weights lie mostly (:data:`OWN_BONES_SHARE`) on the columns
    ``below_head``: an armature with bones for it (a rabbit's ears, hair
    chains) keeps them.

    Parameters
    ----------
    mesh : Mesh with n vertices
    weights : (n, b) array, rows summing to 1 (or 0: unweighted)
    head : int or None, and below_head : int array (:func:`head_columns`); None changes nothing

    Returns
    -------
    (n, b) array and the number of cards bound to the head.
    """
    weights = np.asarray(weights, dtype=np.float64)
    cards = hanging_cards(mesh) if head is not None else None
    if cards is None or cards.count == 0:
        return weights, 0
    roots = weights[cards.hangs_from]
    on_head = (roots.sum(axis=1) > 0) & (roots.argmax(axis=1) == head)
    rows = np.flatnonzero(cards.mask)
    card = cards.card_of_vertex[rows]
    total = np.bincount(card, weights=weights[rows].sum(axis=1), minlength=cards.count)
    own = np.bincount(card, weights=weights[rows][:, np.asarray(below_head, dtype=np.int64)].sum(axis=1),
                      minlength=cards.count)
    bound = on_head & ~(own >= OWN_BONES_SHARE * np.maximum(total, 1e-300))
    # A vertex left unweighted (its row zero) stays so, as rigid_weights keeps it.
    moved = rows[bound[card] & (weights[rows].sum(axis=1) > 0)]
    result = weights.copy()
    result[moved] = 0.0
    result[moved, head] = 1.0
    return result, int(np.count_nonzero(bound))
