"""Triangles wound outward, whatever winding the file gave them.

Vertex normals, the proxy's clusters and the networks' features all follow
the triangles' winding (counter-clockwise seen from outside). A mesh whose
faces were applied with a negative scale, exported inside out, or only
partly flipped would be read as another shape, so every job that reads
normals first turns its triangles outward here. The file is never changed:
only the arrays the job reads.

1. **Consistent within a piece.** Triangles sharing an edge with exactly one
   other triangle (seam copies of a vertex count as one vertex, see
   ``same_vertex``) must traverse it in opposite directions. A breadth-first
   walk over that face adjacency from one triangle of each piece turns every
   triangle to agree with the triangle it was reached from; the turn of each
   triangle relative to its piece's first is the parity of the walk's path,
   summed by pointer jumping (no loop over faces). A piece that cannot be
   wound consistently (a Moebius strip) keeps the file's winding unless the
   walk's leaves fewer edges run twice the same way. An edge of three or
   more triangles joins nothing (which of them pair up is unknown), so the
   two sides of such an edge are separate pieces. A triangle given twice is read
   once; given twice with opposite windings it is double-sided (a cloak seen
   from both sides) and has no outside of its own.
2. **Outward per piece.** Each piece is closed up by a fan over each of its
   boundary loops, from the loop's centroid (a hole where the head or a hand
   was a separate object, the ends of a sleeve), and turned so that the
   enclosed volume is positive. That volume is trusted unless the piece is
   flat or thin (:data:`FLAT_SHEET_SHARE`) or, open, mostly hole: fans
   covering more than :data:`MAX_CAP_SHARE` of its area (a dress and a
   shirt are trusted; a bowl, a mouth seen from inside, is not).
3. **The rest follow the file.** A piece that is mostly hole (a cape, a hair
   card, one layer of a wing whose two layers meet only at non-manifold
   edges, a lone triangle) has no inside to tell: it keeps the way most of
   its area faced in the file, unless most of the area of the trusted
   pieces faced inwards (the whole file inside out): then it is turned too.
   With no trusted piece, the closed-up volume of all pieces together decides.

A ray or voxel inside test was not used: an open sheet has no inside (the
voxel solid of :mod:`..distances` is one cell deep there, thinner than a
wing), while the volume closed by its loops is a sum over triangles.
Limits: a separate closed or trusted inner layer modelled to face inwards
(the inside of a shirt not joined to its outside) is read turned outward; a
cape flipped on its own, with the body right, stays flipped.

A mesh already wound outward comes back exactly unchanged.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order, connected_components

from ..types import Mesh
from .weld import weld_vertices

#: A piece whose closed-up volume is at most this share of its area to the
#: power 1.5 is a sheet with no inside to tell: flat (a spherical cap of
#: half-angle t radians gives about 0.14 t, so bent by under 2 degrees), or
#: closed but thinner than about 1 % of its size (a fin of two layers that
#: may cross). A sphere gives 0.094, a limb about 0.03.
FLAT_SHEET_SHARE = 5e-3
#: An open piece whose closing fans have more area than this share of its
#: own is mostly hole and its volume is not trusted: a bowl seen from inside
#: (a nozzle, a mouth) faces inwards on purpose. A hemisphere gives 0.5, a
#: flared skirt about 0.7, a sheet about 1; a dress closed at waist and hem
#: about 0.15, a body without its head and hands a few hundredths.
MAX_CAP_SHARE = 0.25
#: Vertices closer than this share of the bounding-box diagonal are one vertex
#: for the adjacency (0.2 mm on a 2 m character): seam copies, and the rim of
#: a mouth bag modelled apart from the hole it lines, which then continues
#: the head's surface instead of reading as a bowl of its own.
JOIN_SHARE = 1e-4


def inward_triangles(V: np.ndarray, F: np.ndarray, same_vertex: np.ndarray | None = None) -> np.ndarray:
    """Which triangles to turn so that every piece faces outward (module docstring).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    same_vertex : (n,) int array, optional
        One id per vertex, equal for the copies of one vertex split at a
        seam (``weld_vertices``'s ``to_welded``), so triangles meet across
        seams; by default the vertex indices themselves.

    Returns
    -------
    turn : (m,) bool array; triangles with a repeated corner and
        double-sided ones turn only with the whole file
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    ids = F if same_vertex is None else np.asarray(same_vertex, dtype=np.int64)[F]
    proper = np.flatnonzero((ids[:, 0] != ids[:, 1]) & (ids[:, 1] != ids[:, 2]) & (ids[:, 2] != ids[:, 0]))
    if not len(proper):
        return np.zeros(len(F), dtype=bool)
    first_copy, double_sided = _copies(ids[proper])
    read = np.flatnonzero((first_copy == np.arange(len(proper))) & ~double_sided)
    proper_turn = np.zeros(len(proper), dtype=bool)
    inverted = False
    if len(read):
        faces = proper[read]
        relative, piece, paired = _consistent_turns(ids[faces])
        piece_turn, inverted = _inward_pieces(V, F[faces], ids[faces], relative, piece, paired)
        proper_turn[read] = relative ^ piece_turn[piece]
    # Triangles with no side of their own turn with the whole file.
    turn = np.full(len(F), inverted)
    turn[proper] = np.where(double_sided, inverted, proper_turn[first_copy])
    return turn


def outward_triangles(V: np.ndarray, F: np.ndarray,
                      same_vertex: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``F`` with the :func:`inward_triangles` turned (corners 1 and 2 swapped).

    Returns
    -------
    F_out : (m, 3) int64 array; ``F`` itself when nothing turned
    turned : (m,) bool array
    """
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    turned = inward_triangles(V, F, same_vertex)
    if not turned.any():
        return F, turned
    F_out = F.copy()
    F_out[turned] = F[turned][:, [0, 2, 1]]
    return F_out, turned


def outward_mesh(mesh: Mesh) -> tuple[Mesh, np.ndarray]:
    """``mesh`` with its triangles wound outward, vertices closer than
    :data:`JOIN_SHARE` of its diagonal joined for the adjacency; everything
    else kept.

    Returns
    -------
    mesh : Mesh; ``mesh`` itself when nothing turned
    turned : (m,) bool array over its triangles
    """
    to_welded = weld_vertices(mesh.vertices, mesh.triangles, JOIN_SHARE * mesh.bounding_box_diagonal)[2]
    triangles, turned = outward_triangles(mesh.vertices, mesh.triangles, to_welded)
    if not turned.any():
        return mesh, turned
    return Mesh(mesh.vertices, triangles, mesh.triangle_polygons, mesh.object_offsets, mesh.object_names), turned


def inward_faces_note(count: int, reader: str) -> str:
    """What a report says when ``count`` triangles faced inwards and ``reader``
    ("the skeleton prediction") read them turned."""
    what = "1 triangle" if count == 1 else f"{count} triangles"
    return (f"{what} of the mesh faced inwards (flipped normals); {reader} read them turned outward "
            "(the file is unchanged)")


def _consistent_turns(ids: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 1 of the module docstring on (k, 3) triangles of distinct vertex ids.

    Returns
    -------
    relative : (k,) bool, turned relative to the first triangle of its
        piece (none in a piece that keeps the file's winding)
    piece : (k,) int, connected piece of each triangle
    paired : (3k,) bool, each half-edge (rows of ``ids[:, [0, 1, 2]]`` to
        ``ids[:, [1, 2, 0]]``, triangle by triangle) shares its edge with
        exactly one other
    """
    k = len(ids)
    starts, ends = ids.ravel(), ids[:, [1, 2, 0]].ravel()
    width = int(ids.max()) + 1
    keys = np.minimum(starts, ends) * width + np.maximum(starts, ends)
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    first = np.flatnonzero(np.r_[True, sorted_keys[1:] != sorted_keys[:-1]])
    counts = np.diff(np.r_[first, len(keys)])
    paired = np.zeros(len(keys), dtype=bool)
    pair_first = first[counts == 2]
    one, other = order[pair_first], order[pair_first + 1]
    paired[one] = paired[other] = True
    face_a, face_b = one // 3, other // 3
    # Traversed the same way: one of the two must turn relative to the other.
    same_way = (starts[one] < ends[one]) == (starts[other] < ends[other])
    # Two triangles on the same three ids share three edges: one link each.
    # ``links`` comes sorted, so a link is found again by binary search.
    links, unique = np.unique(np.minimum(face_a, face_b) * k + np.maximum(face_a, face_b), return_index=True)
    face_a, face_b, same_way = face_a[unique], face_b[unique], same_way[unique]
    adjacency = sp.coo_matrix((np.ones(len(face_a)), (face_a, face_b)), shape=(k, k))
    piece_count, piece = connected_components(adjacency, directed=False)
    # A root node k links the first triangle of every piece, so one walk reaches all of them.
    _, piece_first = np.unique(piece, return_index=True)
    rows = np.r_[face_a, piece_first]
    cols = np.r_[face_b, np.full(piece_count, k)]
    walk = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(k + 1, k + 1))
    _, predecessors = breadth_first_order(walk, k, directed=False, return_predecessors=True)
    up = predecessors.astype(np.int64)
    up[k] = k
    faces = np.flatnonzero(up[:k] != k)
    found = np.searchsorted(links, np.minimum(faces, up[faces]) * k + np.maximum(faces, up[faces]))
    turn = np.zeros(k + 1, dtype=bool)
    turn[faces] = same_way[found]
    # Pointer jumping: after each pass, turn[i] is the parity from i to up[i],
    # up[i] twice as many steps toward the root.
    while (up != k).any():
        turn, up = turn ^ turn[up], up[up]
    turn = turn[:k]
    # A piece that cannot be wound consistently (a Moebius strip) keeps the
    # file's winding unless the walk leaves fewer edges run twice the same way.
    walk_conflicts = np.bincount(piece[face_a], same_way ^ turn[face_a] ^ turn[face_b], minlength=piece_count)
    file_conflicts = np.bincount(piece[face_a], same_way, minlength=piece_count)
    return turn & (walk_conflicts < file_conflicts)[piece], piece, paired


def _copies(ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles on the same three vertex ids, among (k, 3) ``ids`` of distinct ids.

    Returns
    -------
    first_copy : (k,) int, the first triangle on the same ids (itself when alone)
    double_sided : (k,) bool, its ids also carry a triangle of the other winding
    """
    k = len(ids)
    corners = np.sort(ids, axis=1)
    order = np.lexsort(corners.T[::-1])
    ordered = corners[order]
    new = np.r_[True, np.any(ordered[1:] != ordered[:-1], axis=1)]
    group = np.empty(k, dtype=np.int64)
    group[order] = np.cumsum(new) - 1
    first = np.full(int(group.max()) + 1, k, dtype=np.int64)
    np.minimum.at(first, group, np.arange(k))
    # A cyclic turn of ascending ids climbs twice in its three steps; the other winding once.
    ascending = (ids < np.roll(ids, -1, axis=1)).sum(axis=1) == 2
    windings = np.bincount(group, weights=ascending)
    double_sided = ((windings > 0) & (windings < np.bincount(group)))[group]
    return first[group], double_sided


def _inward_pieces(V: np.ndarray, F: np.ndarray, ids: np.ndarray, relative: np.ndarray, piece: np.ndarray,
                   paired: np.ndarray) -> tuple[np.ndarray, bool]:
    """Steps 2 and 3 of the module docstring.

    ``F`` (k, 3) and their vertex ``ids`` are wound as in the file, and
    consistently within each piece once the ``relative`` rows are turned.

    Returns
    -------
    piece_turn : (pieces,) bool, turn the piece (its consistent winding)
    inverted : bool, most of the file faced inwards
    """
    count = int(piece.max()) + 1
    consistent = np.where(relative[:, None], F[:, [0, 2, 1]], F)
    # Volumes about the centre of the triangles' box: a closed surface's does
    # not depend on the point, and near the shape it loses the fewest digits.
    a, b, c = V[consistent[:, 0]], V[consistent[:, 1]], V[consistent[:, 2]]
    origin = 0.5 * (np.minimum(np.minimum(a, b), c).min(axis=0) + np.maximum(np.maximum(a, b), c).max(axis=0))
    V, a, b, c = V - origin, a - origin, b - origin, c - origin
    areas = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    piece_area = np.bincount(piece, areas, minlength=count)
    volume = np.bincount(piece, np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0, minlength=count)
    # The boundary half-edges, running the way the consistent winding runs them.
    half = np.flatnonzero(~paired)
    owner, corner = half // 3, half % 3
    turned = relative[owner]
    ahead = (corner + 1) % 3
    starts = np.where(turned, F[owner, ahead], F[owner, corner])
    ends = np.where(turned, F[owner, corner], F[owner, ahead])
    start_ids = np.where(turned, ids[owner, ahead], ids[owner, corner])
    end_ids = np.where(turned, ids[owner, corner], ids[owner, ahead])
    fan_volume, cap_area = _fans(V, starts, ends, start_ids, end_ids, piece[owner], count)
    volume += fan_volume
    trusted = (np.abs(volume) > FLAT_SHEET_SHARE * piece_area ** 1.5) & (cap_area <= MAX_CAP_SHARE * piece_area)
    # The piece_turn that keeps the winding most of each piece's area had in the file.
    turned_area = np.bincount(piece, areas * relative, minlength=count)
    as_in_file = turned_area > piece_area - turned_area
    outward = volume < 0
    if trusted.any():
        # Area of the trusted pieces that faced inwards in the file.
        inward_area = np.where(outward, piece_area - turned_area, turned_area)[trusted].sum()
        inverted = bool(inward_area > 0.5 * piece_area[trusted].sum())
    else:
        file_volume = np.where(as_in_file, -volume, volume).sum()
        inverted = bool(file_volume < -FLAT_SHEET_SHARE * piece_area.sum() ** 1.5)
    return np.where(trusted, outward, as_in_file ^ inverted), inverted


def _fans(V: np.ndarray, starts: np.ndarray, ends: np.ndarray, start_ids: np.ndarray, end_ids: np.ndarray,
          piece: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The fans that close each piece's boundary loops: (count,) volume and
    (count,) area per piece.

    Boundary half-edge ``h`` runs from vertex ``starts[h]`` to ``ends[h]``
    (ids ``start_ids``, ``end_ids``) in piece ``piece[h]``; half-edges
    meeting at a vertex id of the same piece form one loop, closed by the
    triangles (loop centroid, end, start), which run each edge backwards."""
    if not len(starts):
        return np.zeros(count), np.zeros(count)
    width = int(max(start_ids.max(), end_ids.max())) + 1
    _, nodes = np.unique(np.r_[piece * width + start_ids, piece * width + end_ids], return_inverse=True)
    node_count = int(nodes.max()) + 1
    half = len(starts)
    chain = sp.coo_matrix((np.ones(half), (nodes[:half], nodes[half:])), shape=(node_count, node_count))
    loop = connected_components(chain, directed=False)[1][nodes[:half]]
    loop_count = int(loop.max()) + 1
    members = np.bincount(loop, minlength=loop_count)[:, None]
    centroids = np.stack([np.bincount(loop, V[starts, axis], minlength=loop_count) for axis in range(3)], axis=1)
    apex = (centroids / members)[loop]
    # Tetrahedra from the origin to the fan triangles (apex, end, start).
    volumes = np.einsum("ij,ij->i", apex, np.cross(V[ends], V[starts])) / 6.0
    areas = 0.5 * np.linalg.norm(np.cross(V[ends] - apex, V[starts] - apex), axis=1)
    return np.bincount(piece, volumes, minlength=count), np.bincount(piece, areas, minlength=count)
