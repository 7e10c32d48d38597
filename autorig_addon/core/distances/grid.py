"""The voxel grid all vertex-to-bone distances run on, and what lies in its cells.

A :class:`VoxelGrid` is a box of cubic cells over a mesh with two masks,
the cells a triangle touches (``surface``, set by
:func:`.surface_voxels.voxelize_surface`) and the cells the surface encloses
(``inside``, set by :func:`.interior.fill_interior`). This module also
finds the cells a bone crosses (:func:`segment_cells`) and holds the
26-neighbourhood every later stage steps through.

Units: positions and distances in scene units (those of the mesh vertices);
"cell coordinates" are positions divided by the cell size, measured from the
grid origin, so cell ``(i, j, k)`` spans ``[i, i + 1) x [j, j + 1) x [k, k + 1)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

#: Cells along the longest side of the mesh bounding box (both RigNet and
#: HeterSkinNet use 88).
DEFAULT_RESOLUTION = 88
#: Allowed resolutions, in cells along the longest side.
MIN_RESOLUTION = 4
MAX_RESOLUTION = 1024
#: Spacing of the points sampled along a bone to find the cells it crosses, in cells.
BONE_SAMPLE_SPACING_CELLS = 0.25

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
        :func:`.interior.fill_interior` runs.
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
