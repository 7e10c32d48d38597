"""Volumetric geodesic vertex-to-bone distances on shapes with known answers."""

import re

import numpy as np
import pytest

from autorig_addon.core.distances.bone_distances import voxelize_covering_bones
from autorig_addon.core.distances.interior import fill_interior
from autorig_addon.core.distances.vertex_distances import UNREACHABLE_PENALTY
from autorig_addon.core.distances.volumetric_geodesic import OUTSIDE_JUMP_PENALTY, volumetric_geodesic_distances
from autorig_addon.core.errors import Cancelled, InputError
from autorig_addon.core.geometry.segments import point_segment_distances
from autorig_addon.core.types import Mesh
from geometry_fixtures import BAD_BONES, body_with_hat, box_mesh, cylinder, vertex_index


def u_tube() -> Mesh:
    """Two upright arms (x in [0, 0.2] and [0.8, 1], y in [0, 1]) joined by
    a base (y in [0, 0.2]); 0.2 thick in z. Three overlapping closed boxes."""
    return Mesh.concatenate([
        box_mesh([0, 0, 0], [0.2, 1, 0.2], 0.05),
        box_mesh([0, 0, 0], [1, 0.2, 0.2], 0.05),
        box_mesh([0.8, 0, 0], [1, 1, 0.2], 0.05),
    ])


def test_convex_shape_gives_straight_distances():
    mesh = cylinder(radius=0.2, height=2.0, segments=32, rings=41)
    heads, tails = np.array([[0, 0, 0.0], [0, 0, 1.0]]), np.array([[0, 0, 1.0], [0, 0, 2.0]])
    distances = volumetric_geodesic_distances(mesh, heads, tails, resolution=88)
    # Inside a convex solid every bone is in sight: the geodesic is the straight line.
    np.testing.assert_allclose(distances, point_segment_distances(mesh.vertices, heads, tails), atol=1e-9)


def test_bent_tube_geodesic_goes_around_the_bend():
    mesh = u_tube()
    heads = np.array([[0.1, 0.3, 0.1], [0.9, 0.3, 0.1]])  # one bone up each arm
    tails = np.array([[0.1, 1.0, 0.1], [0.9, 1.0, 0.1]])
    resolution = 88
    cell = 1.0 / resolution
    distances = volumetric_geodesic_distances(mesh, heads, tails, resolution=resolution)
    tip = vertex_index(mesh, [0.2, 1.0, 0.1])  # top of the first arm, inner face
    straight = point_segment_distances(mesh.vertices[[tip]], heads, tails)[0]
    assert straight[1] == pytest.approx(0.7)
    # Down the inner face (0.8), across the base (0.6), up 45 degrees to the
    # bone's lower end (0.1 * sqrt 2).
    expected = 0.8 + 0.6 + 0.1 * np.sqrt(2)
    assert distances[tip, 1] == pytest.approx(expected, abs=1.5 * cell)
    assert distances[tip, 1] - straight[1] > 0.8
    # Its own bone is in sight: straight distance, exactly.
    assert distances[tip, 0] == pytest.approx(straight[0], abs=1e-9)


def test_bone_outside_the_mesh_gets_finite_penalised_distances():
    mesh = box_mesh([0, 0, 0], [1, 1, 1], 0.1)
    heads, tails = np.array([[0.5, 0.5, 1.3]]), np.array([[0.5, 0.5, 1.6]])
    cell = 1.25 / 88  # the grid grows to cover the bone, by at most a quarter of the box
    distances = volumetric_geodesic_distances(mesh, heads, tails, resolution=88)
    assert np.all(np.isfinite(distances))
    top = vertex_index(mesh, [0.5, 0.5, 1.0])
    bottom = vertex_index(mesh, [0.5, 0.5, 0.0])
    # A penalised jump across the 0.3 gap, then straight down through the box.
    assert distances[top, 0] == pytest.approx(OUTSIDE_JUMP_PENALTY * 0.3, abs=3 * cell)
    assert distances[bottom, 0] == pytest.approx(OUTSIDE_JUMP_PENALTY * 0.3 + 1.0, abs=3 * cell)


def test_bones_inside_an_open_tube_enter_it_all_along():
    # An open sleeve encloses no volume, so its bones lie in the air: each
    # must reach the wall next to it (penalised jump across the radius), not
    # one entry cell from which every path runs along the wall.
    mesh = cylinder(radius=0.1, height=2.0, segments=24, rings=41, capped=False)
    heads, tails = np.array([[0, 0, 0.0], [0, 0, 1.0]]), np.array([[0, 0, 1.0], [0, 0, 2.0]])
    cell = 2.0 / 88
    distances = volumetric_geodesic_distances(mesh, heads, tails, resolution=88)
    z = mesh.vertices[:, 2]
    for bone, part in ((0, z < 0.8), (1, z > 1.2)):
        assert np.all(distances[part].argmin(axis=1) == bone)
        assert distances[part, bone].max() == pytest.approx(OUTSIDE_JUMP_PENALTY * 0.1, abs=4 * cell)


def test_disconnected_part_is_reached_from_the_nearest_bone():
    mesh, hat_vertices, heads, tails = body_with_hat()
    cell = 1.3 / 88
    distances = volumetric_geodesic_distances(mesh, heads, tails, resolution=88)
    assert np.all(np.isfinite(distances))
    straight = point_segment_distances(mesh.vertices, heads, tails)
    assert np.all(distances[hat_vertices] > straight[hat_vertices])
    assert np.all(distances[hat_vertices, 1] < distances[hat_vertices, 0])
    # From the upper bone's tip across the 0.15 air gap, penalised.
    brim_centre = vertex_index(mesh, [0, 0, 1.1])
    assert distances[brim_centre, 1] == pytest.approx(OUTSIDE_JUMP_PENALTY * 0.15, abs=3 * cell)


def test_vertex_in_no_face_gets_the_documented_fallback():
    body = box_mesh([0, 0, 0], [1, 1, 1], 0.25)
    stray = np.array([[5.0, 0.5, 0.5]])
    mesh = Mesh(np.vstack([body.vertices, stray]), body.triangles)
    heads, tails = np.array([[0.5, 0.5, 0.2]]), np.array([[0.5, 0.5, 0.8]])
    distances = volumetric_geodesic_distances(mesh, heads, tails, resolution=20)
    expected = UNREACHABLE_PENALTY * point_segment_distances(stray, heads, tails)[0, 0]
    assert distances[-1, 0] == pytest.approx(expected)


def test_a_shared_grid_gives_the_same_distances():
    mesh = box_mesh([0, 0, 0], [1, 1, 1], 0.25)
    heads, tails = np.array([[0.5, 0.5, 0.2], [0.5, 0.5, 1.2]]), np.array([[0.5, 0.5, 0.8], [0.5, 0.5, 1.4]])
    grid = fill_interior(voxelize_covering_bones(mesh, heads, tails, 20))
    np.testing.assert_array_equal(
        volumetric_geodesic_distances(mesh, heads, tails, grid=grid, resolution=5),  # resolution ignored
        volumetric_geodesic_distances(mesh, heads, tails, resolution=20),
    )


def test_progress_is_reported_and_cancel_stops_the_work():
    mesh = box_mesh([0, 0, 0], [1, 1, 1], 0.25)
    heads, tails = np.array([[0.5, 0.5, 0.2]]), np.array([[0.5, 0.5, 0.8]])
    reports = []
    volumetric_geodesic_distances(mesh, heads, tails, resolution=16, progress=lambda f, m: reports.append((f, m)))
    fractions = [fraction for fraction, _ in reports]
    assert fractions == sorted(fractions)
    assert reports[0] == (0.0, "Voxelising the surface")
    assert (0.2, "Building the path graph") in reports
    assert reports[-1] == (1.0, "Distances done")

    def cancel(fraction, message):
        raise Cancelled()

    with pytest.raises(Cancelled):
        volumetric_geodesic_distances(mesh, heads, tails, resolution=16, progress=cancel)


@pytest.mark.parametrize("heads, tails, message", BAD_BONES)
def test_bad_bones_are_rejected(heads, tails, message):
    mesh = box_mesh([0, 0, 0], [1, 1, 1], 0.25)
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        volumetric_geodesic_distances(mesh, heads, tails)
