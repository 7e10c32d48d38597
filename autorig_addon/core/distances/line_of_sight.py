"""Straight distances where a vertex sees the bone.

Stage 6 of the vertex-to-bone distances (see :mod:`.bone_distances`): a
path through cells is a staircase of 26-neighbour steps, up to 12.8 %
longer than the straight line. Where the straight segment from a vertex to
the bone's nearest point runs through cells a path may use, that segment is
the shortest path, and its length replaces the staircase.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from ..geometry.segments import nearest_points_on_segments
from .grid import VoxelGrid

#: Graph paths are staircases of 26-neighbour steps, at most this many
#: times the straight length (worst direction about (1, 0.41, 0.32)).
STAIRCASE_RATIO = 1.13
#: Besides the staircase, a graph distance may exceed the straight one by up
#: to this many cells (node centres off the bone and off the vertex).
STAIRCASE_SLACK_CELLS = 6.0


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
