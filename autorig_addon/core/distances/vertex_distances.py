"""Vertex-to-bone distances read off shortest paths on a bone graph.

Stage 5 of the vertex-to-bone distances (see :mod:`.bone_distances`): a
vertex's distance to a bone is the best, over the graph nodes of its cell
and the 26 around it, of the node's path length plus the straight step from
the node's centre to the vertex.
"""

from __future__ import annotations

import numpy as np

from ..geometry.segments import point_segment_distances
from ..progress import ProgressCallback
from .cell_graph import BoneGraph, bone_node_distances
from .grid import NEIGHBOURHOOD_OFFSETS

#: A vertex no path reaches (a loose vertex in no face with no usable cell
#: around it) gets this many times its straight distance to the bone, so
#: every distance is finite and the missing path still counts against it.
UNREACHABLE_PENALTY = 4.0


def vertex_cell_candidates(graph: BoneGraph, vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The nodes around each vertex that may carry its distance.

    Candidates are the nodes of the vertex's cell and its 26 neighbours.

    Returns
    -------
    candidates : (n, 27) int64 array, index into ``query_nodes`` or -1
    query_nodes : (q,) int64 array, the distinct grid nodes involved
    """
    grid = graph.grid
    cells = grid.point_cells(vertices)[:, None, :] + NEIGHBOURHOOD_OFFSETS[None, :, :]
    valid = grid.in_grid(cells)
    node = np.full(valid.shape, -1, dtype=np.int64)
    c = cells[valid]
    node[valid] = graph.nodes.cell_node[c[:, 0], c[:, 1], c[:, 2]]
    query_nodes, inverse = np.unique(node, return_inverse=True)
    inverse = inverse.reshape(node.shape)
    if len(query_nodes) and query_nodes[0] < 0:
        query_nodes = query_nodes[1:]
        inverse = inverse - 1  # the -1 node maps to -1
    return inverse, query_nodes


def combine_vertex_distances(
    graph: BoneGraph,
    vertices: np.ndarray,
    candidates: np.ndarray,
    query_nodes: np.ndarray,
    node_distances: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Vertex distance = min over candidate nodes of (node distance + straight
    step from the node centre to the vertex), layer multiples removed.

    Returns
    -------
    distances : (n, b) float64 array, inf where no candidate is reached
    layers : (n, b) int64 array, the multiples of ``graph.layer_cost`` the
        best path paid (mesh layers crossed; all 0 without a layer cost)
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    best = np.full((len(vertices), graph.bone_count), np.inf)
    padded = np.vstack([node_distances, np.full((1, graph.bone_count), np.inf)])  # row -1: no node
    centres = np.vstack([graph.nodes.centres[query_nodes], np.zeros((1, 3))])
    for k in range(candidates.shape[1]):
        index = candidates[:, k]
        step = np.linalg.norm(centres[index] - vertices, axis=1)
        np.minimum(best, padded[index] + step[:, None], out=best)
    layers = np.zeros(best.shape, dtype=np.int64)
    if graph.layer_cost > 0:
        finite = np.isfinite(best)
        layers[finite] = np.floor(best[finite] / graph.layer_cost).astype(np.int64)
        best[finite] -= layers[finite] * graph.layer_cost
    return best, layers


def fill_unreached(
    distances: np.ndarray, vertices: np.ndarray, heads: np.ndarray, tails: np.ndarray,
    penalty: float = UNREACHABLE_PENALTY,
) -> np.ndarray:
    """Replace inf/NaN entries by ``penalty`` x straight vertex-to-bone distance.

    Parameters
    ----------
    distances : (n, b) float64 array
    vertices : (n, 3) float64 array
    heads, tails : (b, 3) float64 arrays
    penalty : float >= 1

    Returns
    -------
    (n, b) float64 array with only finite entries (``distances`` itself when
    it has no other).
    """
    bad = ~np.isfinite(distances)
    if not bad.any():
        return distances
    out = distances.copy()
    rows = np.flatnonzero(bad.any(axis=1))
    straight = point_segment_distances(vertices[rows], heads, tails)
    out[rows] = np.where(bad[rows], penalty * straight, distances[rows])
    return out


def vertex_distances_on_graph(graph: BoneGraph, vertices: np.ndarray,
                              progress: ProgressCallback | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Shortest-path distances from every vertex to every bone of ``graph``,
    through the vertex's candidate cells (see :func:`combine_vertex_distances`).

    Returns
    -------
    distances : (n, b) float64 array, inf where no candidate is reached
    layers : (n, b) int64 array, mesh layers the best path crossed
    """
    candidates, query_nodes = vertex_cell_candidates(graph, vertices)
    node_distances = bone_node_distances(graph, query_nodes, progress)
    return combine_vertex_distances(graph, vertices, candidates, query_nodes, node_distances)
