"""The voxel stages of the vertex-to-bone distances (core/distances: grid,
surface_voxels, interior, cell_graph, vertex_distances) on grids small
enough to check by hand."""

import itertools
import re

import numpy as np
import pytest
from scipy import ndimage
from scipy.spatial import cKDTree

from autorig_addon.core.distances import cell_graph
from autorig_addon.core.distances.cell_graph import (
    assemble_bone_graph,
    bone_node_distances,
    fine_cells,
    layer_cost_above,
    merge_cells,
    neighbour_node_pairs,
)
from autorig_addon.core.distances.grid import MAX_RESOLUTION, MIN_RESOLUTION, segment_cells
from autorig_addon.core.distances.interior import fill_interior
from autorig_addon.core.distances.line_of_sight import refine_in_sight
from autorig_addon.core.distances.surface_voxels import triangle_touches_cell, voxelize_surface
from autorig_addon.core.distances.vertex_distances import (
    UNREACHABLE_PENALTY,
    combine_vertex_distances,
    fill_unreached,
    vertex_cell_candidates,
)
from autorig_addon.core.errors import InputError
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh, plain_grid

# --------------------------------------------------------------------------
# Voxelisation and filling
# --------------------------------------------------------------------------


def test_unit_cube_on_cell_boundaries_gives_a_two_cell_shell_and_a_filled_core():
    # Cube [0, 1]^3 at 10 cells per side: cell 0.1, two cells of padding, so
    # the faces lie exactly on cell boundaries and touch the cells on both
    # sides: the shell is cells 1..2 and 11..12, the core cells 3..10.
    grid = fill_interior(voxelize_surface(box_mesh([0, 0, 0], [1, 1, 1], 0.25), resolution=10, padding_cells=2))
    assert grid.shape == (14, 14, 14)
    assert grid.cell_size == pytest.approx(0.1)
    np.testing.assert_allclose(grid.origin, [-0.2, -0.2, -0.2])
    index = np.indices(grid.shape)
    in_block = np.all((index >= 1) & (index <= 12), axis=0)
    in_core = np.all((index >= 3) & (index <= 10), axis=0)
    np.testing.assert_array_equal(grid.surface, in_block & ~in_core)
    np.testing.assert_array_equal(grid.inside, in_core)
    assert grid.surface.sum() == 12**3 - 8**3 and grid.inside.sum() == 8**3


def test_box_missing_a_face_encloses_nothing():
    closed = box_mesh([0, 0, 0], [1, 1, 1], 0.25)
    # Drop the triangles of the top face (z = 1).
    keep = ~np.all(np.isclose(closed.vertices[closed.triangles][:, :, 2], 1.0), axis=1)
    grid = fill_interior(voxelize_surface(Mesh(closed.vertices, closed.triangles[keep]), resolution=10))
    # The closed box's two-cell shell (see above) less the top face's cells
    # z = 11, 12 that no side face reaches (x and y in 3..10).
    index = np.indices(grid.shape)
    shell = np.all((index >= 1) & (index <= 12), axis=0) & ~np.all((index >= 3) & (index <= 10), axis=0)
    lid = np.all((index[:2] >= 3) & (index[:2] <= 10), axis=0) & (index[2] >= 11) & (index[2] <= 12)
    np.testing.assert_array_equal(grid.surface, shell & ~lid)
    assert not grid.inside.any()


def test_conservative_voxelisation_covers_every_point_of_a_triangle():
    rng = np.random.default_rng(3)
    triangle = np.array([[0.05, 0.1, 0.0], [0.93, 0.35, 0.61], [0.3, 0.97, 0.22]])
    grid = voxelize_surface(Mesh(triangle, [[0, 1, 2]]), resolution=16)
    weights = rng.dirichlet(np.ones(3), size=20000)
    cells = grid.point_cells(weights @ triangle)
    assert grid.surface[cells[:, 0], cells[:, 1], cells[:, 2]].all()
    # And no cell farther than its half diagonal from the triangle is marked.
    marked = grid.cell_centres(np.argwhere(grid.surface))
    samples = rng.dirichlet(np.ones(3), size=20000) @ triangle
    gap, _ = cKDTree(samples).query(marked)
    assert gap.max() <= np.sqrt(3) / 2 * grid.cell_size + 0.02 * grid.cell_size


def _clip_polygon(polygon, axis, bound, keep_below):
    """Sutherland-Hodgman clip of a convex polygon against x[axis] <= bound
    (or >= bound)."""
    out = []
    inside = (lambda p: p[axis] <= bound + 1e-12) if keep_below else (lambda p: p[axis] >= bound - 1e-12)
    for i in range(len(polygon)):
        current, following = polygon[i], polygon[(i + 1) % len(polygon)]
        if inside(current):
            out.append(current)
        if inside(current) != inside(following):
            t = (bound - current[axis]) / (following[axis] - current[axis])
            out.append(current + t * (following - current))
    return out


def test_triangle_box_test_matches_polygon_clipping():
    rng = np.random.default_rng(7)
    triangles = rng.uniform(-1.0, 2.0, size=(3000, 3, 3))
    cells = np.zeros((3000, 3), dtype=np.int64)  # the unit cell [0, 1]^3
    fast = triangle_touches_cell(triangles, cells, 0.0)
    reference = []
    for triangle in triangles:
        polygon = list(triangle)
        for axis, bound in itertools.product(range(3), (0.0, 1.0)):
            polygon = _clip_polygon(polygon, axis, bound, keep_below=bound == 1.0)
            if not polygon:
                break
        reference.append(bool(polygon))
    np.testing.assert_array_equal(fast, reference)
    assert 300 < fast.sum() < 2700  # both outcomes well represented


def test_voxelisation_matches_testing_every_cell():
    # Large random triangles (spanning many cells, all orientations): the
    # per-column candidates must find exactly the cells a brute-force test
    # of every cell of the grid finds.
    rng = np.random.default_rng(11)
    corners = rng.uniform(0.0, 1.0, size=(25, 3, 3))
    mesh = Mesh(corners.reshape(-1, 3), np.arange(75).reshape(25, 3))
    grid = voxelize_surface(mesh, resolution=12)
    all_cells = np.argwhere(np.ones(grid.shape, bool))
    expected = np.zeros(grid.shape, bool)
    for triangle in corners:
        local = (triangle - grid.origin) / grid.cell_size
        hit = triangle_touches_cell(np.broadcast_to(local, (len(all_cells), 3, 3)), all_cells, 1e-7)
        expected[tuple(all_cells[hit].T)] = True
    np.testing.assert_array_equal(grid.surface, expected)


def test_tilted_sheet_separates_the_two_sides_even_diagonally():
    # A plane tilted against all axes; 26-connected paths through cells the
    # sheet does not touch must not get across it.
    corners = np.array([[0, 0, 0.3], [1, 0, 0.55], [1, 1, 0.9], [0, 1, 0.65]])
    sheet = Mesh(corners, [[0, 1, 2], [0, 2, 3]])
    grid = voxelize_surface(sheet, resolution=24, padding_cells=1)
    centres = grid.cell_centres(np.argwhere(np.ones(grid.shape, bool))).reshape(*grid.shape, 3)
    height = 0.3 + 0.25 * centres[..., 0] + 0.35 * centres[..., 1]
    within = (centres[..., 0] > 0) & (centres[..., 0] < 1) & (centres[..., 1] > 0) & (centres[..., 1] < 1)
    labels, _ = ndimage.label(~grid.surface & within, structure=np.ones((3, 3, 3)))
    above = np.unique(labels[within & ~grid.surface & (centres[..., 2] > height)])
    below = np.unique(labels[within & ~grid.surface & (centres[..., 2] < height)])
    assert len(above) and len(below)
    assert not set(above[above > 0]) & set(below[below > 0])
    # Over the sheet, the marked cells are exactly those the plane passes
    # through or touches: |n . (centre - p)| <= h/2 (|n_x| + |n_y| + |n_z|),
    # n = (-0.25, -0.35, 1) (up to round-off in the cell coordinates).
    normal = np.array([-0.25, -0.35, 1.0])
    offset = (centres - np.array([0, 0, 0.3])) @ normal
    reach = 0.5 * grid.cell_size * np.abs(normal).sum()
    over = (np.floor(centres[..., 0] / grid.cell_size) >= 0) & (np.ceil(centres[..., 0] / grid.cell_size) <= 24)
    over &= (np.floor(centres[..., 1] / grid.cell_size) >= 0) & (np.ceil(centres[..., 1] / grid.cell_size) <= 24)
    touching = np.isclose(np.abs(offset), reach, rtol=0, atol=1e-9 * grid.cell_size) & over
    assert touching.sum() > 0 and grid.surface[touching].all()
    np.testing.assert_array_equal(grid.surface[over], np.abs(offset[over]) <= reach + 1e-9 * grid.cell_size)


@pytest.mark.parametrize("mesh, options, message", [
    (Mesh(np.zeros((3, 3)), np.zeros((0, 3), int)), {}, "The mesh has no faces; voxelisation needs a surface."),
    (Mesh(np.zeros((3, 3)), [[0, 1, 2]]), {}, "All vertices of the mesh are at one point; it has no size to voxelise."),
    (box_mesh([0, 0, 0], [1, 1, 1], 0.5), {"resolution": MIN_RESOLUTION - 1},
     f"Voxel resolution must be between {MIN_RESOLUTION} and {MAX_RESOLUTION} cells, got {MIN_RESOLUTION - 1}."),
    (box_mesh([0, 0, 0], [1, 1, 1], 0.5), {"resolution": MAX_RESOLUTION + 1},
     f"Voxel resolution must be between {MIN_RESOLUTION} and {MAX_RESOLUTION} cells, got {MAX_RESOLUTION + 1}."),
    (box_mesh([0, 0, 0], [1, 1, 1], 0.5), {"padding_cells": 0}, "Voxel padding must be at least 1 cell, got 0."),
    (Mesh([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]], [[0, 1, 2]]), {},
     "The mesh has vertices at NaN or infinite positions; fix them before skinning."),
])
def test_voxelize_surface_rejects_bad_input(mesh, options, message):
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        voxelize_surface(mesh, **options)


def test_fill_marks_only_cells_no_face_path_leads_out_of():
    # A 3 x 3 x 3 shell of surface cells around cell (2, 2, 2) of a 5^3 grid.
    surface = np.zeros((5, 5, 5), dtype=bool)
    surface[1:4, 1:4, 1:4] = True
    surface[2, 2, 2] = False
    filled = fill_interior(plain_grid(surface.shape, surface=surface))
    expected = np.zeros(surface.shape, dtype=bool)
    expected[2, 2, 2] = True
    np.testing.assert_array_equal(filled.inside, expected)
    # A missing corner cell joins the centre to the outside only diagonally:
    # the fill is 6-connected, so the centre is still enclosed.
    corner = surface.copy()
    corner[1, 1, 1] = False
    np.testing.assert_array_equal(fill_interior(plain_grid(surface.shape, surface=corner)).inside, expected)
    # A missing face cell opens it.
    face = surface.copy()
    face[2, 2, 1] = False
    assert not fill_interior(plain_grid(surface.shape, surface=face)).inside.any()


# --------------------------------------------------------------------------
# Bones and small helpers
# --------------------------------------------------------------------------


def test_segment_cells_lists_the_cells_a_bone_crosses():
    grid = plain_grid((6, 4, 4))
    bone, cells = segment_cells(grid, [[0.5, 1.5, 1.5], [-3.0, 2.5, 2.5]], [[4.5, 1.5, 1.5], [1.5, 2.5, 2.5]])
    first = cells[bone == 0]
    np.testing.assert_array_equal(first[np.argsort(first[:, 0])], [[i, 1, 1] for i in range(5)])
    # The second bone starts outside the grid: only cells 0 and 1 exist.
    second = cells[bone == 1]
    np.testing.assert_array_equal(second[np.argsort(second[:, 0])], [[0, 2, 2], [1, 2, 2]])


def test_fine_cells_are_the_surface_and_bone_cells_grown_by_the_margin():
    surface = np.zeros((6, 6, 6), dtype=bool)
    surface[1, 1, 1] = True
    grid = plain_grid(surface.shape, surface=surface)
    away = np.array([[10.0, 10, 10]]), np.array([[11.0, 10, 10]])  # a bone outside the grid
    np.testing.assert_array_equal(fine_cells(grid, *away, 0), surface)
    expected = np.zeros(surface.shape, dtype=bool)
    expected[0:3, 0:3, 0:3] = True
    np.testing.assert_array_equal(fine_cells(grid, *away, 1), expected)
    bone = np.array([[0.5, 4.5, 4.5]]), np.array([[5.5, 4.5, 4.5]])
    expected = surface.copy()
    expected[:, 4, 4] = True
    np.testing.assert_array_equal(fine_cells(grid, *bone, 0), expected)


def test_layer_cost_is_the_next_power_of_two():
    assert [layer_cost_above(b) for b in (6.5, 8.0, 0.3, 1000.0)] == [8.0, 16.0, 0.5, 1024.0]


def test_unreached_entries_get_the_penalised_straight_distance():
    heads, tails = np.array([[0.0, 0, 0], [0, 5, 0]]), np.array([[1.0, 0, 0], [1, 5, 0]])
    vertices = np.array([[0.5, 1.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 3.0]])
    distances = np.array([[1.5, np.inf], [np.nan, 7.0], [3.0, 6.0]])
    filled = fill_unreached(distances, vertices, heads, tails)
    assert UNREACHABLE_PENALTY == 4.0
    np.testing.assert_allclose(filled, [[1.5, 4 * 4.0], [4 * 1.0, 7.0], [3.0, 6.0]])
    assert fill_unreached(filled, vertices, heads, tails) is filled  # nothing to fill: the same array


# --------------------------------------------------------------------------
# Graph machinery on grids small enough to check by hand
# --------------------------------------------------------------------------


def test_merge_cells_groups_each_class_of_a_two_cell_block():
    classes = np.full((4, 2, 2), 1)
    classes[1, 0, 0] = 0  # another class in the first block
    classes[3, :, :] = -1  # no node
    nodes = merge_cells(plain_grid(classes.shape), classes, np.zeros(classes.shape, bool))
    assert nodes.count == 3
    assert len(set(nodes.cell_node[:2].ravel())) == 2
    assert nodes.cell_node[1, 0, 0] != nodes.cell_node[0, 0, 0]
    assert (nodes.cell_node[3] == -1).all()
    first = nodes.cell_node[0, 0, 0]
    # Centre of the 7 class-1 cells of the first block.
    np.testing.assert_allclose(nodes.centres[first],
                               [(0.5 * 4 + 1.5 * 3) / 7, (0.5 * 3 + 1.5 * 4) / 7, (0.5 * 3 + 1.5 * 4) / 7])
    np.testing.assert_allclose(nodes.centres[nodes.cell_node[2, 0, 0]], [2.5, 1.0, 1.0])
    pairs = {tuple(sorted(p)) for p in neighbour_node_pairs(nodes)}
    assert len(pairs) == 3  # all three nodes touch each other


def test_merge_cells_makes_big_blocks_only_where_allowed():
    classes = np.ones((16, 8, 8), dtype=int)
    coarsen = np.ones(classes.shape, bool)
    coarsen[8:] = False
    nodes = merge_cells(plain_grid(classes.shape), classes, coarsen, max_block=8)
    # One 8-block for x < 8, then 2-blocks: 4 * 4 * 4 of them.
    assert nodes.count == 1 + 64
    assert (nodes.cell_node[:8] == nodes.cell_node[0, 0, 0]).all()
    np.testing.assert_allclose(nodes.centres[nodes.cell_node[0, 0, 0]], [4, 4, 4])
    np.testing.assert_allclose(nodes.centres[nodes.cell_node[8:10, 2:4, 6:8]], np.full((2, 2, 2, 3), [9.0, 3.0, 7.0]))
    assert len(np.unique(nodes.cell_node[8:])) == 64
    # A block must lie wholly inside the allowed cells: one cell outside
    # breaks its 8-block into 4-blocks (7 of them) and the rest into 2-blocks.
    coarsen[7, 7, 7] = False
    nodes = merge_cells(plain_grid(classes.shape), classes, coarsen, max_block=8)
    assert nodes.count == 7 + 8 + 64


def _l_corridor():
    """A 2-cell-thick L: x in [0, 8) along y in [0, 2), then y in [2, 8) at
    x in [6, 8); z in [0, 2). Cell size 0.5. Every 2x2x2 block is full, so
    the nodes sit at block centres (cell units): (1,1) (3,1) (5,1) (7,1)
    (7,3) (7,5) (7,7), all at z = 1."""
    inside = np.zeros((8, 8, 2), dtype=bool)
    inside[:, 0:2, :] = True
    inside[6:8, 2:8, :] = True
    return plain_grid(inside.shape, 0.5, inside=inside)


def test_shortest_paths_on_a_hand_checked_l_corridor():
    grid = _l_corridor()
    nodes = merge_cells(grid, np.where(grid.inside, 0, -1), np.zeros(grid.shape, bool))
    pairs = neighbour_node_pairs(nodes)
    centre_cells = [(1, 1), (3, 1), (5, 1), (7, 1), (7, 3), (7, 5), (7, 7)]
    index = [nodes.cell_node[x - 1, y - 1, 0] for x, y in centre_cells]
    # Steps of 2 cells along the corridor, plus the diagonal that cuts the
    # inner corner: blocks (5,1) and (7,3) share the cell corner at (6, 2).
    expected_pairs = {tuple(sorted((index[i], index[i + 1]))) for i in range(6)} | {tuple(sorted((index[2], index[4])))}
    assert {tuple(p) for p in pairs} == expected_pairs
    # A point-like bone at the first node's centre.
    bone_point = grid.origin + np.array([1.0, 1.0, 1.0]) * grid.cell_size
    graph = assemble_bone_graph(grid, nodes, pairs, None, 0.0,
                                (np.array([0]), np.array([index[0]]), np.array([0.0])), 1)
    distances = bone_node_distances(graph, np.array(index))[:, 0]
    h, diagonal = grid.cell_size, 2 * np.sqrt(2)
    np.testing.assert_allclose(distances, np.array([0, 2, 4, 6, 4 + diagonal, 6 + diagonal, 8 + diagonal]) * h,
                               atol=1e-8)
    # A vertex at the far end, half a cell beyond the last node centre.
    vertex = grid.origin + np.array([[7.0, 7.5, 1.0]]) * h
    candidates, query = vertex_cell_candidates(graph, vertex)
    vertex_distance, layers = combine_vertex_distances(graph, vertex, candidates, query,
                                                       bone_node_distances(graph, query))
    assert vertex_distance[0, 0] == pytest.approx((8 + diagonal + 0.5) * h)
    assert layers[0, 0] == 0
    assert np.linalg.norm(vertex - bone_point) < vertex_distance[0, 0]


def test_bone_graph_sources_only_leave_their_bone():
    # Two bones on a 1-node-wide corridor; bone 1 must not act as a shortcut
    # for bone 0 (its virtual node has no incoming edges).
    inside = np.ones((8, 2, 2), dtype=bool)
    grid = plain_grid(inside.shape, inside=inside)
    nodes = merge_cells(grid, np.where(inside, 0, -1), np.zeros(inside.shape, bool))
    pairs = neighbour_node_pairs(nodes)
    ends = [nodes.cell_node[0, 0, 0], nodes.cell_node[7, 0, 0]]
    sources = (np.array([0, 1]), np.array(ends), np.array([0.0, 0.0]))
    graph = assemble_bone_graph(grid, nodes, pairs, None, 0.0, sources, 2)
    distances = bone_node_distances(graph, np.array(ends))
    np.testing.assert_allclose(distances, [[0, 6], [6, 0]], atol=1e-8)


def test_bones_batched_one_at_a_time_give_the_same_paths(monkeypatch):
    grid = _l_corridor()
    nodes = merge_cells(grid, np.where(grid.inside, 0, -1), np.zeros(grid.shape, bool))
    ends = np.array([nodes.cell_node[0, 0, 0], nodes.cell_node[6, 6, 0], nodes.cell_node[4, 0, 0]])
    sources = (np.arange(3), ends, np.zeros(3))
    graph = assemble_bone_graph(grid, nodes, neighbour_node_pairs(nodes), None, 0.0, sources, 3)
    together = bone_node_distances(graph, ends)
    monkeypatch.setattr(cell_graph, "DIJKSTRA_BATCH_BYTES", 1)  # one bone per batch
    np.testing.assert_array_equal(bone_node_distances(graph, ends), together)
    # Corner block (5, 1) to the far end (7, 7): the diagonal, then two steps of 2 cells.
    h = grid.cell_size
    diagonal = 2 * np.sqrt(2)
    expected = np.array([[0, 8 + diagonal, 4], [8 + diagonal, 0, 4 + diagonal], [4, 4 + diagonal, 0]])
    # Zero-length source edges are stored at MIN_EDGE_CELLS (scipy drops zero edges).
    np.testing.assert_allclose(together, (expected + cell_graph.MIN_EDGE_CELLS) * h, rtol=1e-12, atol=0)


def test_line_of_sight_replaces_a_path_only_through_clear_cells():
    # A 10 x 3 x 3 corridor of unit cells, clear but for one edge row (a
    # real grid always has cells a path may not use); the vertex and a
    # point-like bone 8 cells apart on its axis.
    grid = plain_grid((10, 3, 3))
    vertex, bone = np.array([[0.5, 1.5, 1.5]]), np.array([[8.5, 1.5, 1.5]])
    clear = np.ones(grid.shape, dtype=bool)
    clear[:, 0, 0] = False
    paths = np.array([[8.3]])
    np.testing.assert_array_equal(refine_in_sight(grid, clear, paths, vertex, bone, bone), [[8.0]])
    # A path longer than the staircase bound (1.13 x 8 + 6 cells) cannot be
    # a bent view of the same segment: it is left alone.
    np.testing.assert_array_equal(refine_in_sight(grid, clear, np.array([[16.0]]), vertex, bone, bone), [[16.0]])
    # One blocked cell on the segment hides the bone.
    blocked = clear.copy()
    blocked[4, 1, 1] = False
    np.testing.assert_array_equal(refine_in_sight(grid, blocked, paths, vertex, bone, bone), [[8.3]])
    # ... unless it is where the walk may leave from or end in.
    start = clear.copy()
    start[0, 1, 1] = False
    np.testing.assert_array_equal(refine_in_sight(grid, start, paths, vertex, bone, bone), [[8.3]])
    np.testing.assert_array_equal(refine_in_sight(grid, start, paths, vertex, bone, bone, leave_start=True), [[8.0]])
    end = clear.copy()
    end[8, 1, 1] = False
    np.testing.assert_array_equal(refine_in_sight(grid, end, paths, vertex, bone, bone, end_margin_cells=1.5), [[8.0]])
    np.testing.assert_array_equal(refine_in_sight(grid, end, paths, vertex, bone, bone), [[8.3]])
