"""Geometric skinning (core/skinning/geometric) and the bone heat diffusion
it runs (core/skinning/heat_diffusion), against answers that follow from
symmetry, linearity and the heat equation."""

import re

import numpy as np
import pytest

from autorig_addon.core.errors import Cancelled, InputError
from autorig_addon.core.geometry.segments import point_segment_distances
from autorig_addon.core.skinning import geometric
from autorig_addon.core.skinning.geometric import geometric_weights, sees_nearest_bone
from autorig_addon.core.skinning.heat_diffusion import heat_diffusion_weights
from autorig_addon.core.types import Mesh, Skeleton
from geometry_fixtures import box_mesh, cylinder, grid, subdivided


def two_bone_cylinder():
    """Cylinder r = 0.2 along z in [0, 2], rings every 0.05; bone 'lower' z in [0, 1], 'upper' [1, 2].

    The mesh maps onto itself under (z, angle) -> (2 - z, -angle), which swaps
    the bones, and under turns by 1/24 of a circle.
    """
    mesh = cylinder(radius=0.2, height=2.0, segments=24, rings=41)
    skeleton = Skeleton([[0, 0, 0], [0, 0, 1.0]], [-1, 0], ("lower", "upper"), [[0, 0, 1.0], [0, 0, 2.0]])
    return mesh, skeleton


def straight_distances(mesh, skeleton):
    return point_segment_distances(mesh.vertices, skeleton.joints, skeleton.tails)


def ring_values(mesh, values):
    """(levels, per-ring mean, per-ring spread) of per-vertex ``values``."""
    z = np.round(mesh.vertices[:, 2], 9)
    levels = np.unique(z)
    return levels, np.array([values[z == h].mean() for h in levels]), np.array([np.ptp(values[z == h]) for h in levels])


def assert_valid(weights, max_influences):
    matrix = weights.matrix
    assert np.all(np.isfinite(matrix)) and np.all(matrix >= 0)
    np.testing.assert_allclose(matrix.sum(axis=1), 1.0, atol=1e-12)
    assert np.count_nonzero(matrix, axis=1).max() <= max_influences
    assert np.count_nonzero(matrix, axis=1).min() >= 1


# --------------------------------------------------------------------------- heat diffusion


def test_diffused_heat_sums_to_one_on_every_vertex():
    # The sources of each vertex sum to one, and (-L + MH) 1 = MH 1 (L 1 = 0),
    # so the unnormalised weights of all bones add up to exactly 1.
    mesh, skeleton = two_bone_cylinder()
    raw = heat_diffusion_weights(mesh, straight_distances(mesh, skeleton), 4.0)
    np.testing.assert_allclose(raw.sum(axis=1), 1.0, atol=1e-12)


def test_heat_clamped_at_the_ends_of_a_strip_blends_linearly():
    # Only the two end columns are heated (each by its own bone, at distance
    # 0, i.e. nearly clamped); in between the weights are harmonic, and on a
    # flat grid the cotangent-harmonic function with those ends is x itself.
    strip = grid(11, 5)
    x = strip.vertices[:, 0]
    distances = np.column_stack([x, 1.0 - x])
    ends = (x < 1e-9) | (x > 1 - 1e-9)
    raw = heat_diffusion_weights(strip, distances, 4.0, heated=ends)
    np.testing.assert_allclose(raw[:, 1], x, atol=1e-6)
    np.testing.assert_allclose(raw.sum(axis=1), 1.0, atol=1e-12)


def test_parts_whose_nearest_bone_is_one_bone_get_exactly_that_bone():
    # Two separate triangles, each nearest to a different bone: the heat
    # equation's solution is the indicator of the nearest bone on each part.
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], [[0, 1, 2], [3, 4, 5]])
    distances = np.array([[0.1, 0.9], [0.2, 0.8], [0.3, 0.7], [0.9, 0.1], [0.8, 0.2], [0.7, 0.3]])
    weights = heat_diffusion_weights(mesh, distances, 4.0)
    np.testing.assert_allclose(weights, [[1, 0]] * 3 + [[0, 1]] * 3, atol=1e-12)


def test_a_part_that_sees_no_bone_is_still_bound_to_its_nearest():
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], [[0, 1, 2], [3, 4, 5]])
    distances = np.array([[0.1, 0.9], [0.2, 0.8], [0.3, 0.7], [0.9, 0.1], [0.8, 0.2], [0.7, 0.3]])
    heated = np.array([True, True, True, False, False, False])
    weights = heat_diffusion_weights(mesh, distances, 4.0, heated)
    np.testing.assert_allclose(weights, [[1, 0]] * 3 + [[0, 1]] * 3, atol=1e-12)


def test_seam_copies_get_the_weights_of_the_welded_surface():
    mesh, skeleton = two_bone_cylinder()
    distances = straight_distances(mesh, skeleton)
    soup_vertices = mesh.triangles.ravel()  # every triangle with its own three copies
    soup = Mesh(mesh.vertices[soup_vertices], np.arange(len(soup_vertices)).reshape(-1, 3))
    np.testing.assert_allclose(
        heat_diffusion_weights(soup, distances[soup_vertices], 4.0),
        heat_diffusion_weights(mesh, distances, 4.0)[soup_vertices],
        atol=1e-12,
    )


def test_a_vertex_sees_its_nearest_bone_only_when_the_path_is_straight():
    vertices = np.array([[0.0, 1.0, 0.0], [0.0, 2.0, 0.0], [0.0, 3.0, 0.0]])
    heads, tails = np.array([[-1.0, 0.0, 0.0]]), np.array([[1.0, 0.0, 0.0]])
    # Straight distances are 1, 2 and 3; the second path is 2 % longer (the
    # slack), the third bends around something (3.1, 3.3 %).
    distances = np.array([[1.0], [2.04], [3.1]])
    np.testing.assert_array_equal(sees_nearest_bone(vertices, distances, heads, tails), [True, True, False])


# --------------------------------------------------------------------------- geometric weights


@pytest.mark.parametrize("distance", ["geodesic", "hollow"])
def test_two_bone_cylinder_blends_symmetrically_about_the_joint(distance):
    mesh, skeleton = two_bone_cylinder()
    # Inside a convex shape both distances are the straight ones, exactly.
    weights = geometric_weights(mesh, skeleton, distance=distance)
    reference = geometric_weights(mesh, skeleton, distances=straight_distances(mesh, skeleton))
    np.testing.assert_array_equal(weights.matrix, reference.matrix)
    assert weights.bone_names == ("lower", "upper")
    assert_valid(weights, 2)
    levels, upper, spread = ring_values(mesh, weights.matrix[:, 1])
    # The mesh's symmetry swaps the bones: the joint ring is exactly half and
    # half, the other rings mirror it, and every ring is uniform.
    assert upper[levels == 1.0] == pytest.approx(0.5, abs=1e-12)
    np.testing.assert_allclose(upper, 1.0 - upper[::-1], atol=1e-12)
    np.testing.assert_allclose(spread, 0.0, atol=1e-12)
    assert np.all(np.diff(upper) >= 0) and np.all(np.diff(upper[(levels > 0.1) & (levels < 1.9)]) > 0)
    # Far from the joint the other bone's weight falls below the influence
    # threshold and is pruned: the ends are rigid.
    bottom = mesh.vertices[:, 2] <= 0.1 + 1e-9  # three rings and the cap centre
    assert bottom.sum() == 3 * 24 + 1
    np.testing.assert_array_equal(weights.matrix[bottom], [[1.0, 0.0]] * (3 * 24 + 1))


def test_max_influences_one_gives_rigid_binding_split_at_the_joint():
    mesh, skeleton = two_bone_cylinder()
    weights = geometric_weights(mesh, skeleton, distances=straight_distances(mesh, skeleton), max_influences=1)
    assert_valid(weights, 1)
    z = mesh.vertices[:, 2]
    np.testing.assert_array_equal(weights.matrix[z < 1 - 1e-9], [[1.0, 0.0]] * int(np.sum(z < 1 - 1e-9)))
    np.testing.assert_array_equal(weights.matrix[z > 1 + 1e-9], [[0.0, 1.0]] * int(np.sum(z > 1 + 1e-9)))


def test_an_influence_limit_keeps_each_rows_largest_weights():
    mesh, _ = two_bone_cylinder()
    skeleton = Skeleton(
        [[0, 0, 0], [0, 0, 0.7], [0, 0, 1.4]], [-1, 0, 1], ("a", "b", "c"), [[0, 0, 0.7], [0, 0, 1.4], [0, 0, 2.0]]
    )
    distances = straight_distances(mesh, skeleton)
    unlimited = geometric_weights(mesh, skeleton, distances=distances, max_influences=0).matrix
    limited = geometric_weights(mesh, skeleton, distances=distances, max_influences=2).matrix
    assert np.count_nonzero(unlimited, axis=1).max() == 3
    assert np.count_nonzero(limited, axis=1).max() == 2
    # The kept bones are the two largest of the unlimited row; rows that
    # already had at most two bones are unchanged.
    smallest = unlimited.argmin(axis=1)
    np.testing.assert_array_equal(limited[np.arange(len(limited)), smallest][np.count_nonzero(unlimited, axis=1) == 3],
                                  0.0)
    two = np.count_nonzero(unlimited, axis=1) <= 2
    np.testing.assert_allclose(limited[two], unlimited[two], atol=1e-12)


@pytest.mark.parametrize("distance", ["geodesic", "hollow"])
def test_far_loose_part_binds_wholly_to_its_nearest_bone(distance):
    body, skeleton = two_bone_cylinder()
    prop = box_mesh([-0.1, -0.1, 4.0], [0.1, 0.1, 4.2], 0.05)  # 2 above the top, 3 above 'lower'
    mesh = Mesh.concatenate([body, prop])
    weights = geometric_weights(mesh, skeleton, distance=distance)
    assert_valid(weights, 2)
    np.testing.assert_array_equal(weights.matrix[body.vertex_count:], [[0.0, 1.0]] * prop.vertex_count)


def test_non_deform_bones_get_no_column_and_change_nothing():
    mesh, two_bones = two_bone_cylinder()
    skeleton = Skeleton(
        [[0, 0, 0], [0, 0, 1.0], [0, 0, 1.0]], [-1, 0, 1], ("lower", "control", "upper"),
        [[0, 0, 1.0], [0.5, 0, 1.0], [0, 0, 2.0]], deform=[True, False, True],
    )
    weights = geometric_weights(mesh, skeleton)
    assert weights.bone_names == ("lower", "upper")
    np.testing.assert_array_equal(weights.matrix, geometric_weights(mesh, two_bones).matrix)


def test_higher_falloff_gives_a_narrower_blend():
    mesh, skeleton = two_bone_cylinder()
    distances = straight_distances(mesh, skeleton)

    def blended_vertices(falloff):
        upper = geometric_weights(mesh, skeleton, distances=distances, falloff=falloff).matrix[:, 1]
        return np.count_nonzero((upper > 0.05) & (upper < 0.95))

    assert blended_vertices(16.0) < blended_vertices(4.0) < blended_vertices(1.0)


def test_weights_do_not_depend_on_scene_scale():
    mesh, skeleton = two_bone_cylinder()
    reference = geometric_weights(mesh, skeleton)
    for scale in (1e-3, 1e3):
        scaled_mesh = Mesh(mesh.vertices * scale, mesh.triangles)
        scaled = Skeleton(skeleton.joints * scale, skeleton.parents, skeleton.names, skeleton.tails * scale)
        np.testing.assert_allclose(geometric_weights(scaled_mesh, scaled).matrix, reference.matrix, atol=1e-9)


def test_progress_ends_at_one_and_cancel_stops_the_work():
    mesh, skeleton = two_bone_cylinder()
    reports = []
    geometric_weights(mesh, skeleton, distances=straight_distances(mesh, skeleton),
                      progress=lambda f, m: reports.append((f, m)))
    assert reports == [(0.9, "Diffusing bone heat"), (1.0, "Weights done")]

    def cancel(fraction, message):
        raise Cancelled()

    with pytest.raises(Cancelled):
        geometric_weights(mesh, skeleton, progress=cancel)


def test_bad_input_is_rejected_with_a_clear_message():
    mesh, skeleton = two_bone_cylinder()
    n = mesh.vertex_count
    cases = [
        ({"skeleton": Skeleton(skeleton.joints, skeleton.parents, skeleton.names, skeleton.tails, [False, False])},
         "The armature has no deform bones; enable Deform on the bones that should move the mesh."),
        ({"mesh": Mesh(np.zeros((0, 3)), np.zeros((0, 3), int))}, "The mesh has no vertices."),
        ({"distances": np.ones((n, 3))},
         f"Distances must have one row per vertex and one column per deform bone ({n} x 2), got ({n}, 3)."),
        ({"distances": np.full((n, 2), np.nan)}, "Distances must be finite and non-negative; recompute them."),
        ({"distances": np.full((n, 2), -1.0)}, "Distances must be finite and non-negative; recompute them."),
        ({"distance": "heat"}, "Unknown distance method 'heat'; use one of geodesic, hollow."),
        ({"falloff": 0.0}, "Falloff must be a positive number, got 0.0."),
        ({"max_influences": -1}, "Max influences must be 0 (no limit) or more, got -1."),
        ({"smoothing_iterations": -1}, "Smoothing iterations cannot be negative, got -1."),
        ({"smoothing_strength": 1.5}, "Smoothing strength must lie in [0, 1], got 1.5."),
    ]
    for options, message in cases:
        arguments = {"mesh": mesh, "skeleton": skeleton, **options}
        with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
            geometric_weights(arguments.pop("mesh"), arguments.pop("skeleton"), **arguments)


# --------------------------------------------------------------------------- big meshes: the proxy


@pytest.fixture(scope="module")
def fine_cylinder_with_button():
    """The two-bone cylinder subdivided to 15,746 vertices, and a 2 cm box
    (a button, its own part) 1 mm off its side just above the joint, where
    the body blends the two bones."""
    body = subdivided(two_bone_cylinder()[0], 2)
    button = box_mesh([0.201, -0.01, 1.04], [0.221, 0.01, 1.06], 0.01)
    return Mesh.concatenate([body, button]), body.vertex_count


def solved_on_proxy(monkeypatch, proxy_vertices):
    """Make every mesh above 1,000 vertices go through a proxy of about ``proxy_vertices``."""
    monkeypatch.setattr(geometric, "PROXY_VERTEX_THRESHOLD", 1000)
    monkeypatch.setattr(geometric, "PROXY_VERTICES", proxy_vertices)


def test_meshes_below_the_threshold_are_solved_vertex_by_vertex(monkeypatch):
    def refuse(*args):
        raise AssertionError("no proxy below the threshold")

    monkeypatch.setattr(geometric, "simplified_proxy", refuse)
    mesh, skeleton = two_bone_cylinder()
    assert mesh.vertex_count <= geometric.PROXY_VERTEX_THRESHOLD
    assert_valid(geometric_weights(mesh, skeleton), 2)


def test_weights_through_the_proxy_approach_the_full_solution_as_it_is_refined(monkeypatch, fine_cylinder_with_button):
    mesh, _ = fine_cylinder_with_button
    _, skeleton = two_bone_cylinder()
    full = geometric_weights(mesh, skeleton).matrix
    errors = []
    for proxy_vertices in (750, 1500, 3000):
        solved_on_proxy(monkeypatch, proxy_vertices)
        weights = geometric_weights(mesh, skeleton)
        assert_valid(weights, 2)
        errors.append(np.abs(weights.matrix - full).max())
    # The error follows the cell size (the square root of the vertex
    # count): each doubling of the proxy shrinks it, here to under 0.03.
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.03


def test_a_button_touching_a_big_body_keeps_its_own_bone(monkeypatch, fine_cylinder_with_button):
    mesh, body_count = fine_cylinder_with_button
    _, skeleton = two_bone_cylinder()
    solved_on_proxy(monkeypatch, 1500)
    weights = geometric_weights(mesh, skeleton).matrix
    # The button lies wholly above the joint: every one of its vertices is
    # nearest the upper bone, so heat in the button alone gives exactly that
    # bone, while the body it touches blends both bones there.
    np.testing.assert_array_equal(weights[body_count:], [[0.0, 1.0]] * (mesh.vertex_count - body_count))
    z = mesh.vertices[:body_count, 2]
    beside = np.abs(z - 1.05) < 0.02
    assert np.all((weights[:body_count][beside, 1] > 0.5) & (weights[:body_count][beside, 1] < 0.9))


def test_given_distances_are_averaged_onto_the_proxy(monkeypatch, fine_cylinder_with_button):
    mesh, _ = fine_cylinder_with_button
    _, skeleton = two_bone_cylinder()
    distances = straight_distances(mesh, skeleton)
    full = geometric_weights(mesh, skeleton, distances=distances).matrix
    solved_on_proxy(monkeypatch, 3000)
    reports = []
    weights = geometric_weights(mesh, skeleton, distances=distances, progress=lambda f, m: reports.append(m))
    assert_valid(weights, 2)
    assert np.abs(weights.matrix - full).max() < 0.05
    assert reports == ["Simplifying the mesh", "Diffusing bone heat", "Carrying the weights to every vertex",
                       "Weights done"]


def test_a_far_prop_on_a_big_mesh_binds_wholly_to_its_nearest_bone(monkeypatch, fine_cylinder_with_button):
    body, _ = fine_cylinder_with_button
    _, skeleton = two_bone_cylinder()
    prop = box_mesh([-0.1, -0.1, 4.0], [0.1, 0.1, 4.2], 0.05)
    mesh = Mesh.concatenate([body, prop])
    solved_on_proxy(monkeypatch, 1500)
    weights = geometric_weights(mesh, skeleton, max_influences=1)
    assert_valid(weights, 1)
    np.testing.assert_array_equal(weights.matrix[body.vertex_count:], [[0.0, 1.0]] * prop.vertex_count)
