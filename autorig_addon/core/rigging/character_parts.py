"""What of a mesh is the character: a ground plane, stray specks, several characters.

The meshes a user rigs together (a selection, or every mesh of a file) are
read as one world-space mesh, and the skeleton prediction reads all of it:
a ground plane got bones on its corners and was bound too, a stray
triangle 100 m away got a 97 m bone, two characters got one armature
spanning both. This module tells them apart from the shapes alone, in
world space with +Z up (Blender's):

1. **Pieces**: faces joined by edges, the copies a seam splits a vertex into
   welded (:mod:`..geometry.weld`, :mod:`..geometry.topology`). Vertices in
   no face with an area belong to no piece and are left as they are (the
   prediction never reads loose vertices, and refuses a mesh of faces
   without an area naming them).
2. **Ground**: a piece that is flat and level (thinner than
   :data:`GROUND_THICKNESS_SHARE` of its width, :data:`GROUND_FACING_SHARE`
   of its area facing up or down), lies under the rest (its top at most
   :data:`GROUND_HEIGHT_SHARE` of the rest's height above the rest's lowest
   point) and is wider than the rest's footprint: it reaches past it on
   every side by :data:`GROUND_MARGIN_SHARE` of the footprint's longer side
   and covers :data:`GROUND_AREA_RATIO` times its area. The rest is
   measured by its robust box (:func:`..geometry.outliers.robust_box`), so a
   speck does not widen it. A plinth no wider than the character, a thick
   one, a cape or a flat skirt (not under the feet, not wider) stay.
3. **Groups**: the other pieces, gathered while the gap between two
   groups' bounding boxes is at most :data:`SEPARATION_SHARE` of the larger
   one's diagonal (pieces almost touching are joined first on a grid, so
   thousands of hair cards cost little).
4. **Specks**: a group holding under :data:`SPECK_AREA_SHARE` of the area
   whose gap to every group kept as the character is over
   :data:`SPECK_GAP_SHARE` of the character's diagonal: a stray triangle,
   a forgotten vertex cluster. Eyes, buttons, teeth or a loose hat lie
   close to the body and stay.
5. **Several characters**: two or more groups, specks aside, each with at
   least :data:`CHARACTER_SHARE` of the largest group's area or of the
   tallest group's height. A sword dropped beside the character (a small
   share of the area, lying flat) is not a second character and stays.

Ground pieces and specks are *left out*: the skeleton is predicted for the
rest, and the rig job leaves them unweighted, or unbound when a whole
object is left out. Several characters are refused by the rig job with
:func:`several_characters_message`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..geometry.bounding_box import bounding_box_diagonal
from ..geometry.flatness import FACING_ANGLE_DEGREES
from ..geometry.normals import triangle_area_normals
from ..geometry.outliers import robust_box
from ..geometry.topology import connected_component_labels
from ..geometry.weld import seam_tolerance, weld_vertices
from ..messages import listed_names
from ..types import Mesh
from .predict import FLAT_FACE_AREA_SHARE

#: A ground is thinner (its vertical extent) than this share of its width (its longer horizontal side) ...
GROUND_THICKNESS_SHARE = 0.02
#: ... with at least this share of its area facing up or down (within ``flatness.FACING_ANGLE_DEGREES``) ...
GROUND_FACING_SHARE = 0.9
#: ... its top at most this share of the rest's height above the rest's lowest point (feet sunk into it) ...
GROUND_HEIGHT_SHARE = 0.05
#: ... reaching past the rest's footprint on every side by this share of the footprint's longer side ...
GROUND_MARGIN_SHARE = 0.05
#: ... and covering this many times the footprint's area (1.5 times as wide and deep).
GROUND_AREA_RATIO = 2.25
#: Groups whose bounding boxes lie closer than this share of the larger one's diagonal are one group.
SEPARATION_SHARE = 0.1
#: A speck holds under this share of the area of the pieces other than the ground ...
SPECK_AREA_SHARE = 0.005
#: ... and lies farther than this share of the character's diagonal from it.
SPECK_GAP_SHARE = 0.25
#: A group is a character of its own with this share of the largest group's area or of the tallest one's height.
CHARACTER_SHARE = 0.2
#: Cell of the grid joining pieces that almost touch, share of the robust box's diagonal.
TOUCH_CELL_SHARE = 0.005
#: Most groups compared pair by pair (memory: their square); past it the grid's cells are doubled.
MAX_GROUPS = 1000

#: What a left-out part is.
GROUND, SPECK = "ground", "speck"


@dataclass(frozen=True)
class LeftOutPart:
    """Pieces of one object left out of the character for one reason.

    Attributes
    ----------
    object_index : int, the object in the mesh's ``object_names``
    kind : str, :data:`GROUND` or :data:`SPECK`
    pieces : int, how many pieces
    vertices : int, how many of the mesh's vertices (rows) they hold
    whole_object : bool, they are every vertex in a face of the object
    distance : float, a speck's gap to the character (bounding boxes, scene units); 0 for a ground
    """

    object_index: int
    kind: str
    pieces: int
    vertices: int
    whole_object: bool
    distance: float = 0.0


@dataclass(frozen=True)
class CharacterParts:
    """What of a mesh is the character (:func:`character_parts`).

    Attributes
    ----------
    left_out : (n,) bool array over the mesh's vertices, the ground's and the specks'
    piece_of_vertex : (n,) int array, the piece of each vertex, -1 for one in no face with an area
    parts : tuple of LeftOutPart, per object and reason, objects in order, ground first
    characters : tuple of (n,) bool arrays, the vertices of each character when there
        are several (empty otherwise), largest area first
    apart : float, the smallest gap between two of ``characters`` (bounding boxes, scene units)
    """

    left_out: np.ndarray
    piece_of_vertex: np.ndarray
    parts: tuple = ()
    characters: tuple = ()
    apart: float = 0.0

    @property
    def several(self) -> bool:
        """Whether the mesh holds more than one character."""
        return len(self.characters) > 1

    def whole_objects(self) -> list[int]:
        """The objects every face vertex of which is left out, in order."""
        return sorted({part.object_index for part in self.parts if part.whole_object})


def character_parts(mesh: Mesh) -> CharacterParts:
    """Tell the character from a ground plane, stray specks and other
    characters in ``mesh`` (see the module docstring).

    Parameters
    ----------
    mesh : Mesh, world space (+Z up), finite, one or more objects

    Returns
    -------
    CharacterParts
    """
    vertices = mesh.vertices
    piece_of_vertex, pieces = _pieces(mesh)
    left_out = np.zeros(len(vertices), dtype=bool)
    if not pieces.count:
        return CharacterParts(left_out, piece_of_vertex)
    ground = _ground_pieces(vertices, piece_of_vertex, pieces)
    others = np.flatnonzero(~ground)
    group_of_other = _groups(vertices, piece_of_vertex, pieces, others)
    group_count = int(group_of_other.max()) + 1 if len(others) else 0
    group_area = np.bincount(group_of_other, weights=pieces.area[others], minlength=group_count)
    group_low = np.full((group_count, 3), np.inf)
    group_high = np.full((group_count, 3), -np.inf)
    np.minimum.at(group_low, group_of_other, pieces.low[others])
    np.maximum.at(group_high, group_of_other, pieces.high[others])
    speck_groups, speck_distance = _specks(group_area, group_low, group_high)

    group_of_piece = np.full(pieces.count, -1)
    group_of_piece[others] = group_of_other
    in_piece = piece_of_vertex >= 0
    group_of_vertex = np.full(len(vertices), -1)
    group_of_vertex[in_piece] = group_of_piece[piece_of_vertex[in_piece]]
    left_out[in_piece] = ground[piece_of_vertex[in_piece]]
    speck_vertex = (group_of_vertex >= 0) & speck_groups[np.maximum(group_of_vertex, 0)]
    left_out |= speck_vertex

    characters, apart = _characters(group_area, group_low, group_high, speck_groups)
    character_masks = tuple(group_of_vertex == group for group in characters) if len(characters) > 1 else ()
    parts = _left_out_parts(mesh, piece_of_vertex, left_out & ~speck_vertex, speck_vertex,
                            speck_distance[np.maximum(group_of_vertex, 0)])
    return CharacterParts(left_out, piece_of_vertex, parts, character_masks, apart)


def _left_out_parts(mesh: Mesh, piece_of_vertex: np.ndarray, ground: np.ndarray, speck: np.ndarray,
                    distance: np.ndarray) -> tuple:
    """The :class:`LeftOutPart` of each object and reason, from (n,) masks of
    the ground's and the specks' vertices and (n,) each speck vertex's gap
    to the character. An object is left out whole when every vertex of it
    in a piece is, for either reason."""
    parts = []
    for index in range(len(mesh.object_names)):
        rows = mesh.object_slice(index)
        in_piece = piece_of_vertex[rows] >= 0
        whole = bool(np.array_equal(ground[rows] | speck[rows], in_piece))
        for kind, mask in ((GROUND, ground[rows]), (SPECK, speck[rows])):
            if mask.any():
                gap = float(distance[rows][mask].min()) if kind == SPECK else 0.0
                parts.append(LeftOutPart(index, kind, len(np.unique(piece_of_vertex[rows][mask])),
                                         int(np.count_nonzero(mask)), whole, gap))
    return tuple(parts)


@dataclass(frozen=True)
class _Pieces:
    """Per piece: (p, 3) bounding box corners, (p,) area, (p,) area facing up or down."""

    low: np.ndarray
    high: np.ndarray
    area: np.ndarray
    level_area: np.ndarray

    @property
    def count(self) -> int:
        return len(self.area)


def _pieces(mesh: Mesh) -> tuple[np.ndarray, _Pieces]:
    """(n,) piece of each vertex (-1: in no face with an area) and the pieces' measures."""
    vertices, triangles = mesh.vertices, mesh.triangles
    area_normals = triangle_area_normals(vertices, triangles)
    doubled = np.linalg.norm(area_normals, axis=1)
    # Faces without an area add no shape (the prediction's face count names them): they make no piece.
    has_area = 0.5 * doubled > FLAT_FACE_AREA_SHARE * bounding_box_diagonal(vertices) ** 2
    triangles, area_normals, doubled = triangles[has_area], area_normals[has_area], doubled[has_area]
    in_face = np.zeros(len(vertices), dtype=bool)
    in_face[triangles] = True
    _, welded_triangles, to_welded = weld_vertices(vertices, triangles, seam_tolerance(mesh))
    labels = connected_component_labels(welded_triangles, int(to_welded.max()) + 1 if len(to_welded) else 0)
    piece_of_vertex = np.full(len(vertices), -1)
    _, piece_of_vertex[in_face] = np.unique(labels[to_welded[in_face]], return_inverse=True)
    count = int(piece_of_vertex.max()) + 1
    low = np.full((count, 3), np.inf)
    high = np.full((count, 3), -np.inf)
    np.minimum.at(low, piece_of_vertex[in_face], vertices[in_face])
    np.maximum.at(high, piece_of_vertex[in_face], vertices[in_face])
    level = np.abs(area_normals[:, 2]) >= np.cos(np.radians(FACING_ANGLE_DEGREES)) * doubled
    piece_of_triangle = piece_of_vertex[triangles[:, 0]]
    area = 0.5 * np.bincount(piece_of_triangle, weights=doubled, minlength=count)
    level_area = 0.5 * np.bincount(piece_of_triangle, weights=np.where(level, doubled, 0.0), minlength=count)
    return piece_of_vertex, _Pieces(low, high, area, level_area)


def _ground_pieces(vertices: np.ndarray, piece_of_vertex: np.ndarray, pieces: _Pieces) -> np.ndarray:
    """(p,) bool: the pieces that are a ground under the rest (module docstring)."""
    extent = pieces.high - pieces.low
    width = extent[:, :2].max(axis=1)
    level = ((extent[:, 2] <= GROUND_THICKNESS_SHARE * width) & (pieces.area > 0)
             & (pieces.level_area >= GROUND_FACING_SHARE * pieces.area))
    rest = (piece_of_vertex >= 0) & ~level[np.maximum(piece_of_vertex, 0)]
    if not level.any() or not rest.any():
        return np.zeros(pieces.count, dtype=bool)
    low, high = robust_box(vertices[rest])
    footprint = high[:2] - low[:2]
    margin = GROUND_MARGIN_SHARE * footprint.max()
    under = pieces.high[:, 2] <= low[2] + GROUND_HEIGHT_SHARE * (high[2] - low[2])
    past = np.all(pieces.low[:, :2] <= low[:2] - margin, axis=1) & np.all(pieces.high[:, :2] >= high[:2] + margin,
                                                                           axis=1)
    covering = extent[:, 0] * extent[:, 1] >= GROUND_AREA_RATIO * footprint[0] * footprint[1]
    return level & under & past & covering


def _groups(vertices: np.ndarray, piece_of_vertex: np.ndarray, pieces: _Pieces, chosen: np.ndarray) -> np.ndarray:
    """(len(chosen),) group of each of the ``chosen`` pieces, numbered from 0
    (module docstring: pieces almost touching joined on a grid, then
    groups joined while their gap is small for the larger one)."""
    if not len(chosen):
        return np.zeros(0, dtype=np.int64)
    index_of_piece = np.full(pieces.count, -1)
    index_of_piece[chosen] = np.arange(len(chosen))
    owner = index_of_piece[np.maximum(piece_of_vertex, 0)]
    inside = (piece_of_vertex >= 0) & (owner >= 0)
    points, owner = vertices[inside], owner[inside]
    low, high = robust_box(points)
    cell = max(TOUCH_CELL_SHARE * float(np.linalg.norm(high - low)), 1e-12)
    while True:
        count, group = _touching(points, owner, len(chosen), cell)
        if count <= MAX_GROUPS:
            break
        cell *= 2.0
    group_low = np.full((count, 3), np.inf)
    group_high = np.full((count, 3), -np.inf)
    np.minimum.at(group_low, group, pieces.low[chosen])
    np.maximum.at(group_high, group, pieces.high[chosen])
    while True:
        diagonal = np.linalg.norm(group_high - group_low, axis=1)
        close = _box_gaps(group_low, group_high) <= SEPARATION_SHARE * np.maximum.outer(diagonal, diagonal)
        merged_count, merged = connected_components(sp.csr_matrix(close), directed=False)
        if merged_count == count:
            return group
        low_of, high_of = np.full((merged_count, 3), np.inf), np.full((merged_count, 3), -np.inf)
        np.minimum.at(low_of, merged, group_low)
        np.maximum.at(high_of, merged, group_high)
        count, group, group_low, group_high = merged_count, merged[group], low_of, high_of


def _touching(points: np.ndarray, owner: np.ndarray, owner_count: int, cell: float) -> tuple[int, np.ndarray]:
    """Join the owners of points in the same or neighbouring cells of a grid
    of ``cell``; returns the number of groups and each owner's group."""
    keys = np.floor(points / cell).astype(np.int64)
    # Each axis's cells numbered by rank, so the packed key stays small however far the points spread.
    levels = [np.unique(keys[:, axis]) for axis in range(3)]
    strides = (len(levels[1]) * len(levels[2]), len(levels[2]), 1)
    packed = sum(np.searchsorted(levels[axis], keys[:, axis]) * strides[axis] for axis in range(3))
    cells, first, cell_of_point = np.unique(packed, return_index=True, return_inverse=True)
    cell_owner = owner[first]
    pairs = [np.stack([owner, cell_owner[cell_of_point]], axis=1)]
    cell_keys = keys[first]
    for offset in np.array(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1])).reshape(3, -1).T:
        if not offset.any():
            continue
        shifted = cell_keys + offset
        found = np.ones(len(cells), dtype=bool)
        neighbour = np.zeros(len(cells), dtype=np.int64)
        for axis in range(3):
            rank = np.minimum(np.searchsorted(levels[axis], shifted[:, axis]), len(levels[axis]) - 1)
            found &= levels[axis][rank] == shifted[:, axis]
            neighbour += rank * strides[axis]
        at = np.minimum(np.searchsorted(cells, neighbour), len(cells) - 1)
        found &= cells[at] == neighbour
        pairs.append(np.stack([cell_owner[found], cell_owner[at[found]]], axis=1))
    pairs = np.concatenate(pairs)
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(owner_count, owner_count))
    return connected_components(graph.tocsr(), directed=False)


def _box_gaps(low: np.ndarray, high: np.ndarray, other_low: np.ndarray | None = None,
              other_high: np.ndarray | None = None) -> np.ndarray:
    """(g, h) distances between axis-aligned boxes (0 where they overlap): of
    ``low``/``high`` (g, 3) to ``other_low``/``other_high`` (h, 3), or to themselves."""
    if other_low is None:
        other_low, other_high = low, high
    squared = np.zeros((len(low), len(other_low)))
    for axis in range(3):
        apart = np.maximum(other_low[None, :, axis] - high[:, None, axis],
                           low[:, None, axis] - other_high[None, :, axis])
        squared += np.maximum(apart, 0.0) ** 2
    return np.sqrt(squared)


def _specks(area: np.ndarray, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(g,) bool: the groups that are specks, and (g,) each group's gap to the
    nearest group kept as the character (module docstring)."""
    minor = area < SPECK_AREA_SHARE * area.sum()
    specks = minor.copy()
    gaps = np.zeros(len(area))
    while True:
        kept = ~specks
        if not kept.any():
            return np.zeros(len(area), dtype=bool), gaps
        size = float(np.linalg.norm(high[kept].max(axis=0) - low[kept].min(axis=0)))
        gaps = _box_gaps(low, high, low[kept], high[kept]).min(axis=1)
        # Groups kept so far stay kept; a minor group near one of them joins the character, and the check repeats.
        now = minor & (gaps > SPECK_GAP_SHARE * size)
        if np.array_equal(now, specks):
            return specks, gaps
        specks = now


def _characters(area: np.ndarray, low: np.ndarray, high: np.ndarray, specks: np.ndarray) -> tuple[list[int], float]:
    """The groups that are characters of their own (module docstring),
    largest area first, and the smallest gap between two of them (0 for one)."""
    candidates = np.flatnonzero(~specks)
    if len(candidates) < 2:
        return candidates.tolist(), 0.0
    height = high[:, 2] - low[:, 2]
    if area[candidates].max() <= 0:
        return candidates[:1].tolist(), 0.0
    big = (area >= CHARACTER_SHARE * area[candidates].max()) | (height >= CHARACTER_SHARE * height[candidates].max())
    chosen = candidates[big[candidates]]
    chosen = chosen[np.argsort(-area[chosen], kind="stable")]
    if len(chosen) < 2:
        return chosen.tolist(), 0.0
    gaps = _box_gaps(low[chosen], high[chosen])
    return chosen.tolist(), float(gaps[np.triu_indices(len(chosen), 1)].min())


# --------------------------------------------------------------------------- wording


def distance_text(distance: float) -> str:
    """A distance in the scene's units, read as metres (Blender's default): "97 m"."""
    return f"{distance:.3g} m"


def left_out_notes(mesh: Mesh, parts: CharacterParts, *, bound: bool) -> list[str]:
    """What the report says about each part left out (``bound``: the run
    binds the meshes, so the pieces stay unweighted and whole objects
    unbound)."""
    notes = []
    for part in parts.parts:
        name = mesh.object_names[part.object_index]
        if part.whole_object:
            fate = "left out of the skeleton" + (" and not bound" if bound else "")
            if part.kind == GROUND:
                notes.append(f"'{name}' is flat, under the character and wider than it: {fate} (a ground plane?)")
            else:
                notes.append(f"'{name}' lies {distance_text(part.distance)} from the character: {fate} "
                             "(a stray speck?)")
            continue
        fate = "left out of the skeleton" + (" and left unweighted" if bound else "")
        verb = "was" if part.pieces == 1 else "were"
        if part.kind == GROUND:
            what = "a flat piece" if part.pieces == 1 else f"{part.pieces} flat pieces"
            notes.append(f"'{name}': {what} of {part.vertices} vertices under the character and wider than it {verb} "
                         f"{fate} (a ground plane?)")
        else:
            what = "1 loose piece" if part.pieces == 1 else f"{part.pieces} loose pieces"
            notes.append(f"'{name}': {what} of {part.vertices} vertices {distance_text(part.distance)} from the "
                         f"character {verb} {fate} (a stray speck?)")
    return notes


def several_characters_message(mesh: Mesh, parts: CharacterParts, fix: str) -> str:
    """The refusal of a mesh holding several characters: who they are, how
    far apart, and ``fix`` (how to rig them one at a time, as the run was started)."""
    descriptions = [_description(mesh, parts.piece_of_vertex >= 0, character) for character in parts.characters]
    objects = [{name for name, _ in description} for description in descriptions]
    count = len(parts.characters)
    if all(len(names) == 1 for names in objects) and len(set.union(*objects)) == 1:
        (name,) = objects[0]
        who = f"{count} parts of '{name}'"
    else:
        texts = [" with ".join(filter(None, [listed_names([n for n, whole in description if whole], quoted=True),
                                             _parts_text([n for n, whole in description if not whole])]))
                 for description in descriptions]
        who = ", ".join(texts[:-1]) + " and " + texts[-1]
    subject = f"'{mesh.object_names[0]}' holds" if len(mesh.object_names) == 1 else "The meshes hold"
    apart = f"{distance_text(parts.apart)} apart" if count == 2 else f"at least {distance_text(parts.apart)} apart"
    span = "both" if count == 2 else "them all"
    return (f"{subject} {count} characters: {who} standing {apart}. One armature would span {span}: rig them one at "
            f"a time: {fix}. Nothing was built.")


def _description(mesh: Mesh, in_piece: np.ndarray, vertices: np.ndarray) -> list[tuple[str, bool]]:
    """(object name, whole) for each object with vertices in the mask
    ``vertices``: whole when none of its other vertices lies in a piece
    (``in_piece``, (n,) bool)."""
    description = []
    for index, name in enumerate(mesh.object_names):
        rows = mesh.object_slice(index)
        inside = vertices[rows] & in_piece[rows]
        if inside.any():
            description.append((name, bool(np.array_equal(inside, in_piece[rows]))))
    return description


def _parts_text(names: list[str]) -> str:
    """"part of 'Props'" for objects only partly in a character ("" for none)."""
    return f"part of {listed_names(names, quoted=True)}" if names else ""
