"""Conservative voxelisation: the cells a triangle mesh touches.

Stage 1 of the vertex-to-bone distances (see :mod:`.bone_distances`): every
cell that shares a point with a triangle becomes a surface cell
(Schwarz & Seidel 2010), so thin parts such as cloth and hair cards are never
lost between cells and a 26-connected step between two other cells never
crosses the mesh.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..progress import ProgressCallback, report
from ..types import Mesh
from .grid import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION, VoxelGrid

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
    origin, cell_size, shape = grid_frame(mesh, resolution, padding_cells, cover_points)
    surface = np.zeros(shape, dtype=bool)
    grid = VoxelGrid(origin, cell_size, shape, surface, np.zeros(shape, dtype=bool))
    _mark_triangle_cells(grid, mesh.vertices, mesh.triangles, progress)
    return grid


def grid_frame(
    mesh: Mesh,
    resolution: int = DEFAULT_RESOLUTION,
    padding_cells: int = DEFAULT_PADDING_CELLS,
    cover_points: np.ndarray | None = None,
) -> tuple[np.ndarray, float, tuple]:
    """Where :func:`voxelize_surface` puts its grid, without voxelising.

    Parameters
    ----------
    as for :func:`voxelize_surface`

    Returns
    -------
    origin : (3,) float64 array, world position of cell (0, 0, 0)'s lowest corner
    cell_size : float, scene units
    shape : (3,) int tuple, cells along x, y, z

    Raises
    ------
    InputError for a mesh without faces, at one point or with non-finite
    vertices, or a resolution or padding out of bounds.
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
    return origin, cell_size, shape


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
        touches = triangle_touches_cell(corners[triangle], cells, tolerance)
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
            heights.append(anchor_uvw[:, 2]
                           - (nu * (iu + du - anchor_uvw[:, 0]) + nv * (iv + dv - anchor_uvw[:, 1])) / safe_nw)
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


def triangle_touches_cell(triangles: np.ndarray, cells: np.ndarray, tolerance: float) -> np.ndarray:
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
