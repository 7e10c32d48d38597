"""Memory the voxel distances will take, estimated before they run.

The voxel pipeline (:mod:`.bone_distances`) holds several arrays over every
cell of its grid, a graph whose size follows the cells the surface touches,
and per-vertex tables, so its peak grows with the cube of the resolution: on
a 3.7k-vertex character HollowDist takes 0.7 GiB at resolution 256, 4 GiB
at 512 and, by this model, about 29 GiB at 1024. :func:`check_voxel_memory`
refuses a resolution whose estimate exceeds the free memory before any cell
is allocated, naming the largest resolution that fits.

The model is linear in four counts, each with a cost per distance kind
measured on the KayKit Knight and Rogue, the Quaternius Horse and the
Knight subdivided to 145k vertices (resolutions 64 to 512; peak resident
memory above the process's own; least squares, rounded up). It is never
below a measurement: 10 to 35 % above at resolution 256 and more, more
at low resolutions where the fixed part dominates:

* grid cells (dense masks, labels, node indices over the whole box),
* surface cells (the fine graph nodes and edges around the mesh), estimated
  from the mesh area: conservative voxelisation touches about 1.35 cells per
  cell-sized square of surface (1.27 to 1.37 measured),
* vertices (the nodes around each vertex, line-of-sight tests), and
* vertex-bone pairs (the distance tables).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..memory import require_memory, usable_memory_bytes
from ..types import Mesh
from .grid import MIN_RESOLUTION
from .surface_voxels import grid_frame


@dataclass(frozen=True)
class VoxelMemory:
    """Peak bytes of one distance kind per counted item (see the module docstring).

    Attributes
    ----------
    per_cell : float, bytes per grid cell
    per_surface_cell : float, bytes per cell the surface touches
    per_vertex : float, bytes per mesh vertex
    per_vertex_bone : float, bytes per (vertex, bone) pair
    """

    per_cell: float
    per_surface_cell: float
    per_vertex: float
    per_vertex_bone: float


#: HollowDist (:mod:`.hollow_dist`): measured 58.8 bytes a cell, 1951 a
#: surface cell, 2630 a vertex, none per vertex-bone pair beyond its distance.
HOLLOW_MEMORY = VoxelMemory(per_cell=64.0, per_surface_cell=2048.0, per_vertex=2800.0, per_vertex_bone=8.0)
#: Volumetric geodesic (:mod:`.volumetric_geodesic`): measured 23.6 bytes a
#: cell, 1012 a surface cell, 2098 a vertex and 102 a vertex-bone pair.
GEODESIC_MEMORY = VoxelMemory(per_cell=32.0, per_surface_cell=1024.0, per_vertex=2200.0, per_vertex_bone=108.0)
#: Bytes the pipeline takes whatever the grid (a batch of Dijkstra results, buffers).
FIXED_BYTES = 96 * 2**20
#: Cells the surface touches per cell-sized square of mesh area (measured 1.27 to 1.37).
SURFACE_CELLS_PER_AREA = 1.4


def mesh_area(mesh: Mesh) -> float:
    """Total area of the triangles of ``mesh``, scene units squared."""
    corners = mesh.vertices[mesh.triangles]
    return float(0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                                      axis=1).sum())


def estimated_memory_bytes(mesh: Mesh, heads: np.ndarray, tails: np.ndarray, resolution: int,
                           memory: VoxelMemory = HOLLOW_MEMORY) -> float:
    """Estimated peak bytes of :func:`.bone_distances.bone_distances` at ``resolution``.

    Parameters
    ----------
    mesh : Mesh with at least one triangle
    heads, tails : (b, 3) float64 arrays, the bones (they may widen the grid)
    resolution : int, cells along the longest side of the mesh's box
    memory : VoxelMemory of the distance kind

    Returns
    -------
    float, bytes (the model of the module docstring)
    """
    cover = np.vstack([np.asarray(heads, np.float64).reshape(-1, 3), np.asarray(tails, np.float64).reshape(-1, 3)])
    _, cell_size, shape = grid_frame(mesh, resolution, cover_points=cover)
    cells = float(np.prod(shape))
    surface_cells = min(cells, SURFACE_CELLS_PER_AREA * mesh_area(mesh) / cell_size**2)
    vertices, bones = mesh.vertex_count, len(cover) // 2
    return (FIXED_BYTES + memory.per_cell * cells + memory.per_surface_cell * surface_cells
            + memory.per_vertex * vertices + memory.per_vertex_bone * vertices * bones)


def largest_fitting_resolution(mesh: Mesh, heads: np.ndarray, tails: np.ndarray, resolution: int,
                               budget_bytes: float, memory: VoxelMemory = HOLLOW_MEMORY) -> int | None:
    """The largest resolution up to ``resolution`` whose estimate fits in
    ``budget_bytes``, or None when not even :data:`.grid.MIN_RESOLUTION` does
    (the estimate grows with the resolution, so a bisection finds it)."""
    def fits(value: int) -> bool:
        return estimated_memory_bytes(mesh, heads, tails, value, memory) <= budget_bytes

    if not fits(MIN_RESOLUTION):
        return None
    low, high = MIN_RESOLUTION, int(resolution)
    while low < high:
        middle = (low + high + 1) // 2
        low, high = (middle, high) if fits(middle) else (low, middle - 1)
    return low


def check_voxel_memory(mesh: Mesh, heads: np.ndarray, tails: np.ndarray, resolution: int,
                       memory: VoxelMemory = HOLLOW_MEMORY) -> None:
    """Raise :class:`~autorig_addon.core.errors.InputError` when the voxel
    distances at ``resolution`` would not fit in the free memory (see
    :func:`~autorig_addon.core.memory.require_memory`), naming the largest
    resolution that fits; never where the free memory is unknown."""
    needed = estimated_memory_bytes(mesh, heads, tails, resolution, memory)
    budget = usable_memory_bytes()
    if budget is None or needed <= budget:
        return
    _, _, shape = grid_frame(mesh, resolution, cover_points=np.vstack([heads, tails]))
    fitting = largest_fitting_resolution(mesh, heads, tails, resolution, budget, memory)
    advice = (f"Resolution {fitting} fits: lower it to that or less (Resolution in the Skin panel, "
              "--resolution on the command line)." if fitting is not None else
              "Free some memory (close other programs) or simplify the mesh.")
    require_memory(needed, f"The voxel grid at resolution {resolution} ({' x '.join(map(str, shape))} cells)", advice)
