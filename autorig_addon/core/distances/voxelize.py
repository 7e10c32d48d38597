"""Voxel grids of a mesh and shortest paths on them.

Both vertex-to-bone distances (:mod:`.volumetric_geodesic` and
:mod:`.hollow_dist`) run the same pipeline, and this module holds its
shared stages:

1. :func:`voxelize_surface` marks every cell a triangle touches
   (conservative voxelisation, Schwarz & Seidel 2010), so thin parts such as
   cloth and hair cards are never lost between cells.
2. :func:`fill_interior` marks cells enclosed by the surface.
3. :func:`merge_cells`, :func:`neighbour_node_pairs` and
   :func:`assemble_bone_graph` turn the cells a path may use into a graph:
   26-connected steps weighted by their length between groups of cells (see
   below), and one virtual source node per bone.
4. :func:`bone_node_distances` runs Dijkstra from every bone.
5. :func:`vertex_cell_candidates` and :func:`combine_vertex_distances`
   turn node distances into vertex distances: the best of the nodes around a
   vertex plus the straight step from that node's centre to the vertex.
6. :func:`refine_in_sight` replaces a distance by the straight one where
   the vertex sees the bone, removing the staircase error of cell paths.

Why groups of cells: a per-bone Dijkstra costs time in proportion to the
graph size, and at 256 cells a side the air and thick interiors hold
millions of cells. Two kinds of grouping keep the graph small without
joining anything the cells keep apart: the cells of one class in an aligned
2 x 2 x 2 block (all of them are 26-neighbours already) form one node, and
aligned 4, 8, ... blocks of one class far from the surface and the bones
(where paths are straight) form one node each, an adaptive octree without
the tree. Paths are measured between group centres, so their lengths are
known to about a cell; which parts connect is decided at full resolution.

Units: positions and distances in scene units (those of the mesh vertices);
"cell coordinates" are positions divided by the cell size, measured from the
grid origin, so cell ``(i, j, k)`` spans ``[i, i + 1) x [j, j + 1) x [k, k + 1)``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from scipy import ndimage
from scipy.sparse.csgraph import dijkstra

from ..errors import InputError
from ..geometry.segments import nearest_points_on_segments, point_segment_distances
from ..progress import ProgressCallback, report, sub_progress
from ..types import Mesh

#: Cells along the longest side of the mesh bounding box (both RigNet and
#: HeterSkinNet use 88).
DEFAULT_RESOLUTION = 88
#: Allowed resolutions, in cells along the longest side.
MIN_RESOLUTION = 4
MAX_RESOLUTION = 1024
#: Empty cells added around the mesh on every side, so the outside is one
#: connected region that wraps around the mesh.
DEFAULT_PADDING_CELLS = 2
#: Bones outside the mesh's bounding box widen the grid by at most this
#: fraction of the box's longest side.
COVER_MARGIN = 0.25
#: Triangle/cell pairs tested per batch; bounds memory (about 200 bytes a pair).
PAIR_BATCH = 1 << 18
#: Slack of the triangle/box test, in cells: touching counts as overlapping.
OVERLAP_TOLERANCE_CELLS = 1e-7
#: Spacing of the points sampled along a bone to find the cells it crosses, in cells.
BONE_SAMPLE_SPACING_CELLS = 0.25
#: Largest merged block, in cells per side (a power of two).
MAX_BLOCK_CELLS = 8
#: Memory for one batch of Dijkstra results (8 bytes per node per bone);
#: bones are processed in batches that fit.
DIJKSTRA_BATCH_BYTES = 64 << 20
#: Graph paths are staircases of 26-neighbour steps, at most this many
#: times the straight length (worst direction about (1, 0.41, 0.32)).
STAIRCASE_RATIO = 1.13
#: Besides the staircase, a graph distance may exceed the straight one by up
#: to this many cells (node centres off the bone and off the vertex).
STAIRCASE_SLACK_CELLS = 6.0
#: Stored step lengths are kept at least this many cells long: scipy drops
#: zero-length edges.
MIN_EDGE_CELLS = 1e-9

#: The 26 neighbour offsets and the 13 of them that point "forward" (each
#: undirected neighbour pair is found once through a forward offset).
NEIGHBOUR_OFFSETS = np.array(
    [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) != (0, 0, 0)], dtype=np.int64
)
FORWARD_OFFSETS = NEIGHBOUR_OFFSETS[[tuple(o) > (0, 0, 0) for o in NEIGHBOUR_OFFSETS]]
#: The cell itself and its 26 neighbours.
NEIGHBOURHOOD_OFFSETS = np.array(
    [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)], dtype=np.int64
)


@dataclass(frozen=True)
class VoxelGrid:
    """A regular grid of cubic cells over a mesh.

    Attributes
    ----------
    origin : (3,) float64 array
        World position of the lowest corner of cell ``(0, 0, 0)``.
    cell_size : float
        Edge length of a cell, scene units.
    shape : (3,) int tuple
        Cells along x, y, z.
    surface : (nx, ny, nz) bool array
        Cells touched by a triangle ("mesh cells").
    inside : (nx, ny, nz) bool array
        Cells enclosed by the surface and not touched by it; all False until
        :func:`fill_interior` runs.
    """

    origin: np.ndarray
    cell_size: float
    shape: tuple
    surface: np.ndarray
    inside: np.ndarray

    @property
    def occupied(self) -> np.ndarray:
        """(nx, ny, nz) bool: surface or inside cells (the solid)."""
        return self.surface | self.inside

    @property
    def outside(self) -> np.ndarray:
        """(nx, ny, nz) bool: cells neither on nor inside the surface."""
        return ~(self.surface | self.inside)

    def point_cells(self, points: np.ndarray) -> np.ndarray:
        """(k, 3) int64: cell holding each of the (k, 3) ``points`` (may lie
        outside the grid; see :meth:`in_grid`)."""
        return np.floor((np.asarray(points, dtype=np.float64) - self.origin) / self.cell_size).astype(np.int64)

    def in_grid(self, cells: np.ndarray) -> np.ndarray:
        """(k,) bool: whether each of the (k, 3) integer ``cells`` exists."""
        cells = np.asarray(cells)
        return np.all((cells >= 0) & (cells < np.asarray(self.shape)), axis=-1)

    def cell_centres(self, cells: np.ndarray) -> np.ndarray:
        """(k, 3) float64 world centres of the (k, 3) integer ``cells``."""
        return self.origin + (np.asarray(cells, dtype=np.float64) + 0.5) * self.cell_size


def voxelize_surface(
    mesh: Mesh,
    resolution: int = DEFAULT_RESOLUTION,
    padding_cells: int = DEFAULT_PADDING_CELLS,
    cover_points: np.ndarray | None = None,
    progress: ProgressCallback | None = None,
) -> VoxelGrid:
    """Mark every cell that a triangle of ``mesh`` touches.

    Conservative voxelisation: a cell is a surface cell when the closed cell
    and the closed triangle share a point (separating-axis triangle/box test,
    Akenine-Moeller 2001, as used by Schwarz & Seidel 2010). Hence a
    26-connected step between two non-surface cells never crosses the mesh,
    and one-sided parts (cloth, hair cards) make a wall paths cannot pass.

    Parameters
    ----------
    mesh : Mesh with at least one triangle
    resolution : int
        Cells along the longest side of the voxelised box, the mesh's
        bounding box (:data:`DEFAULT_RESOLUTION` = 88; higher keeps thin gaps
        such as those between fingers open).
    padding_cells : int
        Empty cells added on every side (at least 1 so the outside connects).
    cover_points : (k, 3) float64 array, optional
        Points the grid should also cover (bone ends, so paths through the
        air can start at bones outside the mesh). Each is first clamped to
        the mesh's bounding box grown by :data:`COVER_MARGIN` of its longest
        side, so one far-away bone cannot coarsen the grid.
    progress : optional ProgressCallback

    Returns
    -------
    VoxelGrid with ``surface`` set and ``inside`` all False.
    """
    if not len(mesh.triangles):
        raise InputError("The mesh has no faces; voxelisation needs a surface.")
    if not MIN_RESOLUTION <= int(resolution) <= MAX_RESOLUTION:
        raise InputError(
            f"Voxel resolution must be between {MIN_RESOLUTION} and {MAX_RESOLUTION} cells, got {resolution}."
        )
    if padding_cells < 1:
        raise InputError(f"Voxel padding must be at least 1 cell, got {padding_cells}.")
    used_vertices = mesh.vertices[np.unique(mesh.triangles)]
    if not np.all(np.isfinite(used_vertices)):
        raise InputError("The mesh has vertices at NaN or infinite positions; fix them before skinning.")
    low, high = used_vertices.min(axis=0), used_vertices.max(axis=0)
    extent = high - low
    if extent.max() <= 0.0:
        raise InputError("All vertices of the mesh are at one point; it has no size to voxelise.")
    if cover_points is not None and len(cover_points):
        margin = COVER_MARGIN * extent.max()
        covered = np.clip(np.asarray(cover_points, dtype=np.float64).reshape(-1, 3), low - margin, high + margin)
        low, high = np.minimum(low, covered.min(axis=0)), np.maximum(high, covered.max(axis=0))
        extent = high - low
    cell_size = float(extent.max()) / int(resolution)
    core_cells = np.maximum(np.ceil(extent / cell_size - 1e-9).astype(np.int64), 1)
    # Centre the mesh in its cells so the padding is the same on both sides.
    slack = core_cells * cell_size - extent
    origin = low - padding_cells * cell_size - 0.5 * slack
    shape = tuple(int(n) for n in core_cells + 2 * padding_cells)
    surface = np.zeros(shape, dtype=bool)
    grid = VoxelGrid(origin, cell_size, shape, surface, np.zeros(shape, dtype=bool))
    _mark_triangle_cells(grid, mesh.vertices, mesh.triangles, progress)
    return grid


def _mark_triangle_cells(grid: VoxelGrid, V: np.ndarray, F: np.ndarray, progress: ProgressCallback | None) -> None:
    """Set ``grid.surface`` for every cell touched by a triangle of (V, F).

    Candidate cells of a large triangle are not its whole bounding box but,
    for each column of cells along the axis its normal is closest to, the
    few cells its plane passes through over that column (1 to 3); the exact
    triangle/box test then runs on those only.
    """
    # Work in cell coordinates: cells are unit cubes [i, i + 1).
    corners = (V[F] - grid.origin) / grid.cell_size  # (m, 3, 3)
    tolerance = OVERLAP_TOLERANCE_CELLS
    shape = np.asarray(grid.shape)
    low = np.clip(np.floor(corners.min(axis=1) - tolerance).astype(np.int64), 0, shape - 1)
    high = np.clip(np.floor(corners.max(axis=1) + tolerance).astype(np.int64), 0, shape - 1)
    dims = high - low + 1  # (m, 3) cells of each triangle's bounding box
    # A triangle whose bounding box is one row of cells is connected and spans
    # the row, so it touches every cell of it: no test needed.
    is_row = np.count_nonzero(dims > 1, axis=1) <= 1
    _mark_boxes(grid.surface, low[is_row], dims[is_row], np.prod(dims[is_row], axis=1))
    tested = np.flatnonzero(~is_row)
    if not len(tested):
        return
    normal = np.cross(corners[tested, 1] - corners[tested, 0], corners[tested, 2] - corners[tested, 0])
    # Columns run along w, the normal's largest axis; u, v span the column grid.
    w = np.abs(normal).argmax(axis=1)
    axes = np.stack([(w + 1) % 3, (w + 2) % 3, w], axis=1)  # (t, 3): u, v, w
    low_uvw = np.take_along_axis(low[tested], axes, axis=1)
    dims_uvw = np.take_along_axis(dims[tested], axes, axis=1)
    normal_uvw = np.take_along_axis(normal, axes, axis=1)
    anchor_uvw = np.take_along_axis(corners[tested, 0], axes, axis=1)
    column_counts = dims_uvw[:, 0] * dims_uvw[:, 1]
    column_starts = np.concatenate([[0], np.cumsum(column_counts)])
    total = int(column_starts[-1])
    for batch_start in range(0, total, PAIR_BATCH):
        column = np.arange(batch_start, min(batch_start + PAIR_BATCH, total), dtype=np.int64)
        local = np.searchsorted(column_starts, column, side="right") - 1
        offset = column - column_starts[local]
        iu = low_uvw[local, 0] + offset // dims_uvw[local, 1]
        iv = low_uvw[local, 1] + offset % dims_uvw[local, 1]
        w_low, w_high = _plane_span_over_columns(normal_uvw[local], anchor_uvw[local], iu, iv, tolerance)
        w_low = np.maximum(w_low, low_uvw[local, 2])
        w_high = np.minimum(w_high, low_uvw[local, 2] + dims_uvw[local, 2] - 1)
        counts = np.maximum(w_high - w_low + 1, 0)
        owner = np.repeat(np.arange(len(column)), counts)
        iw = w_low[owner] + np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
        uvw = np.stack([iu[owner], iv[owner], iw], axis=1)
        triangle = tested[local[owner]]
        cells = np.empty_like(uvw)
        np.put_along_axis(cells, axes[local[owner]], uvw, axis=1)
        touches = _triangle_touches_cell(corners[triangle], cells, tolerance)
        hit = cells[touches]
        grid.surface[hit[:, 0], hit[:, 1], hit[:, 2]] = True
        report(progress, batch_start / total, "Voxelising the surface")


def _plane_span_over_columns(normal_uvw, anchor_uvw, iu, iv, tolerance):
    """Lowest and highest w cell the plane (normal, anchor) reaches over the
    column squares [iu, iu + 1] x [iv, iv + 1]; an unbounded span for
    degenerate triangles (zero normal)."""
    nu, nv, nw = normal_uvw[:, 0], normal_uvw[:, 1], normal_uvw[:, 2]
    flat = np.abs(nw) > 0
    safe_nw = np.where(flat, nw, 1.0)
    heights = []
    for du in (0.0, 1.0):
        for dv in (0.0, 1.0):
            heights.append(anchor_uvw[:, 2] - (nu * (iu + du - anchor_uvw[:, 0]) + nv * (iv + dv - anchor_uvw[:, 1])) / safe_nw)
    heights = np.stack(heights, axis=1)
    w_low = np.where(flat, np.floor(heights.min(axis=1) - tolerance), -np.inf)
    w_high = np.where(flat, np.floor(heights.max(axis=1) + tolerance), np.inf)
    big = np.iinfo(np.int64).max // 4
    return np.clip(w_low, -big, big).astype(np.int64), np.clip(w_high, -big, big).astype(np.int64)


def _unravel(index: np.ndarray, dims: np.ndarray) -> np.ndarray:
    """(k, 3) int64 C-order unravel of ``index`` (k,) in boxes of ``dims`` (k, 3)."""
    k = index % dims[:, 2]
    rest = index // dims[:, 2]
    j = rest % dims[:, 1]
    i = rest // dims[:, 1]
    return np.stack([i, j, k], axis=1)


def _mark_boxes(mask: np.ndarray, low: np.ndarray, dims: np.ndarray, counts: np.ndarray) -> None:
    """Set every cell of the boxes ``low[t] + [0, dims[t])`` in ``mask``."""
    if not len(low):
        return
    owner = np.repeat(np.arange(len(low)), counts)
    local = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    cells = low[owner] + _unravel(local, dims[owner])
    mask[cells[:, 0], cells[:, 1], cells[:, 2]] = True


def _triangle_touches_cell(triangles: np.ndarray, cells: np.ndarray, tolerance: float) -> np.ndarray:
    """(k,) bool separating-axis test of k triangles against k unit cells.

    ``triangles`` (k, 3, 3) and ``cells`` (k, 3) are in cell coordinates.
    The axes are the three box normals, the triangle normal and the nine
    edge x box-axis cross products. Touching (distance 0 along every axis)
    counts.
    """
    v = triangles - (cells[:, None, :] + 0.5)  # box centred at the origin, half size 0.5
    touches = np.all((v.min(axis=1) <= 0.5 + tolerance) & (v.max(axis=1) >= -0.5 - tolerance), axis=1)
    edges = np.roll(v, -1, axis=1) - v  # edge i runs from vertex i to vertex i + 1
    normal = np.cross(edges[:, 0], edges[:, 1])
    radius = 0.5 * np.abs(normal).sum(axis=1)
    touches &= np.abs(np.einsum("ij,ij->i", normal, v[:, 0])) <= radius + tolerance * (1.0 + radius)
    for i in range(3):
        e = edges[:, i]
        a, b = v[:, i], v[:, (i + 2) % 3]  # vertex i + 1 projects like vertex i
        for axis in range(3):
            # Axis = unit(axis) x e; projection of p is e . (p x unit(axis)).
            u, w = (axis + 1) % 3, (axis + 2) % 3
            pa = e[:, w] * a[:, u] - e[:, u] * a[:, w]
            pb = e[:, w] * b[:, u] - e[:, u] * b[:, w]
            r = 0.5 * (np.abs(e[:, u]) + np.abs(e[:, w]))
            slack = r + tolerance * (1.0 + r)
            touches &= (np.minimum(pa, pb) <= slack) & (np.maximum(pa, pb) >= -slack)
    return touches


def fill_interior(grid: VoxelGrid) -> VoxelGrid:
    """Mark the cells enclosed by the surface.

    A non-surface cell is outside when a 6-connected path of non-surface
    cells joins it to the border of the grid; every other non-surface cell
    is inside. Open parts (cloth, a body with an open neck) enclose nothing,
    so their interior stays empty: that is the honest answer.

    Returns
    -------
    A new VoxelGrid with ``inside`` set.
    """
    empty = ~grid.surface
    labels, _ = ndimage.label(empty)  # default structure: 6-connectivity
    border = np.concatenate(
        [labels[[0, -1], :, :].ravel(), labels[:, [0, -1], :].ravel(), labels[:, :, [0, -1]].ravel()]
    )
    outside_labels = np.unique(border[border > 0])
    outside = np.isin(labels, outside_labels)
    return replace(grid, inside=empty & ~outside)


def segment_cells(grid: VoxelGrid, heads: np.ndarray, tails: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cells each bone segment passes through.

    Points are sampled along each segment every
    :data:`BONE_SAMPLE_SPACING_CELLS` cells (ends included); a cell counts
    once per bone. Parts of a bone outside the grid give no cells.

    Parameters
    ----------
    heads, tails : (b, 3) float64 arrays, segment ends in world space

    Returns
    -------
    bone : (c,) int64 array, the bone of each entry
    cells : (c, 3) int64 array, its cell
    """
    heads = np.asarray(heads, dtype=np.float64).reshape(-1, 3)
    tails = np.asarray(tails, dtype=np.float64).reshape(-1, 3)
    lengths = np.linalg.norm(tails - heads, axis=1) / grid.cell_size
    samples = np.ceil(lengths / BONE_SAMPLE_SPACING_CELLS).astype(np.int64) + 1
    bone = np.repeat(np.arange(len(heads)), samples)
    step = np.arange(len(bone)) - np.repeat(np.cumsum(samples) - samples, samples)
    t = step / np.maximum(samples[bone] - 1, 1)
    points = heads[bone] + t[:, None] * (tails[bone] - heads[bone])
    cells = grid.point_cells(points)
    keep = grid.in_grid(cells)
    bone, cells = bone[keep], cells[keep]
    flat = np.ravel_multi_index(cells.T, grid.shape)
    _, first = np.unique(bone * np.prod(grid.shape) + flat, return_index=True)
    return bone[first], cells[first]






# --------------------------------------------------------------------------
# Graphs on the grid
# --------------------------------------------------------------------------


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
    distances: np.ndarray, vertices: np.ndarray, heads: np.ndarray, tails: np.ndarray, penalty: float
) -> np.ndarray:
    """Replace inf/NaN entries by ``penalty`` x straight vertex-to-bone distance.

    Returns a new (n, b) float64 array with only finite entries.
    """
    bad = ~np.isfinite(distances)
    if not bad.any():
        return distances
    out = distances.copy()
    rows = np.flatnonzero(bad.any(axis=1))
    straight = point_segment_distances(vertices[rows], heads, tails)
    out[rows] = np.where(bad[rows], penalty * straight, distances[rows])
    return out


def validate_bones(heads: np.ndarray, tails: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(b, 3) float64 heads and tails, checked finite and matching."""
    heads = np.asarray(heads, dtype=np.float64).reshape(-1, 3)
    tails = np.asarray(tails, dtype=np.float64).reshape(-1, 3)
    if len(heads) != len(tails):
        raise InputError("Every bone needs one head and one tail.")
    if not len(heads):
        raise InputError("No bones were given; add deforming bones to the armature.")
    if not (np.all(np.isfinite(heads)) and np.all(np.isfinite(tails))):
        raise InputError("A bone has a NaN or infinite position; fix the armature first.")
    return heads, tails


def dilate(mask: np.ndarray, cells: int = 1) -> np.ndarray:
    """``mask`` grown by ``cells`` steps of 26-connectivity."""
    if cells <= 0:
        return mask.copy()
    return ndimage.binary_dilation(mask, structure=np.ones((3, 3, 3), dtype=bool), iterations=cells)


def bone_mask(grid: VoxelGrid, heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(nx, ny, nz) bool: cells crossed by any bone."""
    mask = np.zeros(grid.shape, dtype=bool)
    _, cells = segment_cells(grid, heads, tails)
    mask[cells[:, 0], cells[:, 1], cells[:, 2]] = True
    return mask


def refine_in_sight(
    grid: VoxelGrid,
    clear: np.ndarray,
    distances: np.ndarray,
    vertices: np.ndarray,
    heads: np.ndarray,
    tails: np.ndarray,
    *,
    test: np.ndarray | None = None,
    leave_start: bool = False,
    end_margin_cells: float = 0.0,
) -> np.ndarray:
    """Replace path distances by straight ones where the bone is in sight.

    A vertex sees a bone when the segment from the vertex to the bone's
    nearest point runs through ``clear`` cells only; the shortest path is
    then that segment. Only pairs whose path distance is within the
    staircase bound of the straight one (:data:`STAIRCASE_RATIO`,
    :data:`STAIRCASE_SLACK_CELLS`) can be in sight, so only those are tested.

    Parameters
    ----------
    grid : VoxelGrid
    clear : (nx, ny, nz) bool array, cells a line of sight may cross
    distances : (n, b) float64 path distances
    vertices : (n, 3) float64 array
    heads, tails : (b, 3) float64 arrays
    test : (n, b) bool array, optional; only these pairs may be refined
    leave_start : bool
        Let the segment first run through non-clear cells (the surface the
        vertex lies on) until it reaches its first clear cell.
    end_margin_cells : float
        The last part of the segment within this many cells (along each
        axis) of the bone is not tested (the bone's own cells).

    Returns
    -------
    (n, b) float64 array, a refined copy.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    refined = np.array(distances, dtype=np.float64, copy=True)
    # Chessboard clearance: every cell within (c - 1) steps of a cell of
    # clearance c is clear, which lets the walk stride through open space.
    clearance = np.zeros(tuple(np.asarray(grid.shape) + 2), dtype=np.int32)
    clearance[1:-1, 1:-1, 1:-1] = ndimage.distance_transform_cdt(clear, metric="chessboard")
    slack = STAIRCASE_SLACK_CELLS * grid.cell_size
    rows_per_batch = max(1, (1 << 20) // max(1, len(heads)))
    for start in range(0, len(vertices), rows_per_batch):
        rows = slice(start, min(start + rows_per_batch, len(vertices)))
        v = vertices[rows]
        nearest = nearest_points_on_segments(v, heads, tails)  # (r, b, 3)
        straight = np.linalg.norm(nearest - v[:, None, :], axis=2)
        current = refined[rows]
        candidate = (current > straight) & (current <= STAIRCASE_RATIO * straight + slack)
        if test is not None:
            candidate &= test[rows]
        vertex, bone = np.nonzero(candidate)
        # Cell coordinates, shifted by the one-cell border of ``clearance``.
        starts = (v[vertex] - grid.origin) / grid.cell_size + 1.0
        ends = (nearest[vertex, bone] - grid.origin) / grid.cell_size + 1.0
        visible = _walk_in_sight(clearance, starts, ends, leave_start, end_margin_cells)
        current[vertex[visible], bone[visible]] = straight[vertex[visible], bone[visible]]
    return refined




def _walk_in_sight(
    clearance: np.ndarray, starts: np.ndarray, ends: np.ndarray, leave_start: bool, end_margin: float
) -> np.ndarray:
    """(k,) bool: whether each segment stays in cells of positive ``clearance``.

    ``starts`` and ``ends`` (k, 3) are in the cell coordinates of
    ``clearance`` (points outside it count as not clear). All segments walk
    at once, cell by cell (a 3D DDA, so no cell the segment passes through
    is skipped). From a point in a cell of clearance c, every point less than
    (c - 1) / max|u_i| further along the unit direction u is still in a
    clear cell, so in open space the walk jumps that far instead.
    """
    shape = np.asarray(clearance.shape)
    flat = clearance.ravel()
    delta = ends - starts
    length = np.linalg.norm(delta, axis=1)
    unit = delta / np.where(length > 0, length, 1.0)[:, None]
    widest = np.maximum(np.abs(unit).max(axis=1), 1e-12)
    stop = length - np.minimum(end_margin / widest, length) if end_margin > 0 else length
    inverse_unit = np.divide(1.0, unit, out=np.full_like(unit, np.inf), where=unit != 0)
    # Per segment still walking (compacted every step): start, direction,
    # 1 / direction, position t along it, where to stop, 1 / widest, its index,
    # whether it is still leaving its start.
    start, direction, inverse, t = starts, unit, inverse_unit, np.zeros(len(starts))
    slope, pair, leaving = 1.0 / widest, np.arange(len(starts)), np.full(len(starts), leave_start)
    visible = np.zeros(len(starts), dtype=bool)
    # Each step enters a new cell or jumps, so no walk takes more steps than
    # the cells it can cross; the bound only guards against round-off loops
    # (a segment still walking then counts as not in sight).
    step_limit = 3 * int(np.ceil(np.abs(delta).sum(axis=1).max(initial=0.0))) + 16
    for _ in range(step_limit):
        if not len(pair):
            break
        point = start + t[:, None] * direction
        corner = np.floor(point)
        cell = np.clip(corner.astype(np.int64), 0, shape - 1)
        c = flat[(cell[:, 0] * shape[1] + cell[:, 1]) * shape[2] + cell[:, 2]]
        clear = c > 0
        moving = clear | leaving
        leaving = leaving & ~clear
        # Distance along the direction to the next cell boundary, plus a hair.
        # Moving down from exactly on a boundary, the next one is a cell away.
        below = np.where(point > corner, point - corner, 1.0)
        with np.errstate(invalid="ignore"):  # inf * 0 in the branch np.where drops
            to_boundary = np.where(inverse > 0, (corner + 1.0 - point) * inverse, -below * inverse)
        advance = np.maximum(np.maximum(to_boundary.min(axis=1), 0.0) + 1e-7, (c - 1) * slope - 1e-9)
        # The stop point lies within what was just checked clear.
        done = moving & (t + advance >= stop)
        visible[pair[done]] = True
        t = np.minimum(t + advance, stop)
        keep = moving & ~done
        start, direction, inverse, t = start[keep], direction[keep], inverse[keep], t[keep]
        stop, slope, pair, leaving = stop[keep], slope[keep], pair[keep], leaving[keep]
    return visible


def covering_filled_grid(mesh: Mesh, heads: np.ndarray, tails: np.ndarray, resolution: int,
                         progress: ProgressCallback | None = None) -> VoxelGrid:
    """The mesh voxelised at ``resolution`` (grown to cover the bones) with its inside filled."""
    grid = voxelize_surface(mesh, resolution, cover_points=np.vstack([heads, tails]),
                            progress=sub_progress(progress, 0.0, 0.75))
    return fill_interior(grid)


def vertex_distances_on_graph(graph: "BoneGraph", vertices: np.ndarray,
                              progress: ProgressCallback | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Shortest-path distances from every vertex to every bone of ``graph``,
    through the vertex's candidate cells (see :func:`combine_vertex_distances`)."""
    candidates, query_nodes = vertex_cell_candidates(graph, vertices)
    node_distances = bone_node_distances(graph, query_nodes, progress)
    return combine_vertex_distances(graph, vertices, candidates, query_nodes, node_distances)
