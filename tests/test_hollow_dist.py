"""HollowDist vertex-to-bone distances on shapes with known answers."""

import re

import numpy as np
import pytest

from autorig_addon.core.distances.cell_graph import bone_node_distances
from autorig_addon.core.distances.hollow_dist import build_hollow_graph, hollow_distances
from autorig_addon.core.distances.line_of_sight import STAIRCASE_RATIO
from autorig_addon.core.distances.vertex_distances import (
    UNREACHABLE_PENALTY,
    combine_vertex_distances,
    vertex_cell_candidates,
)
from autorig_addon.core.errors import InputError
from autorig_addon.core.geometry.segments import point_segment_distances
from autorig_addon.core.types import Mesh
from geometry_fixtures import BAD_BONES, body_with_hat, box_mesh, cylinder, plain_grid, vertex_index


def test_convex_shape_gives_straight_distances():
    mesh = cylinder(radius=0.2, height=2.0, segments=32, rings=41)
    heads, tails = np.array([[0, 0, 0.0], [0, 0, 1.0]]), np.array([[0, 0, 1.0], [0, 0, 2.0]])
    distances = hollow_distances(mesh, heads, tails, resolution=88)
    np.testing.assert_allclose(distances, point_segment_distances(mesh.vertices, heads, tails), atol=1e-9)


def test_hand_checked_wall_counts_a_layer_and_keeps_the_length():
    # Cells x = 0..7 (two cells thick in y and z, cell size 1), a mesh wall
    # at x = 4, 5. Nodes: 2x2x2 blocks centred at x = 1, 3, 5 (the wall), 7.
    surface = np.zeros((8, 2, 2), dtype=bool)
    surface[4:6] = True
    grid = plain_grid(surface.shape, surface=surface)
    heads, tails = np.array([[0.5, 1.0, 1.0]]), np.array([[1.5, 1.0, 1.0]])  # through the first block's centre
    graph = build_hollow_graph(grid, heads, tails)
    blocks = [graph.nodes.cell_node[x, 0, 0] for x in (0, 2, 4, 6)]
    raw = bone_node_distances(graph, np.array(blocks))[:, 0]
    # Entering the wall is free, leaving it costs one layer.
    np.testing.assert_allclose(raw, [0, 2, 4, 6 + graph.layer_cost], atol=1e-9)
    # Above any path: 4 nodes x the longest step (2) + the longest bone edge (0)
    # + 4 cells, rounded up to a power of two.
    assert graph.layer_cost == 16.0
    beyond = np.array([[7.5, 1.0, 1.0]])
    candidates, query = vertex_cell_candidates(graph, beyond)
    distance, layers = combine_vertex_distances(graph, beyond, candidates, query, bone_node_distances(graph, query))
    assert distance[0, 0] == pytest.approx(6.5) and layers[0, 0] == 1


def test_bone_outside_a_closed_box_reaches_round_it_not_through_it():
    # A 0.4 x 0.4 x 1 box and a bone alongside it, 0.2 from its +x face.
    mesh = box_mesh([-0.2, -0.2, 0], [0.2, 0.2, 1], 0.05)
    heads, tails = np.array([[0.4, 0, 0.2]]), np.array([[0.4, 0, 0.8]])
    distances = hollow_distances(mesh, heads, tails, resolution=88)[:, 0]
    cell = 1.0 / 88
    near = vertex_index(mesh, [0.2, 0, 0.5])
    far = vertex_index(mesh, [-0.2, 0, 0.5])
    assert distances[near] == pytest.approx(0.2, abs=1e-9)  # in sight through the air
    # Round the box in the plane z = 0.5: to the corner (0.2, 0.2), along the
    # side (0.4), down the far face (0.2); not through the box (0.6). Bent
    # paths are chains of cell steps: at most STAIRCASE_RATIO times longer.
    around = 0.2 * np.sqrt(2) + 0.4 + 0.2
    assert around - 2 * cell <= distances[far] <= STAIRCASE_RATIO * around + 3 * cell


def test_open_sheet_is_a_wall_paths_go_around():
    # Bone inside box A, target box B, a square sheet (cloth) between them.
    sheet = Mesh([[0, -0.5, -0.5], [0, 0.5, -0.5], [0, 0.5, 0.5], [0, -0.5, 0.5]], [[0, 1, 2], [0, 2, 3]])
    box_a = box_mesh([-0.4, -0.1, -0.1], [-0.2, 0.1, 0.1], 0.05)
    box_b = box_mesh([0.2, -0.1, -0.1], [0.4, 0.1, 0.1], 0.05)
    mesh = Mesh.concatenate([sheet, box_a, box_b])
    heads, tails = np.array([[-0.35, 0, 0]]), np.array([[-0.25, 0, 0]])
    distances = hollow_distances(mesh, heads, tails, resolution=88)[:, 0]
    cell = 1.0 / 88
    target = vertex_index(mesh, [0.2, 0, 0])
    assert point_segment_distances(mesh.vertices[[target]], heads, tails)[0, 0] == pytest.approx(0.45)
    # Round the sheet's nearest edge (0, +-0.5, 0) or (0, 0, +-0.5).
    around = np.hypot(0.25, 0.5) + np.hypot(0.2, 0.5)
    assert around - 2 * cell <= distances[target] <= STAIRCASE_RATIO * around + 3 * cell
    # A vertex of box A sees the bone from inside: straight.
    own = vertex_index(mesh, [-0.2, 0, 0])
    assert distances[own] == pytest.approx(0.05, abs=1e-9)


def test_disconnected_part_gets_finite_distances_through_the_air():
    mesh, hat_vertices, heads, tails = body_with_hat()
    cell = 1.3 / 88
    distances = hollow_distances(mesh, heads, tails, resolution=88)
    assert np.all(np.isfinite(distances))
    assert np.all(distances[hat_vertices, 1] < distances[hat_vertices, 0])
    # Straight up out of the body, across the gap: 0.15 from the bone's tip.
    brim_centre = vertex_index(mesh, [0, 0, 1.1])
    assert distances[brim_centre, 1] == pytest.approx(0.15, abs=3 * cell)


@pytest.mark.parametrize("heads, tails, message", BAD_BONES)
def test_bad_bones_are_rejected(heads, tails, message):
    mesh = box_mesh([0, 0, 0], [1, 1, 1], 0.25)
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        hollow_distances(mesh, heads, tails)


def test_vertex_in_no_face_outside_the_grid_gets_the_documented_fallback():
    body = box_mesh([0, 0, 0], [1, 1, 1], 0.25)
    stray = np.array([[5.0, 0.5, 0.5]])
    mesh = Mesh(np.vstack([body.vertices, stray]), body.triangles)
    heads, tails = np.array([[0.5, 0.5, 0.2]]), np.array([[0.5, 0.5, 0.8]])
    distances = hollow_distances(mesh, heads, tails, resolution=20)
    assert distances[-1, 0] == pytest.approx(UNREACHABLE_PENALTY * 4.5)  # 4.5 straight to the bone
