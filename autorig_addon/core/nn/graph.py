"""Edge indices: which nodes send messages to which in a graph network.

An edge index is a (2, e) int64 array: ``edges[0]`` holds the senders
(sources ``j``), ``edges[1]`` the receivers (targets ``i``); a layer
gathers from the senders and aggregates into the receivers. Builders of
one node set (mesh one-ring, geodesic balls, self loops) return their
edges without duplicates, sorted by receiver and then by sender, so every
receiver's edges are one contiguous run. The heterogeneous builders
(vertex-to-bone, bone hierarchy) document their own order.

The neighbourhoods are those of the papers: the mesh one-ring and the
geodesic ball around each vertex (RigNet's GMEdgeConv uses both), each
vertex's nearest bones (RigNet's candidates, HeterSkinNet's vertex-bone
edges) and the bone hierarchy in both directions (SkinningNet's skeleton
stream).

Numpy and scipy only: inference inside Blender uses these too.
"""

from __future__ import annotations

from typing import Optional

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from ..geometry.topology import edges as undirected_mesh_edges
from ..skeleton.hierarchy import root_indices

#: Dijkstra sources per batch in :func:`geodesic_ball_edges`; each batch
#: holds a dense (batch, n) float64 distance block, 256 x 5,000 vertices
#: = 10 MB, so the memory stays small for any proxy mesh.
GEODESIC_SOURCES_PER_BATCH = 256


def mesh_edges(faces, vertex_count: int, *, self_loops: bool = False) -> np.ndarray:
    """The one-ring of every vertex: an edge each way along each mesh edge.

    Parameters
    ----------
    faces : (m, 3) int array of triangles
    vertex_count : int
        Number of vertices ``n``; vertices in no triangle get no edges
        (or only their self loop).
    self_loops : bool
        Also give every vertex an edge to itself.

    Returns
    -------
    edges : (2, e) int64, sorted by receiver then sender, no duplicates
        Example: triangles ``[[0, 1, 2], [0, 2, 3]]`` give
        ``[[1, 2, 3, 0, 2, 0, 1, 3, 0, 2], [0, 0, 0, 1, 1, 2, 2, 2, 3, 3]]``.
    """
    undirected = _mesh_edge_pairs(faces, vertex_count)
    both_ways = np.concatenate([undirected.T, undirected.T[::-1]], axis=1)
    if self_loops:
        return with_self_loops(both_ways, vertex_count)
    return _sorted_unique(both_ways, vertex_count)


def geodesic_ball_edges(
    vertices,
    faces,
    radius: float,
    *,
    max_neighbours: Optional[int] = None,
    self_loops: bool = False,
    sources_per_batch: int = GEODESIC_SOURCES_PER_BATCH,
) -> tuple[np.ndarray, np.ndarray]:
    """Edges from every vertex within ``radius`` of each vertex, the
    distance measured along mesh edges (shortest edge path, Dijkstra).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array of triangles
    radius : float
        Ball radius in the units of ``vertices``; a vertex at exactly
        ``radius`` is inside.
    max_neighbours : int, optional
        Keep only each receiver's nearest senders (ties: lower index
        first), which bounds the edge count on dense meshes; the ball is
        then no longer symmetric. Self loops do not count towards it.
    self_loops : bool
        Also give every vertex an edge to itself (distance 0).
    sources_per_batch : int
        Dijkstra sources per batch (memory: ``sources_per_batch * n``
        floats); the result does not depend on it.

    Returns
    -------
    edges : (2, e) int64, sorted by receiver then sender, no duplicates
    distances : (e,) float64 edge-path distance of each edge
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    vertex_count = len(vertices)
    if not radius >= 0:
        raise ValueError(f"The geodesic radius must be >= 0, got {radius}.")
    if max_neighbours is not None and max_neighbours < 1:
        raise ValueError(f"max_neighbours must be at least 1, got {max_neighbours}.")
    pairs = _mesh_edge_pairs(faces, vertex_count)
    lengths = np.linalg.norm(vertices[pairs[:, 1]] - vertices[pairs[:, 0]], axis=1)
    # Built directly as CSR so a zero-length edge (coincident vertices) stays
    # an explicit entry, which csgraph reads as an edge of length 0.
    graph = sp.csr_matrix((lengths, (pairs[:, 0], pairs[:, 1])), shape=(vertex_count, vertex_count))
    receivers, senders, distances = [], [], []
    for start in range(0, vertex_count, max(1, int(sources_per_batch))):
        sources = np.arange(start, min(vertex_count, start + int(sources_per_batch)))
        block = dijkstra(graph, directed=False, indices=sources, limit=radius)
        rows, columns = np.nonzero(np.isfinite(block))
        receivers.append(sources[rows])
        senders.append(columns)
        distances.append(block[rows, columns])
    receivers = np.concatenate(receivers) if receivers else np.zeros(0, dtype=np.int64)
    senders = np.concatenate(senders) if senders else np.zeros(0, dtype=np.int64)
    distances = np.concatenate(distances) if distances else np.zeros(0)
    others = receivers != senders  # a vertex is always in its own ball; self loops are added below
    receivers, senders, distances = receivers[others], senders[others], distances[others]
    if max_neighbours is not None and len(receivers):
        by_distance = np.lexsort((senders, distances, receivers))
        receivers, senders, distances = receivers[by_distance], senders[by_distance], distances[by_distance]
        rank = np.arange(len(receivers)) - np.searchsorted(receivers, receivers, side="left")
        nearest = rank < max_neighbours
        receivers, senders, distances = receivers[nearest], senders[nearest], distances[nearest]
    if self_loops:
        loops = np.arange(vertex_count)
        receivers = np.concatenate([receivers, loops])
        senders = np.concatenate([senders, loops])
        distances = np.concatenate([distances, np.zeros(vertex_count)])
    order = np.lexsort((senders, receivers))
    edges = np.stack([senders[order], receivers[order]]).astype(np.int64)
    return edges, distances[order]


def with_self_loops(edges, node_count: int) -> np.ndarray:
    """``edges`` plus an edge from every node to itself.

    Parameters
    ----------
    edges : (2, e) int array over ``node_count`` nodes
    node_count : int

    Returns
    -------
    (2, e') int64, sorted by receiver then sender, no duplicates (a self
    loop already present is kept once).
    """
    loops = np.arange(node_count, dtype=np.int64)
    return _sorted_unique(np.concatenate([np.asarray(edges, dtype=np.int64).reshape(2, -1),
                                          np.stack([loops, loops])], axis=1), node_count)


def vertex_bone_edges(distances, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Each vertex's ``k`` nearest bones under a given distance.

    Parameters
    ----------
    distances : (n, b) float array
        Distance from each vertex to each bone (volumetric geodesic,
        HollowDist, ...).
    k : int
        Bones per vertex; a skeleton with fewer than ``k`` bones gives every
        vertex all its bones.

    Returns
    -------
    edges : (2, n * min(k, b)) int64
        ``edges[0]`` the vertex, ``edges[1]`` the bone (messages vertex ->
        bone; ``edges[::-1]`` carries them bone -> vertex). Vertex by vertex,
        nearest bone first, ties to the lower bone index. Example: distances
        ``[[3, 1, 2], [0.5, 0.5, 4]]`` and ``k=2`` give
        ``[[0, 0, 1, 1], [1, 2, 0, 1]]``.
    edge_distances : (n * min(k, b),) float64, the distance of each edge
    """
    distances = np.asarray(distances, dtype=np.float64)
    if distances.ndim != 2:
        raise ValueError(f"distances must be a (vertices, bones) matrix, got shape {distances.shape}.")
    if k < 1:
        raise ValueError(f"k must be at least 1, got {k}.")
    vertex_count, bone_count = distances.shape
    kept = min(int(k), bone_count)
    nearest = np.argsort(distances, axis=1, kind="stable")[:, :kept]
    vertices = np.repeat(np.arange(vertex_count, dtype=np.int64), kept)
    bones = nearest.reshape(-1).astype(np.int64)
    return np.stack([vertices, bones]), distances[vertices, bones]


def hierarchy_edges(parents) -> np.ndarray:
    """Bone-to-bone edges along the hierarchy, both directions.

    Parameters
    ----------
    parents : (j,) int array, parent index per bone, -1 for roots (any
        order, see :mod:`autorig_addon.core.skeleton.hierarchy`)

    Returns
    -------
    edges : (2, 2c) int64, ``c`` = number of bones with a parent
        The first ``c`` columns are parent -> child, children in index
        order; the last ``c`` the same pairs child -> parent. Example:
        ``parents = [-1, 0, 1, 2, 1]`` give
        ``[[0, 1, 2, 1, 1, 2, 3, 4], [1, 2, 3, 4, 0, 1, 2, 1]]``.
    """
    parents = np.asarray(parents, dtype=np.int64).reshape(-1)
    has_parent = np.ones(len(parents), dtype=bool)
    has_parent[root_indices(parents)] = False  # also checks every index
    children = np.flatnonzero(has_parent)
    downwards = np.stack([parents[children], children])
    return np.concatenate([downwards, downwards[::-1]], axis=1)


def _mesh_edge_pairs(faces, vertex_count: int) -> np.ndarray:
    """(u, 2) int64 undirected mesh edges, checked against ``vertex_count``."""
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) and (faces.min() < 0 or faces.max() >= vertex_count):
        raise ValueError(f"A triangle refers to a vertex outside 0..{vertex_count - 1}.")
    return undirected_mesh_edges(faces).astype(np.int64).reshape(-1, 2)


def _sorted_unique(edges: np.ndarray, node_count: int) -> np.ndarray:
    """Distinct columns of ``edges``, sorted by receiver then sender."""
    if node_count == 0:
        return np.zeros((2, 0), dtype=np.int64)
    keys = np.unique(edges[1].astype(np.int64) * node_count + edges[0])
    return np.stack([keys % node_count, keys // node_count])
