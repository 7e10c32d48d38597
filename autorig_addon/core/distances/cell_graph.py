"""Path graphs over a voxel grid, with one source per bone, and their shortest paths.

Stages 3 and 4 of the vertex-to-bone distances (see :mod:`.bone_distances`):
:func:`merge_cells`, :func:`neighbour_node_pairs` and
:func:`assemble_bone_graph` turn the cells a path may use into a graph of
26-connected steps weighted by their length between groups of cells, plus
one virtual source node per bone; :func:`bone_node_distances` runs Dijkstra
from every bone.

Why groups of cells: a per-bone Dijkstra costs time in proportion to the
graph size, and at 256 cells a side the air and thick interiors hold
millions of cells. Two kinds of grouping keep the graph small without
joining anything the cells keep apart: the cells of one class in an aligned
2 x 2 x 2 block (all of them are 26-neighbours already) form one node, and
aligned 4, 8, ... blocks of one class far from the surface and the bones
(where paths are straight) form one node each, an adaptive octree without
the tree. Paths are measured between group centres, so their lengths are
known to about a cell; which parts connect is decided at full resolution.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from ..progress import ProgressCallback, report
from .grid import FORWARD_OFFSETS, VoxelGrid, bone_mask, dilate

#: Largest merged block, in cells per side (a power of two).
MAX_BLOCK_CELLS = 8
#: Memory for one batch of Dijkstra results (8 bytes per node per bone);
#: bones are processed in batches that fit.
DIJKSTRA_BATCH_BYTES = 64 << 20
#: Stored step lengths are kept at least this many cells long: scipy drops
#: zero-length edges.
MIN_EDGE_CELLS = 1e-9


@dataclass(frozen=True)
class GridNodes:
    """The nodes of a path graph: groups of cells of one class.

    Attributes
    ----------
    cell_node : (nx, ny, nz) int64 array
        Node of each cell, -1 for cells paths may not enter.
    centres : (N, 3) float64 array
        World position of each node: the mean of its cells' centres.
    node_class : (N,) int16 array
        The class shared by the node's cells (see :func:`merge_cells`).
    """

    cell_node: np.ndarray
    centres: np.ndarray
    node_class: np.ndarray

    @property
    def count(self) -> int:
        return len(self.centres)


def fine_cells(grid: VoxelGrid, heads: np.ndarray, tails: np.ndarray, margin_cells: int) -> np.ndarray:
    """(nx, ny, nz) bool: cells within ``margin_cells`` 26-steps of the surface
    or of a bone, which stay out of big blocks (see :func:`merge_cells`) so
    paths that bend around the surface or start at a bone keep full resolution."""
    return dilate(grid.surface | bone_mask(grid, heads, tails), margin_cells)


def merge_cells(
    grid: VoxelGrid, classes: np.ndarray, coarsen: np.ndarray, max_block: int = MAX_BLOCK_CELLS
) -> GridNodes:
    """Group cells into graph nodes.

    Two levels of grouping:

    * Pair cells: the cells of one class inside an aligned 2 x 2 x 2 block
      form one node. Any two cells of such a block are 26-neighbours, so this
      joins nothing the cell graph did not already join (and, with a
      conservative voxelisation, no step between two cells that are not
      surface cells crosses the mesh); it only measures steps between the
      groups' centres, i.e. at twice the cell size, while parts stay
      separated exactly as finely as the cells separate them.
    * Blocks: aligned cubes of 4, 8, ... ``max_block`` cells per side whose
      cells share one class and are all in ``coarsen`` become one node
      (large empty or interior regions, where paths are straight).

    Parameters
    ----------
    grid : VoxelGrid
    classes : (nx, ny, nz) int array
        -1: no node (paths may not enter); k >= 0: class k (cells of
        different classes never share a node).
    coarsen : (nx, ny, nz) bool array, cells allowed in blocks of 4 and more
    max_block : int, a power of two >= 2

    Returns
    -------
    GridNodes
    """
    classes = np.asarray(classes, dtype=np.int16)
    shape = np.asarray(grid.shape)
    padded_shape = tuple(int(n) for n in -(-shape // max_block) * max_block)
    padded = np.full(padded_shape, -1, dtype=np.int16)
    padded[: shape[0], : shape[1], : shape[2]] = np.where(coarsen, classes, -1)
    # uniform[s]: class of each aligned block of s cells when all its cells share it
    # and may coarsen, else -1.
    uniform = {1: padded}
    size = 1
    while size < max_block:
        finer = uniform[size]
        n = finer.shape
        view = finer.reshape(n[0] // 2, 2, n[1] // 2, 2, n[2] // 2, 2)
        low, high = view.min(axis=(1, 3, 5)), view.max(axis=(1, 3, 5))
        size *= 2
        uniform[size] = np.where(low == high, low, -1).astype(np.int16)
    cell_node = np.full(padded_shape, -1, dtype=np.int64)
    centres, node_class = [], []
    next_id = 0
    covered = None
    for size in sorted(uniform, reverse=True):
        if size < 4:
            break
        coarse = uniform[size].shape
        covered = np.zeros(coarse, dtype=bool) if covered is None else _upsample(covered)
        chosen = (uniform[size] >= 0) & ~covered
        blocks = np.argwhere(chosen)
        ids = np.arange(next_id, next_id + len(blocks))
        view = cell_node.reshape(coarse[0], size, coarse[1], size, coarse[2], size)
        view[blocks[:, 0], :, blocks[:, 1], :, blocks[:, 2], :] = ids[:, None, None, None]
        centres.append(grid.origin + (blocks * size + 0.5 * size) * grid.cell_size)
        node_class.append(uniform[size][chosen])
        covered |= chosen
        next_id += len(blocks)
    cell_node = cell_node[: shape[0], : shape[1], : shape[2]]
    loose = (classes >= 0) & (cell_node < 0)
    cells = np.argwhere(loose)
    pair_block = np.ravel_multi_index((cells // 2).T, tuple(int(n) for n in -(-shape // 2)))
    class_count = max(int(classes.max()) + 1, 1)
    key = pair_block * class_count + classes[loose]
    unique_keys, group = np.unique(key, return_inverse=True)
    cell_node[loose] = next_id + group
    size = np.bincount(group, minlength=len(unique_keys))[:, None]
    mean = np.stack([np.bincount(group, weights=cells[:, a] + 0.5, minlength=len(unique_keys)) for a in range(3)], 1)
    centres.append(grid.origin + mean / size * grid.cell_size)
    node_class.append((unique_keys % class_count).astype(np.int16))
    return GridNodes(np.ascontiguousarray(cell_node), np.concatenate(centres), np.concatenate(node_class))


def _upsample(coarse: np.ndarray) -> np.ndarray:
    """Each cell of ``coarse`` repeated into 2 x 2 x 2 cells."""
    return coarse.repeat(2, axis=0).repeat(2, axis=1).repeat(2, axis=2)


def neighbour_node_pairs(nodes: GridNodes) -> np.ndarray:
    """(e, 2) int64 unordered pairs of nodes holding 26-adjacent cells, each once."""
    index_type = np.int32 if nodes.count < 2**31 - 1 else np.int64
    # A border of -1 cells lets every neighbour be a fixed offset into the
    # flat array: a cell and its neighbour never wrap around a row.
    padded = np.full(tuple(np.asarray(nodes.cell_node.shape) + 2), -1, dtype=index_type)
    padded[1:-1, 1:-1, 1:-1] = nodes.cell_node
    flat = padded.ravel()
    strides = np.array([padded.shape[1] * padded.shape[2], padded.shape[2], 1])
    keys = []
    for offset in FORWARD_OFFSETS:
        delta = int(offset @ strides)  # > 0 for forward offsets
        a, b = flat[:-delta], flat[delta:]
        linked = np.flatnonzero(a != b)
        a, b = a[linked].astype(np.int64), b[linked].astype(np.int64)
        low, high = np.minimum(a, b), np.maximum(a, b)
        key = (low * nodes.count + high)[low >= 0]
        # Runs of cells between the same two nodes repeat a key next to each
        # other: drop those cheaply before the global sort.
        if len(key):
            key = key[np.concatenate([[True], key[1:] != key[:-1]])]
        keys.append(key)
    keys = np.unique(np.concatenate(keys))
    return np.stack([keys // nodes.count, keys % nodes.count], axis=1)


@dataclass(frozen=True)
class BoneGraph:
    """A directed path graph over grid nodes, plus one source node per bone.

    Attributes
    ----------
    grid : VoxelGrid
    nodes : GridNodes, the grid nodes ``0 .. N - 1``
    matrix : (N + b, N + b) scipy.sparse.csr_matrix
        Step lengths in scene units; node ``N + j`` is the virtual source of
        bone ``j`` (edges out of it only, so bones never shortcut paths).
    bone_count : int
    layer_cost : float
        0, or a power of two larger than any geometric path length that
        certain steps add on top of their length (HollowDist counts the mesh
        layers a path crosses this way). Vertex distances drop the multiples.
    """

    grid: VoxelGrid
    nodes: GridNodes
    matrix: sp.csr_matrix
    bone_count: int
    layer_cost: float = 0.0


def assemble_bone_graph(
    grid: VoxelGrid,
    nodes: GridNodes,
    pairs: np.ndarray,
    extra_cost_from: np.ndarray | None,
    layer_cost: float,
    sources: tuple[np.ndarray, np.ndarray, np.ndarray],
    bone_count: int,
) -> BoneGraph:
    """Build the sparse matrix of a :class:`BoneGraph`.

    Parameters
    ----------
    pairs : (e, 2) int64 array, undirected neighbour node pairs
    extra_cost_from : (N,) bool array or None; steps leaving these nodes cost
        ``layer_cost`` more
    layer_cost : float
    sources : (bone (s,) int64, node (s,) int64, length (s,) float64)
        Edges from bone sources to nodes; duplicates keep the shortest.
    bone_count : int
    """
    count = nodes.count
    step = np.linalg.norm(nodes.centres[pairs[:, 0]] - nodes.centres[pairs[:, 1]], axis=1)
    rows = np.concatenate([pairs[:, 0], pairs[:, 1]])
    cols = np.concatenate([pairs[:, 1], pairs[:, 0]])
    lengths = np.concatenate([step, step])
    if extra_cost_from is not None:
        lengths = lengths + np.where(extra_cost_from[rows], layer_cost, 0.0)
    bone, node, length = sources
    order = np.lexsort((length, node, bone))
    bone, node, length = bone[order], node[order], length[order]
    first = np.ones(len(bone), dtype=bool)
    first[1:] = (bone[1:] != bone[:-1]) | (node[1:] != node[:-1])
    floor = MIN_EDGE_CELLS * grid.cell_size
    rows = np.concatenate([rows, count + bone[first]])
    cols = np.concatenate([cols, node[first]])
    lengths = np.maximum(np.concatenate([lengths, length[first]]), floor)
    size = count + bone_count
    matrix = sp.csr_matrix((lengths, (rows, cols)), shape=(size, size))
    return BoneGraph(grid, nodes, matrix, bone_count, layer_cost)


def layer_cost_above(bound: float) -> float:
    """The smallest power of two above ``bound`` (> 0): a per-layer cost whose
    multiples separate exactly from geometric lengths below ``bound`` in float64."""
    return float(2.0 ** (np.floor(np.log2(max(float(bound), 1e-300))) + 1))


def bone_node_distances(
    graph: BoneGraph, query_nodes: np.ndarray, progress: ProgressCallback | None = None
) -> np.ndarray:
    """Shortest path length from every bone to each query node.

    Dijkstra from each bone's virtual source (scipy's C implementation: one
    single-source run per bone, batched to bound memory). Multi-source runs
    with ``min_only`` would merge the bones, so they cannot be used here.

    Parameters
    ----------
    graph : BoneGraph
    query_nodes : (q,) int64 array of grid nodes

    Returns
    -------
    (q, b) float64 array, inf where a bone cannot reach a node.
    """
    size = graph.matrix.shape[0]
    batch = max(1, int(DIJKSTRA_BATCH_BYTES // (8 * size)))
    result = np.empty((len(query_nodes), graph.bone_count))
    first_source = graph.nodes.count
    for start in range(0, graph.bone_count, batch):
        stop = min(start + batch, graph.bone_count)
        distances = dijkstra(graph.matrix, directed=True, indices=np.arange(first_source + start, first_source + stop))
        result[:, start:stop] = distances.reshape(stop - start, size)[:, query_nodes].T
        report(progress, stop / graph.bone_count, "Finding paths from the bones")
    return result
