import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.transfer.transfer import (
    TransferOptions,
    VertexStatus,
    inpaint_weights,
    inpainting_operator,
    transfer_weights,
)
from autorig_addon.core.types import Mesh, Weights
from geometry_fixtures import cylinder, grid, two_bone_weights


@pytest.fixture(scope="module")
def body():
    mesh = cylinder(radius=0.1, segments=32, rings=41)
    return mesh, two_bone_weights(mesh)


def sleeve(radius=0.11, z0=0.05, height=0.9, flip=False, rings=31):
    return cylinder(radius=radius, height=height, z0=z0, segments=40, rings=rings, capped=False, flip=flip)


def expected_upper(z, blend=0.2):
    return np.clip((z - (0.5 - blend / 2)) / blend, 0, 1)


def test_close_sleeve_copies_the_body_weights(body):
    source, weights = body
    target = sleeve()
    result = transfer_weights(source, weights, target)
    assert np.all(result.status == VertexStatus.COPIED)
    np.testing.assert_allclose(result.weights.matrix.sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(result.weights.matrix[:, 1], expected_upper(target.vertices[:, 2]), atol=0.02)
    assert result.max_distance == pytest.approx(0.05 * target.bounding_box_diagonal)


def test_inner_layer_with_flipped_normals_needs_the_second_pass(body):
    source, weights = body
    target = sleeve(radius=0.095, flip=True)
    result = transfer_weights(source, weights, target)
    assert np.all(result.status == VertexStatus.COPIED_FLIPPED)
    with pytest.raises(InputError, match="No vertex"):
        transfer_weights(source, weights, target, TransferOptions(accept_flipped_normals=False))


def test_masked_band_is_inpainted_smoothly_and_symmetrically(body):
    source, weights = body
    target = sleeve()
    z = target.vertices[:, 2]
    mask = (z > 0.3) & (z < 0.7)
    result = transfer_weights(source, weights, target, inpaint_mask=mask)
    assert np.all(result.status[mask] == VertexStatus.MASKED)
    assert np.all(result.status[~mask] == VertexStatus.COPIED)
    upper = result.weights.matrix[:, 1]
    ring_mean = {round(h, 6): upper[np.isclose(z, h)].mean() for h in np.unique(z[mask])}
    heights = sorted(ring_mean)
    values = np.array([ring_mean[h] for h in heights])
    assert np.all(np.diff(values) >= -1e-6)  # monotone along the sleeve
    middle = values[np.argmin(np.abs(np.array(heights) - 0.5))]
    assert middle == pytest.approx(0.5, abs=0.03)
    # Rings stay rings: inpainting does not vary around the axis.
    for h in heights:
        assert np.ptp(upper[np.isclose(z, h)]) < 1e-3


def test_far_overhang_is_inpainted_from_the_matched_rows(body):
    source, weights = body
    target = sleeve(z0=-0.4, height=1.0, rings=41)  # 0.4 below the body's end
    result = transfer_weights(source, weights, target)
    overhang = target.vertices[:, 2] < -0.1
    assert np.all(result.status[overhang] == VertexStatus.INPAINTED)
    np.testing.assert_allclose(result.weights.matrix[overhang, 0], 1.0, atol=0.02)


def test_disconnected_button_moves_rigidly_with_its_closest_point(body):
    source, weights = body
    garment = sleeve()
    button = cylinder(radius=0.02, height=0.02, segments=8, rings=2, z0=0.15)
    button = Mesh(button.vertices + np.array([0.25, 0, 0]), button.triangles)
    target = Mesh.concatenate([garment, button])
    result = transfer_weights(source, weights, target)
    on_button = np.arange(target.vertex_count) >= garment.vertex_count
    assert np.all(result.status[on_button] == VertexStatus.UNMATCHED_PART)
    button_weights = result.weights.matrix[on_button]
    assert np.ptp(button_weights, axis=0).max() < 1e-9  # one rigid set of weights
    np.testing.assert_allclose(button_weights[:, 0], 1.0, atol=1e-9)  # the body's lower bone at z=0.15
    assert np.all(np.isfinite(result.weights.matrix))


def test_protected_rows_keep_their_weights_exactly(body):
    source, weights = body
    target = sleeve()
    top = target.vertices[:, 2] > 0.9
    kept = Weights(np.column_stack([np.full(target.vertex_count, 0.25), np.full(target.vertex_count, 0.75)]),
                   ("upper", "lower"))  # other bone order on purpose
    result = transfer_weights(source, weights, target, protected=top, protected_weights=kept)
    np.testing.assert_allclose(result.weights.matrix[top], [[0.75, 0.25]] * top.sum(), atol=1e-12)
    assert np.all(result.status[top] == VertexStatus.PROTECTED)


def test_seam_split_copies_get_the_same_weights_as_the_welded_mesh(body):
    source, weights = body
    target = sleeve()
    z = target.vertices[:, 2]
    mask = (z > 0.3) & (z < 0.7)
    welded = transfer_weights(source, weights, target, inpaint_mask=mask)
    soup_vertices = target.vertices[target.triangles.ravel()]
    soup = Mesh(soup_vertices, np.arange(len(soup_vertices)).reshape(-1, 3))
    split = transfer_weights(source, weights, soup, inpaint_mask=mask[target.triangles.ravel()])
    np.testing.assert_allclose(split.weights.matrix, welded.weights.matrix[target.triangles.ravel()], atol=1e-9)
    assert welded.welded_vertices == 0
    assert split.welded_vertices == soup.vertex_count - target.vertex_count
    assert f"{split.welded_vertices} seam duplicates welded" in split.summary()


def test_degenerate_target_triangles_never_produce_nan(body):
    source, weights = body
    target = sleeve()
    V = np.vstack([target.vertices, target.vertices[:1], target.vertices[:1] * [1, 1, 1.0000001]])
    F = np.vstack([target.triangles, [[0, len(V) - 2, len(V) - 1]], [[1, 1, 2]]])
    result = transfer_weights(source, weights, Mesh(V, F), inpaint_mask=np.isclose(V[:, 2], 0.05))
    assert np.all(np.isfinite(result.weights.matrix))
    np.testing.assert_allclose(result.weights.matrix.sum(axis=1), 1.0, atol=1e-12)


def test_influence_limit_and_smoothing_keep_rows_normalised(body):
    source, weights = body
    target = sleeve()
    mask = np.abs(target.vertices[:, 2] - 0.5) < 0.2
    result = transfer_weights(source, weights, target, TransferOptions(max_influences=1, smoothing_iterations=5),
                              inpaint_mask=mask)
    assert np.all((result.weights.matrix > 0).sum(axis=1) == 1)
    np.testing.assert_allclose(result.weights.matrix.sum(axis=1), 1.0, atol=1e-12)


@pytest.mark.parametrize("offset, scale, message", [
    ([5.0, 0, 0], 1.0, "does not overlap"),
    ([0, 0, 0], 100.0, "different scales"),
])
def test_far_apart_or_rescaled_targets_are_refused(body, offset, scale, message):
    source, weights = body
    target = sleeve()
    moved = Mesh(target.vertices * scale + np.array(offset), target.triangles)
    with pytest.raises(InputError, match=message):
        transfer_weights(source, weights, moved)


def test_target_without_faces_and_empty_source_weights_are_refused(body):
    source, weights = body
    with pytest.raises(InputError, match="no faces"):
        transfer_weights(source, weights, Mesh(sleeve().vertices, np.zeros((0, 3))))
    with pytest.raises(InputError, match="no bone weights"):
        transfer_weights(source, Weights(np.zeros_like(weights.matrix), weights.bone_names), sleeve())
    bad = weights.matrix.copy()
    bad[0, 0] = np.nan
    with pytest.raises(InputError, match="NaN"):
        transfer_weights(source, Weights(bad, weights.bone_names), sleeve())


def test_inpainting_reproduces_linear_function_on_a_flat_grid():
    # -L and L M^-1 L both vanish on linear functions in the interior, so a
    # linear field fixed on a band at the boundary is recovered inside.
    mesh = grid(15, 15)
    Q = inpainting_operator(mesh.vertices, mesh.triangles)
    x, y = mesh.vertices[:, 0], mesh.vertices[:, 1]
    field = np.column_stack([x, 1 - x])
    known = (x < 0.15) | (x > 0.85) | (y < 0.15) | (y > 0.85)
    solved = inpaint_weights(Q, known, field)
    np.testing.assert_allclose(solved[~known], field[~known], atol=1e-8)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_huge_and_tiny_scenes_give_the_same_weights(body, scale):
    source, weights = body
    target = sleeve(z0=-0.2, height=1.1, rings=41)
    mask = np.abs(target.vertices[:, 2] - 0.5) < 0.15
    reference = transfer_weights(source, weights, target, inpaint_mask=mask)
    scaled = transfer_weights(Mesh(source.vertices * scale, source.triangles), weights,
                              Mesh(target.vertices * scale, target.triangles), inpaint_mask=mask)
    np.testing.assert_array_equal(scaled.status, reference.status)
    np.testing.assert_allclose(scaled.weights.matrix, reference.weights.matrix, atol=1e-7)


def test_non_manifold_edge_is_handled_and_reported(body):
    source, weights = body
    target = sleeve()
    a, b = target.triangles[0][[0, 2]]  # the quad diagonal: already shared by two triangles
    fin_tip = (target.vertices[a] + target.vertices[b]) / 2 + np.array([0.0, 0.0, 0.02]) + 0.3 * target.vertices[a] * [1, 1, 0]
    fin = Mesh(np.vstack([target.vertices, fin_tip]), np.vstack([target.triangles, [[a, b, target.vertex_count]]]))
    result = transfer_weights(source, weights, fin)
    assert result.non_manifold_edges == 1
    assert "1 non-manifold edges" in result.summary()
    assert np.all(np.isfinite(result.weights.matrix))
    np.testing.assert_allclose(result.weights.matrix.sum(axis=1), 1.0, atol=1e-12)


def test_overlap_check_honours_a_larger_match_distance(body):
    source, weights = body
    # A 0.2 x 0.2 patch facing +x, 0.08 beside the body: outside the default
    # margin (5 % of its 0.28 diagonal) but inside a 50 % one.
    patch = grid(5, 5, size=0.2)
    y, z = patch.vertices[:, 0] - 0.1, patch.vertices[:, 1] + 0.4
    target = Mesh(np.column_stack([np.full(len(y), 0.18), y, z]), patch.triangles)
    with pytest.raises(InputError, match="does not overlap"):
        transfer_weights(source, weights, target)
    result = transfer_weights(source, weights, target, TransferOptions(distance_fraction=0.5))
    assert np.count_nonzero(result.status == VertexStatus.COPIED) > 0
