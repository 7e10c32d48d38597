"""Geometric skinning from voxel distances."""

import numpy as np
import pytest
from geometry_fixtures import cylinder
from test_voxelize import box_mesh

from autorig_addon.core.errors import Cancelled, InputError
from autorig_addon.core.skinning.geometric import (
    geometric_weights,
    heat_diffusion_weights,
)
from autorig_addon.core.geometry.mesh_ops import smooth_over_edges, weld_vertices
from autorig_addon.core.types import Mesh, Skeleton


def two_bone_cylinder():
    """Cylinder r = 0.2 along z in [0, 2]; bone 'lower' z in [0, 1], 'upper' [1, 2]."""
    mesh = cylinder(radius=0.2, height=2.0, segments=24, rings=41)
    skeleton = Skeleton([[0, 0, 0], [0, 0, 1.0]], [-1, 0], ("lower", "upper"), [[0, 0, 1.0], [0, 0, 2.0]])
    return mesh, skeleton


def assert_valid(weights, max_influences):
    matrix = weights.matrix
    assert np.all(np.isfinite(matrix)) and np.all(matrix >= 0)
    np.testing.assert_allclose(matrix.sum(axis=1), 1.0, atol=1e-9)
    assert np.count_nonzero(matrix, axis=1).max() <= max_influences
    assert np.count_nonzero(matrix, axis=1).min() >= 1


@pytest.mark.parametrize("method", ["geodesic", "hollow"])
def test_two_bone_cylinder_ends_follow_their_bone_and_blend_in_the_middle(method):
    mesh, skeleton = two_bone_cylinder()
    weights = geometric_weights(mesh, skeleton, method=method)
    assert weights.bone_names == ("lower", "upper")
    assert_valid(weights, 4)
    z = mesh.vertices[:, 2]
    lower, upper = weights.matrix[:, 0], weights.matrix[:, 1]
    assert lower[z < 0.3].min() > 0.95
    assert upper[z > 1.7].min() > 0.95
    middle = np.abs(z - 1.0) < 1e-9
    np.testing.assert_allclose(upper[middle], 0.5, atol=0.02)
    # The blend rises with height, and mirrors between the bones.
    ring_means = [upper[np.abs(z - level) < 1e-9].mean() for level in np.linspace(0.3, 1.7, 15)]
    assert np.all(np.diff(ring_means) > 0)
    np.testing.assert_allclose(ring_means, 1.0 - np.array(ring_means[::-1]), atol=0.02)


def test_max_influences_one_gives_rigid_binding():
    mesh, skeleton = two_bone_cylinder()
    weights = geometric_weights(mesh, skeleton, max_influences=1)
    assert_valid(weights, 1)
    z = mesh.vertices[:, 2]
    np.testing.assert_array_equal(weights.matrix[z < 0.9].argmax(axis=1), 0)
    np.testing.assert_array_equal(weights.matrix[z > 1.1].argmax(axis=1), 1)


def test_zero_max_influences_keeps_every_bone():
    mesh, _ = two_bone_cylinder()
    skeleton = Skeleton(
        [[0, 0, 0], [0, 0, 0.7], [0, 0, 1.4]], [-1, 0, 1], ("a", "b", "c"), [[0, 0, 0.7], [0, 0, 1.4], [0, 0, 2.0]]
    )
    unlimited = geometric_weights(mesh, skeleton, max_influences=0)
    assert_valid(unlimited, 3)
    assert np.count_nonzero(unlimited.matrix, axis=1).max() == 3
    limited = geometric_weights(mesh, skeleton, max_influences=2)
    assert_valid(limited, 2)


@pytest.mark.parametrize("method", ["geodesic", "hollow"])
def test_far_loose_part_binds_to_its_nearest_bone(method):
    body, skeleton = two_bone_cylinder()
    prop = box_mesh([-0.1, -0.1, 4.0], [0.1, 0.1, 4.2], 0.05)  # 2 above the top, 3 above 'lower'
    mesh = Mesh.concatenate([body, prop])
    weights = geometric_weights(mesh, skeleton, method=method)
    assert_valid(weights, 4)
    assert weights.matrix[body.vertex_count:, 1].min() > 0.95


def test_only_deform_bones_get_columns():
    mesh, _ = two_bone_cylinder()
    skeleton = Skeleton(
        [[0, 0, 0], [0, 0, 1.0], [0, 0, 1.0]], [-1, 0, 1], ("lower", "control", "upper"),
        [[0, 0, 1.0], [0.5, 0, 1.0], [0, 0, 2.0]], deform=[True, False, True],
    )
    weights = geometric_weights(mesh, skeleton)
    assert weights.bone_names == ("lower", "upper")
    assert weights.matrix[mesh.vertices[:, 2] > 1.7, 1].min() > 0.95


def test_parts_whose_nearest_bone_is_one_bone_get_exactly_that_bone():
    # Two separate triangles, each nearest to a different bone: the heat
    # equation's solution is the indicator of the nearest bone on each part.
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], [[0, 1, 2], [3, 4, 5]])
    distances = np.array([[0.1, 0.9], [0.2, 0.8], [0.3, 0.7], [0.9, 0.1], [0.8, 0.2], [0.7, 0.3]])
    weights = heat_diffusion_weights(mesh, distances, 4.0)
    np.testing.assert_allclose(weights / weights.sum(axis=1, keepdims=True), [[1, 0]] * 3 + [[0, 1]] * 3, atol=1e-12)


def test_higher_falloff_gives_a_narrower_blend():
    mesh, skeleton = two_bone_cylinder()

    def blended_vertices(falloff):
        upper = geometric_weights(mesh, skeleton, falloff=falloff).matrix[:, 1]
        return np.count_nonzero((upper > 0.05) & (upper < 0.95))

    assert blended_vertices(16.0) < blended_vertices(4.0) < blended_vertices(1.0)


def test_weights_do_not_depend_on_scene_scale():
    mesh, skeleton = two_bone_cylinder()
    reference = geometric_weights(mesh, skeleton)
    for scale in (1e-3, 1e3):
        scaled_mesh = Mesh(mesh.vertices * scale, mesh.triangles)
        scaled = Skeleton(skeleton.joints * scale, skeleton.parents, skeleton.names, skeleton.tails * scale)
        np.testing.assert_allclose(geometric_weights(scaled_mesh, scaled).matrix, reference.matrix, atol=1e-6)


def test_smoothing_averages_neighbours_and_keeps_loose_vertices():
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]], [[0, 1, 2]])
    values = np.array([[1.0], [0.0], [0.0], [7.0]])
    smoothed = smooth_over_edges(values, mesh.triangles, iterations=1, strength=0.5)
    np.testing.assert_allclose(smoothed.ravel(), [0.5, 0.25, 0.25, 7.0])


def test_welded_mesh_smoothing_spreads_across_the_whole_surface():
    # Unwelded box faces do not exchange values; welding joins them.
    box = box_mesh([0, 0, 0], [1, 1, 1], 0.5)
    welded_vertices, welded_triangles, _ = weld_vertices(box.vertices, box.triangles, 1e-9)
    welded = Mesh(welded_vertices, welded_triangles)
    values = np.zeros((welded.vertex_count, 1))
    values[0] = 1.0
    smoothed = smooth_over_edges(values, welded.triangles, iterations=20, strength=0.5)
    assert np.all(smoothed > 0)


def test_cancel_stops_the_work():
    mesh, skeleton = two_bone_cylinder()

    def cancel(fraction, message):
        raise Cancelled()

    with pytest.raises(Cancelled):
        geometric_weights(mesh, skeleton, progress=cancel)


def test_bad_input_is_rejected_with_a_clear_message():
    mesh, skeleton = two_bone_cylinder()
    with pytest.raises(InputError, match="no deform bones"):
        geometric_weights(mesh, Skeleton(skeleton.joints, skeleton.parents, skeleton.names, skeleton.tails, [False, False]))
    with pytest.raises(InputError, match="one column per deform bone"):
        geometric_weights(mesh, skeleton, distances=np.ones((mesh.vertex_count, 3)))
    with pytest.raises(InputError, match="finite"):
        geometric_weights(mesh, skeleton, distances=np.full((mesh.vertex_count, 2), np.nan))
    with pytest.raises(InputError, match="Unknown distance method"):
        geometric_weights(mesh, skeleton, method="heat")
    with pytest.raises(InputError, match="Falloff"):
        geometric_weights(mesh, skeleton, falloff=0.0)
    with pytest.raises(InputError, match="Max influences"):
        geometric_weights(mesh, skeleton, max_influences=-1)
    with pytest.raises(InputError, match="Smoothing strength"):
        geometric_weights(mesh, skeleton, smoothing_strength=1.5)


def test_a_vertex_sees_its_nearest_bone_only_when_the_path_is_straight():
    from autorig_addon.core.skinning.geometric import sees_nearest_bone

    vertices = np.array([[0.0, 1.0, 0.0], [0.0, 2.0, 0.0]])
    heads, tails = np.array([[-1.0, 0.0, 0.0]]), np.array([[1.0, 0.0, 0.0]])
    # Straight distances are 1 and 2; the second vertex's path bends around something (2.5).
    distances = np.array([[1.0], [2.5]])
    np.testing.assert_array_equal(sees_nearest_bone(vertices, distances, heads, tails), [True, False])


def test_a_part_that_sees_no_bone_is_still_bound_to_its_nearest():
    mesh = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], [[0, 1, 2], [3, 4, 5]])
    distances = np.array([[0.1, 0.9], [0.2, 0.8], [0.3, 0.7], [0.9, 0.1], [0.8, 0.2], [0.7, 0.3]])
    heated = np.array([True, True, True, False, False, False])
    weights = heat_diffusion_weights(mesh, distances, 4.0, heated)
    np.testing.assert_allclose(weights / weights.sum(axis=1, keepdims=True), [[1, 0]] * 3 + [[0, 1]] * 3, atol=1e-12)
