"""HollowDist: vertex-to-bone distance through the empty space around the mesh.

HeterSkinNet (Pan et al. 2021, Algorithm 1) measures how far a vertex is
from a bone along paths through *hollow* cells, the cells no triangle
touches, whether they lie inside a closed body or in the air around it.
Paths may enter a mesh cell but never pass through one, so a path cannot
slip through the surface; unlike the volumetric geodesic it needs no
watertight mesh and it reaches bones outside the body and disconnected
parts (a hat, a ball held in a hand, a skirt driven by outside bones).

Our reading of Algorithm 1:

1. Voxelise the surface conservatively: mesh cells are those a triangle
   touches, every other cell is hollow.
2. For each bone, search breadth-first from the cells the bone touches.
   Hollow cells are expanded; a mesh cell gets the distance of the cell it
   was reached from plus the step, and is not expanded.
3. Mesh cells left unreached (the far side of a shell, the outer layer of a
   thick surface) restart the search: the mesh cells reached so far become
   the seeds of a new round, which may cross one mesh layer. Rounds repeat
   until every cell is reached. A cell keeps the distance of the first round
   that reaches it, so a vertex on the near side of a wall is never given a
   shorter path that went through the wall.
4. A vertex's distance is its previous cell's distance plus the straight step
   from that cell to the vertex.

Implementation:

* The rounds are one Dijkstra per bone in which a step out of a mesh cell
  costs an extra ``layer_cost``, a power of two larger than any geometric
  path. The shortest path then minimises first the number of mesh layers
  crossed, then the length, which is exactly the round-by-round result; the
  layer multiples are removed at the end.
* Steps have their Euclidean length (1, sqrt 2, sqrt 3 cells) rather than
  BFS hop counts, and cells are grouped into graph nodes as described in
  :mod:`.cell_graph` (never across the mesh: inside and outside hollow cells
  are never joined directly).
* All cells a bone touches start the search, including mesh cells, whose
  neighbours are seeded too (a bone lying in a thin part spreads to both
  sides of it). A bone entirely outside the grid starts from the grid node
  nearest to it, at the straight distance (the air is hollow).
* Step 4: over the vertex's cell and its 26 neighbours, the best cell
  distance plus the straight step to the vertex; the cell the vertex's cell
  was reached from is among them.
* Line of sight: where the path crossed no layer and the straight segment
  from the vertex to the bone's nearest point, once it has left the mesh
  cells the vertex lies in, crosses no mesh cell until it reaches the
  bone's cells, that segment is the shortest hollow path and its length
  replaces the chain of cell steps (which can be up to 12.8 % longer; bent
  paths keep that error).
* Every distance is finite.

Units: distances are in scene units (those of the mesh vertices).
"""

from __future__ import annotations

import numpy as np

from ..geometry.segments import paired_point_segment_distances, point_segment_distances
from ..progress import ProgressCallback
from ..types import Mesh
from .bone_distances import bone_distances, validate_bones
from .cell_graph import BoneGraph, assemble_bone_graph, fine_cells, layer_cost_above, merge_cells, neighbour_node_pairs
from .grid import DEFAULT_RESOLUTION, NEIGHBOUR_OFFSETS, VoxelGrid, segment_cells
from .line_of_sight import refine_in_sight
from .memory_estimate import HOLLOW_MEMORY

#: A straight segment from a vertex to a bone counts as a hollow path when,
#: once it has left the mesh cells around the vertex, it crosses no mesh
#: cell until it is this many cells (along each axis) from the bone, whose
#: own cells may be mesh cells.
SIGHT_END_MARGIN_CELLS = 1.5
#: Cells within this many steps of the surface or of a bone stay out of big blocks.
FINE_MARGIN_CELLS = 0

_MESH, _INSIDE, _OUTSIDE = 0, 1, 2


def hollow_distances(
    mesh: Mesh,
    heads: np.ndarray,
    tails: np.ndarray,
    *,
    resolution: int = DEFAULT_RESOLUTION,
    grid: VoxelGrid | None = None,
    progress: ProgressCallback | None = None,
) -> np.ndarray:
    """HollowDist from each vertex to each bone.

    :func:`.bone_distances.bone_distances` with :func:`build_hollow_graph`
    and :func:`refine_hollow_in_sight`; see there for the parameters (an
    unfilled ``grid`` works for open meshes).

    Returns
    -------
    (n, b) float64 array of distances in scene units, all finite.
    """
    return bone_distances(mesh, heads, tails, build_hollow_graph, refine_hollow_in_sight,
                          resolution=resolution, grid=grid, memory=HOLLOW_MEMORY, progress=progress)


def build_hollow_graph(grid: VoxelGrid, heads: np.ndarray, tails: np.ndarray) -> BoneGraph:
    """The HollowDist path graph over every cell of ``grid``.

    Parameters
    ----------
    grid : VoxelGrid; ``inside`` filled (it only keeps inside and outside
        hollow cells from being joined diagonally, so an unfilled grid
        works for open meshes)
    heads, tails : (b, 3) float64 arrays

    Returns
    -------
    BoneGraph with ``layer_cost`` set (see module docstring).
    """
    heads, tails = validate_bones(heads, tails)
    side = np.full(grid.shape, _OUTSIDE, dtype=np.int16)
    side[grid.inside] = _INSIDE
    side[grid.surface] = _MESH
    nodes = merge_cells(grid, side, ~fine_cells(grid, heads, tails, FINE_MARGIN_CELLS))
    node_side = nodes.node_class
    pairs = neighbour_node_pairs(nodes)
    sides = np.sort(node_side[pairs], axis=1)
    pairs = pairs[~((sides[:, 0] == _INSIDE) & (sides[:, 1] == _OUTSIDE))]

    bone, node, length = _bone_seeds(grid, nodes, heads, tails)
    steps = np.linalg.norm(nodes.centres[pairs[:, 0]] - nodes.centres[pairs[:, 1]], axis=1)
    # No simple path is longer than (nodes x longest step), plus its start and the step to a vertex.
    bound = nodes.count * steps.max(initial=0.0) + float(length.max()) + 4.0 * grid.cell_size
    return assemble_bone_graph(
        grid, nodes, pairs, node_side == _MESH, layer_cost_above(bound), (bone, node, length), len(heads)
    )


def refine_hollow_in_sight(
    grid: VoxelGrid, distances: np.ndarray, layers: np.ndarray, vertices: np.ndarray, heads: np.ndarray,
    tails: np.ndarray
) -> np.ndarray:
    """Straight distances for the pairs whose hollow path crossed no mesh
    layer and whose vertex sees the bone through hollow cells (see
    :func:`.line_of_sight.refine_in_sight`); a path that had to cross a layer
    cannot be replaced by a straight segment that crosses none.

    Parameters
    ----------
    grid : VoxelGrid
    distances : (n, b) float64, layers : (n, b) int64, as returned by
        :func:`.vertex_distances.combine_vertex_distances`
    vertices : (n, 3) float64; heads, tails : (b, 3) float64

    Returns
    -------
    (n, b) float64 array.
    """
    return refine_in_sight(
        grid, ~grid.surface, distances, vertices, heads, tails,
        test=layers == 0, leave_start=True, end_margin_cells=SIGHT_END_MARGIN_CELLS,
    )


def _bone_seeds(grid, nodes, heads, tails):
    """Where each bone's search starts.

    The cells a bone touches, plus the neighbours of those that are mesh
    cells; a bone with no cell in the grid starts at the node nearest to it.

    Returns
    -------
    bone, node : (s,) int64 arrays; length : (s,) float64 distance from the
    node centre to the bone
    """
    bone, cells = segment_cells(grid, heads, tails)
    on_mesh = grid.surface[cells[:, 0], cells[:, 1], cells[:, 2]]
    around = cells[on_mesh][:, None, :] + NEIGHBOUR_OFFSETS[None, :, :]
    around_bone = np.repeat(bone[on_mesh], len(NEIGHBOUR_OFFSETS))
    around = around.reshape(-1, 3)
    valid = grid.in_grid(around)
    cells = np.concatenate([cells, around[valid]])
    bone = np.concatenate([bone, around_bone[valid]])
    node = nodes.cell_node[cells[:, 0], cells[:, 1], cells[:, 2]]

    missing = np.setdiff1d(np.arange(len(heads)), bone)
    if len(missing):
        distances = point_segment_distances(nodes.centres, heads[missing], tails[missing])
        bone = np.concatenate([bone, missing])
        node = np.concatenate([node, distances.argmin(axis=0)])
    return bone, node, paired_point_segment_distances(nodes.centres[node], heads[bone], tails[bone])
