"""The simplified proxy of a big mesh and carrying values back from it
(core/geometry/proxy), against answers that follow from linearity, from
where each vertex lies and from what belongs to which part."""

import numpy as np
import pytest

from autorig_addon.core.geometry.proxy import COUNT_TOLERANCE, simplified_proxy
from autorig_addon.core.geometry.topology import edges
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh, cylinder, subdivided

RADIUS, HEIGHT = 0.5, 2.0


@pytest.fixture(scope="module")
def capped_cylinder():
    """Closed cylinder r 0.5 along z in [0, 2], subdivided to 16,898 vertices
    (edges about 1.6 cm): flat caps, a smooth side, sharp rims."""
    return subdivided(cylinder(radius=RADIUS, height=HEIGHT, segments=32, rings=33), 2)


@pytest.fixture(scope="module")
def open_cylinder():
    """The side alone (no caps, no rims): a smooth surface, 16,512 vertices."""
    return subdivided(cylinder(radius=RADIUS, height=HEIGHT, segments=32, rings=33, capped=False), 2)


def triangles_in_use(proxy) -> np.ndarray:
    used = np.zeros(proxy.mesh.vertex_count, dtype=bool)
    used[proxy.mesh.triangles.ravel()] = True
    return used


def test_a_linear_function_comes_back_exactly_on_flat_proxy_surface_and_within_a_cell_elsewhere(capped_cylinder):
    mesh = capped_cylinder
    proxy = simplified_proxy(mesh, 2000)
    h = proxy.cell_size
    gradient = np.array([0.3, -0.7, 1.1])

    def linear(points):
        return points @ gradient + 0.25

    carried = proxy.carry(linear(proxy.mesh.vertices)[:, None])[:, 0]
    error = np.abs(carried - linear(mesh.vertices))
    # Interpolation weights are barycentric, so the carried value is the
    # function at the carried point P(x), and the error is |g . (P(x) - x)|.
    # P(x) is the closest point of triangles holding x's cluster vertex,
    # which lies in x's cell, so |P(x) - x| is at most a cell diagonal.
    assert triangles_in_use(proxy)[proxy.cluster].all()
    assert error.max() <= np.linalg.norm(gradient) * np.sqrt(3) * h
    # On the caps, away from the rim, every proxy vertex around a vertex is
    # a mean of cap vertices, so the proxy is the cap's plane there and the
    # closest point is the vertex itself: the value comes back exactly.
    z, r = mesh.vertices[:, 2], np.linalg.norm(mesh.vertices[:, :2], axis=1)
    flat = ((z == 0.0) | (z == HEIGHT)) & (r < RADIUS - 3 * h)
    assert flat.sum() > 100
    assert error[flat].max() <= 1e-9


def test_the_proxy_has_about_the_vertices_asked_for(capped_cylinder):
    for target in (300, 1000, 3000):
        count = simplified_proxy(capped_cylinder, target).mesh.vertex_count
        assert abs(count / target - 1.0) <= COUNT_TOLERANCE


def test_rows_are_barycentric_and_never_empty_with_several_objects_and_loose_bits(capped_cylinder):
    speck = Mesh([[3.0, 0, 0], [3.001, 0, 0], [3.0, 0.001, 0]], [[0, 1, 2]], object_names=("speck",))
    point = Mesh([[0.0, 0, 5.0]], np.zeros((0, 3), int), object_names=("point",))
    hat = box_mesh([-0.3, -0.3, 2.2], [0.3, 0.3, 2.4], 0.05)
    mesh = Mesh.concatenate([capped_cylinder, speck, point, hat])
    proxy = simplified_proxy(mesh, 500)
    matrix = proxy.interpolation
    assert matrix.shape == (mesh.vertex_count, proxy.mesh.vertex_count)
    np.testing.assert_allclose(np.asarray(matrix.sum(axis=1)).ravel(), 1.0, atol=1e-12)
    assert matrix.data.min() >= 0.0
    assert np.diff(matrix.indptr).min() >= 1 and np.diff(matrix.indptr).max() <= 3
    # Every part (here each object, the hat's faces welded) keeps proxy
    # vertices of its own: the speck (a triangle far smaller than a cell)
    # and the lone vertex included.
    parts = np.repeat(np.arange(4), np.diff(mesh.object_offsets))
    for part in range(4):
        own = np.unique(proxy.cluster[parts == part])
        assert not np.isin(own, proxy.cluster[parts != part]).any()
    carried = proxy.carry(proxy.mesh.vertices)
    speck_rows = slice(capped_cylinder.vertex_count, capped_cylinder.vertex_count + 3)
    np.testing.assert_allclose(carried[speck_rows], np.tile(speck.vertices.mean(axis=0), (3, 1)), atol=1e-15)
    np.testing.assert_array_equal(carried[capped_cylinder.vertex_count + 3], [0.0, 0, 5.0])


def test_a_loose_button_touching_the_body_keeps_its_own_values(capped_cylinder):
    # A 2 cm box 1 mm off the side, far smaller than a cell (about 14 cm):
    # it shares cells with the body but is not joined to it.
    button = box_mesh([RADIUS + 0.001, -0.01, 0.99], [RADIUS + 0.021, 0.01, 1.01], 0.01)
    mesh = Mesh.concatenate([capped_cylinder, button])
    proxy = simplified_proxy(mesh, 500)
    assert proxy.cell_size > 0.1
    on_button = np.arange(mesh.vertex_count) >= capped_cylinder.vertex_count
    button_proxy = np.unique(proxy.cluster[on_button])
    assert not np.isin(button_proxy, proxy.cluster[~on_button]).any()
    values = np.zeros((proxy.mesh.vertex_count, 1))
    values[button_proxy] = 1.0
    carried = proxy.carry(values)[:, 0]
    np.testing.assert_array_equal(carried[on_button], 1.0)
    np.testing.assert_array_equal(carried[~on_button], 0.0)


def test_a_smooth_ramp_comes_back_without_jumps_at_cluster_borders(open_cylinder):
    mesh = open_cylinder
    proxy = simplified_proxy(mesh, 500)
    ramp = proxy.carry(proxy.mesh.vertices[:, 2:])[:, 0]  # the height, a ramp of slope 1
    a, b = edges(mesh.triangles).T
    length = np.linalg.norm(mesh.vertices[a] - mesh.vertices[b], axis=1)
    crossing = proxy.cluster[a] != proxy.cluster[b]
    assert crossing.sum() > 1000
    # Closest points on a convex surface from outside it move no further
    # than the points do, so across an edge the carried ramp changes by at
    # most the edge's length; 10 % slack for where the proxy is not convex.
    assert np.max(np.abs(ramp[a] - ramp[b])[crossing] / length[crossing]) <= 1.1
    # Copying the nearest proxy vertex's value instead jumps by up to a cell.
    copied = proxy.mesh.vertices[proxy.cluster, 2]
    assert np.max(np.abs(copied[a] - copied[b])[crossing] / length[crossing]) > 4.0


def test_seam_copies_get_the_values_of_the_welded_surface(capped_cylinder):
    # Turned off the axes, so no vertex normal lies exactly between two
    # axis directions (round-off in welding could then flip its class).
    turn = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    mesh = Mesh(capped_cylinder.vertices @ turn.T, capped_cylinder.triangles)
    soup_vertices = mesh.triangles.ravel()  # every triangle with its own three copies
    soup = Mesh(mesh.vertices[soup_vertices], np.arange(len(soup_vertices)).reshape(-1, 3))
    welded = simplified_proxy(mesh, 500)
    split = simplified_proxy(soup, 500)
    assert split.mesh.vertex_count == welded.mesh.vertex_count
    values = welded.mesh.vertices
    np.testing.assert_allclose(split.carry(split.mesh.vertices), welded.carry(values)[soup_vertices], atol=1e-12)


def test_a_mesh_no_bigger_than_the_target_is_its_own_proxy():
    mesh = cylinder(radius=0.2, height=1.0, segments=12, rings=5)
    proxy = simplified_proxy(mesh, mesh.vertex_count)
    assert proxy.cell_size == 0.0
    np.testing.assert_array_equal(proxy.mesh.vertices, mesh.vertices)
    values = np.random.default_rng(0).random((mesh.vertex_count, 3))
    np.testing.assert_allclose(proxy.carry(values), values, atol=1e-15)


def test_average_is_the_mean_over_each_cluster(capped_cylinder):
    proxy = simplified_proxy(capped_cylinder, 500)
    # The proxy's vertices are the means of their clusters' positions.
    np.testing.assert_allclose(proxy.average(capped_cylinder.vertices), proxy.mesh.vertices, atol=1e-12)


def test_finish_sees_every_row_once_in_batches(capped_cylinder):
    proxy = simplified_proxy(capped_cylinder, 500)
    seen = []

    def finish(rows, carried):
        seen.append(rows)
        return carried / carried.sum(axis=1, keepdims=True)

    values = np.random.default_rng(0).random((proxy.mesh.vertex_count, 4))
    carried = proxy.carry(values, finish)
    assert [r.start for r in seen[1:]] == [r.stop for r in seen[:-1]]
    assert seen[0].start == 0 and seen[-1].stop == capped_cylinder.vertex_count and len(seen) > 1
    plain = proxy.carry(values)
    np.testing.assert_allclose(carried, plain / plain.sum(axis=1, keepdims=True), atol=1e-15)
