"""The pipeline every voxel vertex-to-bone distance runs.

Both distance kinds (:mod:`.volumetric_geodesic` and :mod:`.hollow_dist`)
run the same stages and differ only in the graph they build and in when a
straight segment may replace a path:

1. :func:`.surface_voxels.voxelize_surface` marks every cell a triangle
   touches (conservative voxelisation, Schwarz & Seidel 2010), so thin parts
   such as cloth and hair cards are never lost between cells.
2. :func:`.interior.fill_interior` marks cells enclosed by the surface.
3. The kind's ``build_graph`` turns the cells a path may use into a
   :class:`.cell_graph.BoneGraph`: 26-connected steps between groups of
   cells, and one virtual source node per bone.
4. :func:`.cell_graph.bone_node_distances` runs Dijkstra from every bone.
5. :func:`.vertex_distances.vertex_distances_on_graph` turns node distances
   into vertex distances: the best of the nodes around a vertex plus the
   straight step from that node's centre to the vertex.
6. The kind's ``refine`` replaces a distance by the straight one where the
   vertex sees the bone (:func:`.line_of_sight.refine_in_sight`), removing
   the staircase error of cell paths.

Units: positions and distances in scene units (those of the mesh vertices).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import InputError
from ..progress import ProgressCallback, report, sub_progress
from ..types import Mesh
from .cell_graph import BoneGraph
from .grid import DEFAULT_RESOLUTION, VoxelGrid
from .interior import fill_interior
from .memory_estimate import HOLLOW_MEMORY, VoxelMemory, check_voxel_memory
from .surface_voxels import voxelize_surface
from .vertex_distances import fill_unreached, vertex_distances_on_graph

#: Builds the path graph of a distance kind: (grid, heads, tails) -> BoneGraph.
GraphBuilder = Callable[[VoxelGrid, np.ndarray, np.ndarray], BoneGraph]
#: Replaces path distances by straight ones where the kind allows:
#: (grid, distances, layers, vertices, heads, tails) -> distances.
Refinement = Callable[[VoxelGrid, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray], np.ndarray]


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


def voxelize_covering_bones(mesh: Mesh, heads: np.ndarray, tails: np.ndarray, resolution: int,
                            progress: ProgressCallback | None = None) -> VoxelGrid:
    """Stage 1: the surface of ``mesh`` voxelised at ``resolution``, the grid
    grown to cover the bones near the mesh (``cover_points`` of
    :func:`.surface_voxels.voxelize_surface`), so paths can start at them.

    Parameters
    ----------
    mesh : Mesh with at least one triangle
    heads, tails : (b, 3) float64 arrays
    resolution : int, cells along the longest side of the mesh's bounding box
    progress : optional ProgressCallback

    Returns
    -------
    VoxelGrid with ``surface`` set, ``inside`` not yet filled.
    """
    return voxelize_surface(mesh, resolution, cover_points=np.vstack([heads, tails]), progress=progress)


def bone_distances(
    mesh: Mesh,
    heads: np.ndarray,
    tails: np.ndarray,
    build_graph: GraphBuilder,
    refine: Refinement,
    *,
    resolution: int = DEFAULT_RESOLUTION,
    grid: VoxelGrid | None = None,
    memory: VoxelMemory = HOLLOW_MEMORY,
    progress: ProgressCallback | None = None,
) -> np.ndarray:
    """Distance from each vertex to each bone along the paths of one distance kind.

    Parameters
    ----------
    mesh : Mesh with n vertices
    heads, tails : (b, 3) float64 arrays, bone segments in world space
    build_graph : the kind's path graph (stage 3)
    refine : the kind's line-of-sight pass (stage 6)
    resolution : int, cells along the longest side of the mesh's bounding
        box, widened to cover bones near the mesh
    grid : VoxelGrid, optional
        A grid of this mesh already voxelised and filled
        (``fill_interior(voxelize_covering_bones(...))``), to share it between
        distance kinds; ``resolution`` is then ignored.
    memory : VoxelMemory, the kind's memory model: a ``resolution`` whose
        estimated peak exceeds the free memory is refused before any cell is
        allocated (:func:`.memory_estimate.check_voxel_memory`)
    progress : optional ProgressCallback

    Returns
    -------
    (n, b) float64 array of distances in scene units, all finite (vertices
    no path reaches get :func:`.vertex_distances.fill_unreached`'s fallback).
    """
    heads, tails = validate_bones(heads, tails)
    if grid is None:
        check_voxel_memory(mesh, heads, tails, resolution, memory)
        grid = fill_interior(voxelize_covering_bones(mesh, heads, tails, resolution, sub_progress(progress, 0.0, 0.15)))
    report(progress, 0.2, "Building the path graph")
    graph = build_graph(grid, heads, tails)
    distances, layers = vertex_distances_on_graph(graph, mesh.vertices, sub_progress(progress, 0.3, 0.95))
    distances = refine(grid, distances, layers, mesh.vertices, heads, tails)
    report(progress, 1.0, "Distances done")
    return fill_unreached(distances, mesh.vertices, heads, tails)
