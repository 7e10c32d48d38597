"""Cards: thin strips hanging from a body (hair cards, eyelashes, ribbons).

Game characters model hair as *cards*: dozens of narrow open strips, each a
few quads, rooted on the scalp and hanging over the head, the neck and the
back. Weighted as body, a card hanging to the shoulders was spread over the
head, the chest and the shoulders, so turning the head stretched it at the
neck; the skin binds those hanging from the head to it
(:mod:`..skinning.rigid_parts`). A card (:func:`hanging_cards`) is a loose
piece (faces joined by edges, seams welded) that is

- **thin**: an open sheet (it has a boundary edge), or closed with no volume
  to speak of (a two-sided card);
- **small**: under :data:`CARD_AREA_SHARE` of the mesh's area;
- **long**: its length along its longest axis at least
  :data:`CARD_ELONGATION` times its mean width;
- **hanging**: some vertex of it lies within :data:`ATTACH_SHARE` of the
  largest side of the rest of the mesh (not cards); the highest such vertex
  (+Z up, Blender's) is its *root*, and the nearest vertex of the rest is
  where it hangs from. Hair lying along the back is near the body all the
  way down; it hangs from the scalp.

A flat cape, a skirt or a sleeve is far larger than a card; a tail or a
finger is closed and has volume; a button or an eye is not long.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..types import Mesh
from .normals import triangle_area_normals
from .topology import connected_component_labels
from .weld import weld_mesh

#: A card holds under this share of the mesh's area.
CARD_AREA_SHARE = 0.02
#: A card is at least this many times longer than it is wide (mean width: area over length).
CARD_ELONGATION = 3.0
#: A closed piece whose volume is under this share of a cube on its mean width
#: times its length is a two-sided card (a box of equal width and depth has 1).
CARD_VOLUME_SHARE = 0.05
#: A card's root lies this near the rest of the mesh, as a share of the rest's largest side.
ATTACH_SHARE = 0.05


@dataclass(frozen=True)
class HangingCards:
    """The cards of a mesh (:func:`hanging_cards`).

    Attributes
    ----------
    card_of_vertex : (n,) int array, the card each vertex belongs to, -1 for the rest
    hangs_from : (c,) int array, for each card the vertex of the rest nearest its root
    """

    card_of_vertex: np.ndarray
    hangs_from: np.ndarray

    @property
    def count(self) -> int:
        return len(self.hangs_from)

    @property
    def mask(self) -> np.ndarray:
        """(n,) bool array, the vertices of cards."""
        return self.card_of_vertex >= 0


def hanging_cards(mesh: Mesh) -> HangingCards:
    """The cards hanging from ``mesh``'s body (see the module docstring)."""
    vertex_count = mesh.vertex_count
    none = HangingCards(np.full(vertex_count, -1, dtype=np.int64), np.zeros(0, dtype=np.int64))
    if vertex_count == 0 or len(mesh.triangles) == 0:
        return none
    welded, to_welded = weld_mesh(mesh)
    V, F = welded.vertices, welded.triangles
    labels = connected_component_labels(F, welded.vertex_count)
    pieces = int(labels.max()) + 1
    if pieces < 2:
        return none
    face_piece = labels[F[:, 0]]
    area_normals = triangle_area_normals(V, F)
    areas = 0.5 * np.linalg.norm(area_normals, axis=1)
    piece_area = np.bincount(face_piece, weights=areas, minlength=pieces)
    small = piece_area < CARD_AREA_SHARE * areas.sum()
    candidates = np.flatnonzero(small & (piece_area > 0))
    if len(candidates) == 0:
        return none
    # Signed volume by the divergence theorem: zero for a two-sided card, meaningless for an open sheet.
    volume = np.abs(np.bincount(face_piece, weights=np.einsum("ij,ij->i", V[F[:, 0]], area_normals) / 6.0,
                                minlength=pieces))
    open_piece = _open_pieces(F, face_piece, pieces)
    is_card = np.zeros(pieces, dtype=bool)
    by_piece = np.argsort(labels, kind="stable")
    starts = np.searchsorted(labels[by_piece], np.arange(pieces + 1))
    for piece in candidates:
        length = _length(V[by_piece[starts[piece]:starts[piece + 1]]])
        if length <= 0:
            continue
        closed_area = piece_area[piece] if open_piece[piece] else 0.5 * piece_area[piece]
        width = closed_area / length
        thin = open_piece[piece] or volume[piece] < CARD_VOLUME_SHARE * width * width * length
        is_card[piece] = thin and length >= CARD_ELONGATION * width
    rest = ~is_card[labels]
    if not is_card.any() or not rest.any():
        return none
    rest_vertices = np.flatnonzero(rest)
    largest_side = float(np.ptp(V[rest_vertices], axis=0).max())
    gap, nearest = cKDTree(V[rest_vertices]).query(V[~rest])
    card_vertices = np.flatnonzero(~rest)
    attached = gap <= ATTACH_SHARE * largest_side
    if not attached.any():
        return none
    # A card lying along the body (hair down the back) is near it all along: it hangs from its highest near point.
    near = np.flatnonzero(attached)
    card_label = labels[card_vertices[near]]
    order = np.lexsort((-V[card_vertices[near], 2], card_label))  # per card, highest first
    hanging = near[order[np.r_[True, card_label[order][1:] != card_label[order][:-1]]]]
    card_index = np.full(pieces, -1, dtype=np.int64)
    card_index[labels[card_vertices[hanging]]] = np.arange(len(hanging))
    # The rest's vertex is a welded one: any original copy of it carries its weights.
    original_of_welded = np.zeros(welded.vertex_count, dtype=np.int64)
    original_of_welded[to_welded] = np.arange(vertex_count)
    hangs_from = original_of_welded[rest_vertices[nearest[hanging]]]
    return HangingCards(card_index[labels][to_welded], hangs_from)


def _open_pieces(F: np.ndarray, face_piece: np.ndarray, pieces: int) -> np.ndarray:
    """(pieces,) bool, the pieces with an edge used by one face only."""
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, inverse, counts = np.unique(edges, axis=0, return_inverse=True, return_counts=True)
    boundary_face = np.flatnonzero(counts[inverse.reshape(-1)] == 1) % len(F)
    result = np.zeros(pieces, dtype=bool)
    result[face_piece[boundary_face]] = True
    return result


def _length(points: np.ndarray) -> float:
    """Extent of ``points`` along their principal axis."""
    if len(points) < 2:
        return 0.0
    centred = points - points.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    along = centred @ axis
    return float(along.max() - along.min())
