"""Volumetric geodesic distance from vertices to bones.

The length of the shortest path from a vertex to a bone that stays inside
the shape (RigNet, Xu et al. 2020, after Dionne & de Lasa's Geodesic Voxel
Binding, 2013). Paths run through the solid cells of a voxel grid (surface
cells and the filled interior), so the distance from a fingertip to the
other hand goes up the arm and across the chest, not through the air.

Method (the shared stages are those of :mod:`.bone_distances`):

* Voxelise the surface conservatively and fill the enclosed interior.
* Graph: solid cells, 26-connected, each step as long as the distance
  between cell centres; interior cells away from the surface and the bones
  merge into blocks to keep the graph small.
* Each bone is a virtual source joined to the solid cells it crosses, at the
  distance from the cell centre to the bone segment.
* A bone does not always cross every solid part: it may lie outside the
  body (a skirt bone) and a part may be disconnected (a hat, a ball held in
  a hand). The bone then jumps straight through the air to the part's
  nearest cell at :data:`OUTSIDE_JUMP_PENALTY` times the jump length, so
  every vertex of every part gets a finite distance and the jump still
  counts against the bone.
* Dijkstra per bone; a vertex's distance is the best of its own and the 26
  surrounding cells: that cell's distance plus the straight step from its
  centre to the vertex.
* Line of sight (as RigNet does): where the straight segment from a vertex
  to the nearest point of a bone stays in solid cells, the distance is that
  segment's length, exactly.

Accuracy: graph paths measure steps along axes and 45-degree diagonals
exactly; other directions are measured along a staircase of 26-neighbour
steps, at most 12.8 % longer than the straight line (8.2 % within an axis
plane). The line-of-sight pass removes that error wherever the bone is
visible from the vertex, which covers the bones that matter most for
skinning; paths that must bend around the surface keep it. Cells are
``longest side / resolution`` wide, so surfaces are located to half a cell.

Units: distances are in scene units (those of the mesh vertices).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from ..geometry.segments import paired_point_segment_distances, point_segment_distances
from ..progress import ProgressCallback
from ..types import Mesh
from .bone_distances import bone_distances, validate_bones
from .cell_graph import BoneGraph, assemble_bone_graph, fine_cells, merge_cells, neighbour_node_pairs
from .grid import DEFAULT_RESOLUTION, VoxelGrid, segment_cells
from .line_of_sight import refine_in_sight
from .memory_estimate import GEODESIC_MEMORY

#: A jump through the air from a bone to a solid part it does not cross
#: counts this many times its straight length.
OUTSIDE_JUMP_PENALTY = 2.0
#: A bone enters a part it does not cross at every surface cell at most
#: this many times as far as the part's nearest one (plus one cell), not
#: only at the nearest: a bone inside an open tube (a sleeve, a body open at
#: the neck) is equally near the whole tube, and a single entry would send
#: every path along the surface from that one cell.
JUMP_ENTRY_SLACK = 1.5
#: Cells within this many steps of the surface or of a bone stay out of big
#: blocks, so paths that bend around the surface or start at a bone keep
#: full resolution.
FINE_MARGIN_CELLS = 1

_SOLID_CONNECTIVITY = np.ones((3, 3, 3), dtype=bool)


def volumetric_geodesic_distances(
    mesh: Mesh,
    heads: np.ndarray,
    tails: np.ndarray,
    *,
    resolution: int = DEFAULT_RESOLUTION,
    grid: VoxelGrid | None = None,
    progress: ProgressCallback | None = None,
) -> np.ndarray:
    """Shortest distance through the solid from each vertex to each bone.

    :func:`.bone_distances.bone_distances` with :func:`build_geodesic_graph`
    and :func:`refine_geodesic_in_sight`; see there for the parameters.

    Returns
    -------
    (n, b) float64 array of distances in scene units, all finite.
    """
    return bone_distances(mesh, heads, tails, build_geodesic_graph, refine_geodesic_in_sight,
                          resolution=resolution, grid=grid, memory=GEODESIC_MEMORY, progress=progress)


def refine_geodesic_in_sight(
    grid: VoxelGrid, distances: np.ndarray, layers: np.ndarray, vertices: np.ndarray, heads: np.ndarray,
    tails: np.ndarray
) -> np.ndarray:
    """Straight distances where the segment from the vertex to the bone stays
    in solid cells (:func:`.line_of_sight.refine_in_sight`); ``layers`` is
    unused (a geodesic graph has no layer cost).

    Returns
    -------
    (n, b) float64 array.
    """
    return refine_in_sight(grid, grid.occupied, distances, vertices, heads, tails)


def build_geodesic_graph(grid: VoxelGrid, heads: np.ndarray, tails: np.ndarray) -> BoneGraph:
    """The path graph over the solid cells of a filled ``grid``.

    Parameters
    ----------
    grid : VoxelGrid with ``inside`` filled
    heads, tails : (b, 3) float64 arrays

    Returns
    -------
    BoneGraph whose bone sources reach every solid part (see module docstring).
    """
    heads, tails = validate_bones(heads, tails)
    solid = grid.occupied
    nodes = merge_cells(grid, np.where(solid, 0, -1), grid.inside & ~fine_cells(grid, heads, tails, FINE_MARGIN_CELLS))
    pairs = neighbour_node_pairs(nodes)

    bone, cells = segment_cells(grid, heads, tails)
    in_solid = solid[cells[:, 0], cells[:, 1], cells[:, 2]]
    bone, cells = bone[in_solid], cells[in_solid]
    node = nodes.cell_node[cells[:, 0], cells[:, 1], cells[:, 2]]
    length = paired_point_segment_distances(nodes.centres[node], heads[bone], tails[bone])

    jump_bone, jump_node, jump_length = _jumps_to_uncrossed_parts(grid, nodes, heads, tails, bone, node)
    sources = (
        np.concatenate([bone, jump_bone]),
        np.concatenate([node, jump_node]),
        np.concatenate([length, jump_length]),
    )
    return assemble_bone_graph(grid, nodes, pairs, None, 0.0, sources, len(heads))


def _jumps_to_uncrossed_parts(grid, nodes, heads, tails, source_bone, source_node):
    """Edges from each bone to every solid part (26-connected component) it
    does not cross, entering at the part's surface cells nearest the bone
    (within :data:`JUMP_ENTRY_SLACK` of the nearest).

    The edge costs :data:`OUTSIDE_JUMP_PENALTY` times the jump from the bone
    to that cell's centre, plus the step from the cell to its node's centre
    (only the air is penalised).

    Returns
    -------
    bone, node : (j,) int64 arrays; length : (j,) float64 edge lengths
    """
    solid = grid.occupied
    labels, part_count = ndimage.label(solid, structure=_SOLID_CONNECTIVITY)
    node_part = np.zeros(nodes.count, dtype=np.int64)
    node_part[nodes.cell_node[solid]] = labels[solid] - 1
    bone_count = len(heads)
    crossed = np.zeros((part_count, bone_count), dtype=bool)
    crossed[node_part[source_node], source_bone] = True
    if crossed.all():
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    # The nearest solid cell to a point outside a part is on its surface.
    cells = np.argwhere(grid.surface)
    cell_part = labels[grid.surface] - 1
    order = np.argsort(cell_part, kind="stable")
    cells, cell_part = cells[order], cell_part[order]
    bounds = np.searchsorted(cell_part, np.arange(part_count + 1))
    jump_bone, jump_node, jump_length = [], [], []
    for part in np.flatnonzero(~crossed.all(axis=1)):
        members = cells[bounds[part] : bounds[part + 1]]
        if not len(members):
            continue
        bones = np.flatnonzero(~crossed[part])
        centres = grid.cell_centres(members)
        distances = point_segment_distances(centres, heads[bones], tails[bones])
        nearest = distances.min(axis=0)
        entry_cell, entry_bone = np.nonzero(distances <= nearest * JUMP_ENTRY_SLACK + grid.cell_size)
        entry = members[entry_cell]
        node = nodes.cell_node[entry[:, 0], entry[:, 1], entry[:, 2]]
        to_node = np.linalg.norm(nodes.centres[node] - centres[entry_cell], axis=1)
        jump_bone.append(bones[entry_bone])
        jump_node.append(node)
        jump_length.append(OUTSIDE_JUMP_PENALTY * distances[entry_cell, entry_bone] + to_node)
    if not jump_bone:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(jump_bone), np.concatenate(jump_node), np.concatenate(jump_length)
