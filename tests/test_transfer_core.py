"""Robust weight transfer (core/transfer: matching, inpainting, transfer).

The body is a cylinder whose 'upper' weight ramps linearly between rings
z = 0.4 and 0.6; sleeves around it are prisms with vertical facets, so the
closest body point of a sleeve vertex is level with it and the copied
weight is the ramp itself, exactly. Sleeves are symmetric under
(z, angle) -> (1 - z, -angle), which swaps the two bones' weights.
"""

import re

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from autorig_addon.core.errors import InputError
from autorig_addon.core.geometry import sparse_solve
from autorig_addon.core.geometry.laplacian import cotangent_laplacian, voronoi_mass
from autorig_addon.core.geometry.smoothing import smooth_over_surface
from autorig_addon.core.transfer import TransferOptions, TransferSource, VertexStatus, transfer_weights
from autorig_addon.core.transfer.inpainting import inpaint_weights, inpainting_operator
from autorig_addon.core.transfer.matching import closest_point_weights, match_closest_points
from autorig_addon.core.types import Mesh, Weights
from autorig_addon.core.weights import limit_influences
from geometry_fixtures import cylinder, grid, two_bone_weights


@pytest.fixture(scope="module")
def body():
    mesh = cylinder(radius=0.1, segments=32, rings=41)
    return mesh, two_bone_weights(mesh)


#: The copy and inpainting stages alone, whose answers are exact; the surface
#: smoothing that follows them by default has its own tests below.
UNSMOOTHED = TransferOptions(smoothing_length=0.0)


def sleeve(radius=0.11, z0=0.05, height=0.9, flip=False, rings=31):
    return cylinder(radius=radius, height=height, z0=z0, segments=40, rings=rings, capped=False, flip=flip)


def expected_upper(z, blend=0.2):
    return np.clip((z - (0.5 - blend / 2)) / blend, 0, 1)


def test_close_sleeve_copies_the_body_weights(body):
    source, weights = body
    target = sleeve()
    result = transfer_weights(source, weights, target, UNSMOOTHED)
    assert np.all(result.status == VertexStatus.COPIED)
    upper = expected_upper(target.vertices[:, 2])
    np.testing.assert_allclose(result.weights.matrix, np.column_stack([1 - upper, upper]), atol=1e-12)
    assert result.max_distance == pytest.approx(0.05 * target.bounding_box_diagonal, rel=1e-12)
    assert result.summary() == f"{target.vertex_count} copied, 0 inpainted (0%)"
    # Plain closest-point copying gives the same weights here.
    np.testing.assert_allclose(closest_point_weights(source, weights, target).matrix, result.weights.matrix, atol=1e-12)


def test_inner_layer_with_flipped_normals_needs_the_second_pass(body):
    source, weights = body
    target = sleeve(radius=0.095, flip=True)
    result = transfer_weights(source, weights, target, UNSMOOTHED)
    assert np.all(result.status == VertexStatus.COPIED_FLIPPED)
    np.testing.assert_allclose(result.weights.matrix[:, 1], expected_upper(target.vertices[:, 2]), atol=1e-12)
    message = (f"No vertex of 'mesh' lies within {result.max_distance:.4g} of 'mesh' with agreeing normals on "
               f"weighted parts. {target.vertex_count} of its vertices lie that near but their normals differ from "
               "the body's by more than 30 degrees: recalculate the normals (Shift+N), turn on Flipped Normals or "
               "raise the normal angle. To transfer anyway, turn on Allow Poor Match (--allow-poor-match on the "
               "command line).")
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        transfer_weights(source, weights, target, TransferOptions(accept_flipped_normals=False))


def test_masked_band_is_inpainted_smoothly_and_symmetrically(body):
    source, weights = body
    target = sleeve()
    z = target.vertices[:, 2]
    mask = (z > 0.3) & (z < 0.7)
    result = transfer_weights(source, weights, target, UNSMOOTHED, inpaint_mask=mask)
    assert np.all(result.status[mask] == VertexStatus.MASKED)
    assert np.all(result.status[~mask] == VertexStatus.COPIED)
    upper = result.weights.matrix[:, 1]
    levels = np.unique(np.round(z, 9))
    rings = [np.isclose(z, h) for h in levels]
    values = np.array([upper[ring].mean() for ring in rings])
    # Rings stay rings (the sleeve turns onto itself by 1/40 of a circle) and
    # the symmetry makes the middle ring exactly half and half.
    assert max(np.ptp(upper[ring]) for ring in rings) < 1e-12
    np.testing.assert_allclose(values, 1.0 - values[::-1], atol=1e-12)
    assert values[levels == 0.5] == pytest.approx(0.5, abs=1e-12)
    assert np.all(np.diff(values[(levels > 0.3) & (levels < 0.7)]) > 0)  # rising across the band
    np.testing.assert_allclose(upper[~mask], expected_upper(z[~mask]), atol=1e-12)


def test_far_overhang_is_inpainted_from_the_matched_rows(body):
    source, weights = body
    target = sleeve(z0=-0.4, height=1.0, rings=41)  # 0.4 below the body's end
    result = transfer_weights(source, weights, target)
    overhang = target.vertices[:, 2] < -0.1
    assert np.all(result.status[overhang] == VertexStatus.INPAINTED)
    # Q couples vertices two rings apart; every known row that near the
    # overhang has the lower bone alone, so the overhang has it alone too.
    np.testing.assert_array_equal(result.weights.matrix[overhang], [[1.0, 0.0]] * int(overhang.sum()))


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
    mask = np.isclose(V[:, 2], 0.05)
    result = transfer_weights(source, weights, Mesh(V, F), inpaint_mask=mask)
    # Both extra vertices weld onto vertex 0 and the collapsed triangles drop
    # out: the same weights as the sleeve without them.
    plain = transfer_weights(source, weights, target, inpaint_mask=mask[: target.vertex_count])
    assert result.welded_vertices == 2
    np.testing.assert_allclose(result.weights.matrix[: target.vertex_count], plain.weights.matrix, atol=1e-12)
    np.testing.assert_allclose(result.weights.matrix[-2:], plain.weights.matrix[[0, 0]], atol=1e-12)


def test_influence_limit_and_smoothing_keep_rows_normalised(body):
    source, weights = body
    target = sleeve()
    mask = np.abs(target.vertices[:, 2] - 0.5) < 0.2
    result = transfer_weights(source, weights, target, TransferOptions(max_influences=1, smoothing_iterations=5),
                              inpaint_mask=mask)
    unlimited = transfer_weights(source, weights, target, TransferOptions(smoothing_iterations=5), inpaint_mask=mask)
    # One bone per vertex, the largest of the unlimited result.
    np.testing.assert_array_equal(result.weights.matrix, limit_influences(unlimited.weights.matrix, 1))
    assert set(np.unique(result.weights.matrix)) == {0.0, 1.0}
    # Smoothing moves only the inpainted rows.
    plain = transfer_weights(source, weights, target, inpaint_mask=mask)
    np.testing.assert_array_equal(unlimited.weights.matrix[~mask], plain.weights.matrix[~mask])
    assert np.abs(unlimited.weights.matrix[mask] - plain.weights.matrix[mask]).max() > 1e-3


def test_far_apart_or_rescaled_targets_are_refused(body):
    source, weights = body
    target = sleeve()
    moved = Mesh(target.vertices + np.array([5.0, 0, 0]), target.triangles)
    message = ("'mesh' does not overlap the source 'mesh': move the garment onto the body "
               "(or apply the object transforms) before transferring.")
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        transfer_weights(source, weights, moved)
    scaled = Mesh(target.vertices * 100.0, target.triangles)
    ratio = scaled.bounding_box_diagonal / source.bounding_box_diagonal
    assert f"{ratio:.3g}" == "91.6"
    message = ("The target 'mesh' is 91.6 times larger than the source 'mesh': they look like they are at "
               "different scales. 'mesh' looks 100 times too large for 'mesh' (centimetres and metres mixed up?): "
               "scaled by 1/100, 100% of it would match the body. Fix the units or the object scale, then apply "
               "it (Ctrl+A).")
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        transfer_weights(source, weights, scaled)


def test_unusable_inputs_are_refused_with_their_message(body):
    source, weights = body
    target = sleeve()
    zero = Weights(np.zeros_like(weights.matrix), weights.bone_names)
    n = target.vertex_count
    cases = [
        ((source, weights, Mesh(target.vertices, np.zeros((0, 3)))), {},
         "The target 'mesh' has no faces; it needs a surface to inpaint over."),
        ((Mesh(source.vertices, np.zeros((0, 3))), weights, target), {},
         "The source 'mesh' has no faces; weights are transferred from a surface."),
        ((source, zero, target), {}, "The source 'mesh' carries no bone weights to transfer."),
        ((source, Weights(weights.matrix[:-1], weights.bone_names), target), {},
         "The source weights do not have one row per source vertex."),
        ((source, weights, target, TransferOptions(max_normal_angle=0.0)), {},
         "The normal angle must lie in (0, 180] degrees."),
        ((source, weights, target, TransferOptions(distance_fraction=0.0)), {}, "The match distance must be positive."),
        ((source, weights, target, TransferOptions(max_distance=-1.0)), {}, "The match distance must be positive."),
        ((source, weights, target, TransferOptions(smoothing_strength=2.0)), {},
         "Smoothing strength must lie in [0, 1]."),
        ((source, weights, target), {"inpaint_mask": np.zeros(3, bool)},
         f"The inpaint mask has 3 entries for {n} target vertices."),
        ((source, weights, target), {"protected": np.ones(n, bool)},
         "Protected vertices were given without their weights."),
    ]
    for arguments, keywords, message in cases:
        with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
            transfer_weights(*arguments, **keywords)
    corrupt = Weights(np.full_like(weights.matrix, np.nan), weights.bone_names)
    message = (f"The source 'mesh' has no usable weights: {source.vertex_count} of its {source.vertex_count} "
               "vertices have NaN, infinite or negative weights and the others none. Clean the weights "
               "(Weights > Clean) or skin the body again.")
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        transfer_weights(source, corrupt, target)


def test_a_source_prepared_once_serves_many_targets_with_the_same_weights(body):
    source, two_bones = body
    # A third bone that weighs nothing on the body stays an empty column.
    weights = Weights(np.column_stack([two_bones.matrix, np.zeros(source.vertex_count)]), ["lower", "upper", "unused"])
    prepared_body = TransferSource.prepare(source, weights)
    for target in (sleeve(), sleeve(z0=-0.4, height=1.0, rings=41)):
        alone = transfer_weights(source, weights, target)
        reused = transfer_weights(source, weights, target, prepared=prepared_body)
        np.testing.assert_array_equal(reused.weights.matrix, alone.weights.matrix)
        np.testing.assert_array_equal(reused.status, alone.status)
        assert reused.weights.bone_names == ("lower", "upper", "unused")
        np.testing.assert_array_equal(reused.weights.matrix[:, 2], 0.0)
        np.testing.assert_allclose(reused.weights.matrix.sum(axis=1), 1.0, atol=1e-12)
    other = Weights(weights.matrix.copy(), weights.bone_names)
    with pytest.raises(ValueError, match="another mesh or weights"):
        transfer_weights(source, other, sleeve(), prepared=prepared_body)


def test_inpainting_reproduces_linear_function_on_a_flat_grid():
    # -L and L M^-1 L both vanish on linear functions in the interior, so a
    # linear field fixed on a band at the boundary is recovered inside.
    mesh = grid(15, 15)
    Q = inpainting_operator(mesh.vertices, mesh.triangles)
    # Symmetric, constants in its null space, positive semi-definite.
    assert abs(Q - Q.T).max() < 1e-9 * abs(Q).max()
    np.testing.assert_allclose(Q @ np.ones(mesh.vertex_count), 0.0, atol=1e-9 * abs(Q).max())
    assert np.linalg.eigvalsh(Q.toarray()).min() > -1e-9 * abs(Q).max()
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
    fin_tip = ((target.vertices[a] + target.vertices[b]) / 2 + np.array([0.0, 0.0, 0.02])
               + 0.3 * target.vertices[a] * [1, 1, 0])
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
    result = transfer_weights(source, weights, target, TransferOptions(distance_fraction=0.5, smoothing_length=0.0))
    # Rows |y| <= 0.05 see the body within 16 degrees of +x and copy it; at
    # |y| = 0.1 the body's normal there is 29 degrees off, and more than 30
    # once interpolated across the 32-gon's facets, so those are inpainted.
    near = np.abs(y) <= 0.05 + 1e-9
    np.testing.assert_array_equal(result.status, np.where(near, VertexStatus.COPIED, VertexStatus.INPAINTED))
    np.testing.assert_allclose(result.weights.matrix[near, 1], expected_upper(z[near]), atol=1e-12)


def prepared(mesh, matrix):
    return TransferSource.prepare(mesh, Weights(matrix, [f"bone{i}" for i in range(matrix.shape[1])]))


def test_matching_copies_near_points_and_flags_opposite_normals():
    # A unit square at z = 0 facing +z, weights ramping along x; targets above and below it.
    square = grid(2, 2)
    source_weights = np.column_stack([1 - square.vertices[:, 0], square.vertices[:, 0]])
    target = Mesh([[0.25, 0.5, 0.1], [0.75, 0.5, -0.1], [0.5, 0.5, 0.3], [0.5, 0.5, 0.1]], [[0, 1, 2]])
    normals = np.array([[0, 0, 1.0], [0, 0, -1.0], [0, 0, 1.0], [np.sin(0.6), 0, np.cos(0.6)]])  # last: 34 degrees off
    matches = match_closest_points(prepared(square, source_weights), target, normals, 0.2, 30.0, True)
    np.testing.assert_allclose(matches.weights, [[0.75, 0.25], [0.25, 0.75], [0.5, 0.5], [0.5, 0.5]], atol=1e-12)
    np.testing.assert_allclose(matches.distances, [0.1, 0.1, 0.3, 0.1], atol=1e-12)
    np.testing.assert_array_equal(matches.matched, [True, True, False, False])  # too far; normal too far off
    np.testing.assert_array_equal(matches.flipped, [False, True, False, False])
    strict = match_closest_points(prepared(square, source_weights), target, normals, 0.2, 30.0, False)
    np.testing.assert_array_equal(strict.matched, [True, False, False, False])
    assert not strict.flipped.any()


# --------------------------------------------------------------------------- bad source weights and poor matches


def body_painted_below(body, z_limit, value):
    """The body's weights with every vertex above ``z_limit`` set to
    ``value`` (0: never painted; NaN, inf or negative: corrupt), as an
    artist leaving the top of the body unpainted would."""
    source, weights = body
    matrix = weights.matrix.copy()
    matrix[source.vertices[:, 2] > z_limit, 0] = value
    if value == 0.0:
        matrix[source.vertices[:, 2] > z_limit] = 0.0
    return Weights(matrix, weights.bone_names)


@pytest.mark.parametrize("value", [0.0, np.nan, np.inf, -1.0])
def test_unweighted_or_corrupt_body_rows_never_count_as_a_match(body, value):
    source, _ = body
    painted = body_painted_below(body, 0.71, value)  # body rings from z = 0.725 up carry no usable weight
    target = sleeve()  # rings every 0.03 from z = 0.05
    result = transfer_weights(source, painted, target, UNSMOOTHED)
    z = target.vertices[:, 2]
    over_unweighted = z > 0.7  # their closest points lie on (or draw from) the rings above 0.71
    np.testing.assert_array_equal(result.status, np.where(over_unweighted, VertexStatus.INPAINTED, VertexStatus.COPIED))
    # Inpainted from the copied rings below, which all have the upper bone alone.
    np.testing.assert_allclose(result.weights.matrix[over_unweighted], [[0.0, 1.0]] * int(over_unweighted.sum()),
                               atol=1e-12)
    upper = expected_upper(z[~over_unweighted])
    np.testing.assert_allclose(result.weights.matrix[~over_unweighted], np.column_stack([1 - upper, upper]), atol=1e-12)
    unusable = int(np.count_nonzero(source.vertices[:, 2] > 0.71))
    assert (result.unweighted_source_vertices, result.near_unweighted) == (unusable, int(over_unweighted.sum()))
    corrupt = "" if value == 0.0 else f" ({unusable} with NaN, infinite or negative weights)"
    copied, inpainted = target.vertex_count - int(over_unweighted.sum()), int(over_unweighted.sum())
    assert (copied, inpainted) == (880, 360)
    assert result.summary() == (
        f"880 copied, 360 inpainted (29%), {unusable} vertices of 'mesh' have no "
        f"usable weight{corrupt}; {int(over_unweighted.sum())} vertices near them were inpainted")


def test_a_garment_mostly_over_an_unpainted_body_is_refused_unless_allowed(body):
    source, _ = body
    painted = body_painted_below(body, 0.11, 0.0)  # only the bottom of the body was painted
    target = sleeve()
    copied = int(np.count_nonzero(target.vertices[:, 2] < 0.1))
    assert (copied, target.vertex_count) == (80, 1240)
    distance = 0.05 * target.bounding_box_diagonal
    message = (f"Only 6% of 'mesh' (80 of 1240 vertices) lies within {distance:.3g} of 'mesh' with "
               "agreeing normals on weighted parts; the rest would be guessed by inpainting. "
               f"{target.vertex_count - copied} of its vertices lie over parts of 'mesh' without usable weights: "
               "weight those parts of the body first. To transfer anyway, turn on Allow Poor Match "
               "(--allow-poor-match on the command line).")
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        transfer_weights(source, painted, target)
    result = transfer_weights(source, painted, target, TransferOptions(allow_poor_match=True))
    np.testing.assert_allclose(result.weights.matrix, [[1.0, 0.0]] * target.vertex_count, atol=1e-12)
    only_above = body_painted_below(body, -1.0, 0.0)
    with pytest.raises(InputError, match="^The source 'mesh' carries no bone weights to transfer.$"):
        transfer_weights(source, only_above, target)


@pytest.mark.parametrize("factor, pivot, words", [
    (2.54, "origin", "looks 2.54 times too large for 'Body' (inches and centimetres mixed up?): scaled by 1/2.54"),
    (1 / 2.54, "origin", "looks 2.54 times too small for 'Body' (inches and centimetres mixed up?): scaled by 2.54"),
    (2.54, "centre", "looks 2.54 times too large for 'Body' (inches and centimetres mixed up?): scaled by 1/2.54"),
    (1 / 100, "centre", "looks 100 times too small for 'Body' (centimetres and metres mixed up?): scaled by 100"),
])
def test_a_garment_at_another_unit_scale_is_refused_naming_the_factor(body, factor, pivot, words):
    source, weights = body
    source = Mesh(source.vertices, source.triangles, object_names=("Body",))
    garment = sleeve()
    centre = np.zeros(3) if pivot == "origin" else 0.5 * (garment.vertices.min(0) + garment.vertices.max(0))
    scaled = Mesh(centre + factor * (garment.vertices - centre), garment.triangles, object_names=("Sleeve",))
    with pytest.raises(InputError, match=re.escape(f"'Sleeve' {words}, 100% of it would match the body.")):
        transfer_weights(source, weights, scaled)


def test_a_garment_crossing_the_body_at_2_54_times_its_scale_is_refused_unless_allowed():
    # A body with broad shoulders (a wide cylinder from z = 2 to 2.54 above a
    # thin one) and a sleeve for its thin part modelled in inches: at 2.54
    # times its size the sleeve still meets the shoulders, so a fifth of it
    # copies weights there, and the rest would be guessed.
    thin, broad = cylinder(radius=0.1, height=1.0, rings=41), cylinder(radius=0.254, height=0.54, z0=2.0, rings=23)
    body = Mesh.concatenate([thin, broad])
    body = Mesh(body.vertices, body.triangles, object_names=("Body",))
    upper = (body.vertices[:, 2] > 1.5).astype(float)
    weights = Weights(np.column_stack([1 - upper, upper]), ("lower", "upper"))
    garment = sleeve()
    inches = Mesh(2.54 * garment.vertices, garment.triangles, object_names=("Sleeve",))
    with pytest.raises(InputError) as refused:
        transfer_weights(body, weights, inches)
    message = str(refused.value)
    assert re.match(r"^Only 1\d% of 'Sleeve' \(\d+ of 1240 vertices\) lies within ", message), message
    assert ("'Sleeve' looks 2.54 times too large for 'Body' (inches and centimetres mixed up?): scaled by 1/2.54, "
            "100% of it would match the body. Fix the units or the object scale, then apply it (Ctrl+A). "
            "To transfer anyway, turn on Allow Poor Match (--allow-poor-match on the command line).") in message
    allowed = transfer_weights(body, weights, inches, TransferOptions(allow_poor_match=True))
    np.testing.assert_allclose(allowed.weights.matrix.sum(axis=1), 1.0, atol=1e-12)
    fitted = transfer_weights(body, weights, Mesh(garment.vertices, garment.triangles))
    assert np.all(fitted.status == VertexStatus.COPIED)


def test_a_garment_matched_far_away_after_raising_the_distance_is_refused(body):
    source, weights = body
    target = sleeve()
    far = Mesh(target.vertices + [100.0, 0.0, 0.0], target.triangles, object_names=("Sleeve",))
    with pytest.raises(InputError) as refused:
        transfer_weights(source, weights, far, TransferOptions(max_distance=200.0))
    median = float(np.median(np.linalg.norm(far.vertices[:, :2], axis=1) - 0.1))
    assert str(refused.value).startswith(
        f"'Sleeve' would copy weights from points of 'mesh' {median:.3g} away (median), ")
    assert ": it is not on the body (match distance 200). Move it onto the body or lower the match distance. " \
           "To transfer anyway" in str(refused.value)


def test_an_infinite_vertex_is_named_not_reported_as_a_scale(body):
    source, weights = body
    target = sleeve()
    vertices = target.vertices.copy()
    vertices[7] = [np.finfo(np.float32).max, 0.0, 0.0]  # how Blender stores a vertex moved to infinity
    with pytest.raises(InputError, match=r"^'Sleeve' has a vertex at an infinite or undefined \(NaN\) position "
                                         r"\(index 7\)"):
        transfer_weights(source, weights, Mesh(vertices, target.triangles, object_names=("Sleeve",)))


def test_protected_vertices_with_nothing_to_keep_are_transferred_not_left_empty(body):
    source, weights = body
    target = sleeve()
    top = target.vertices[:, 2] > 0.9
    existing = np.zeros((target.vertex_count, 2))
    existing[top & (target.vertices[:, 0] > 0)] = [0.25, 0.75]  # half the protected ring was painted
    result = transfer_weights(source, weights, target, UNSMOOTHED, protected=top,
                              protected_weights=Weights(existing, ("upper", "lower")))
    kept = top & (target.vertices[:, 0] > 0)
    np.testing.assert_allclose(result.weights.matrix[kept], [[0.75, 0.25]] * int(kept.sum()), atol=1e-12)
    np.testing.assert_allclose(result.weights.matrix[top & ~kept], [[0.0, 1.0]] * int((top & ~kept).sum()), atol=1e-12)
    assert result.unprotected == int((top & ~kept).sum())
    assert f"{result.unprotected} protected vertices had no weight to keep and were transferred" in result.summary()


def test_matching_falls_back_to_the_nearest_weighted_vertex_where_the_closest_point_has_none():
    square = grid(3, 3)  # vertices at x, y in {0, 0.5, 1}
    source_weights = np.column_stack([1 - square.vertices[:, 0], square.vertices[:, 0]])
    source_weights[square.vertices[:, 0] > 0.9] = np.nan  # the x = 1 column is corrupt
    target = Mesh([[0.25, 0.5, 0.05], [0.9, 0.5, 0.05], [0.5, 0.4, 0.05]], [[0, 1, 2]])
    normals = np.tile([0.0, 0.0, 1.0], (3, 1))
    matches = match_closest_points(prepared(square, source_weights), target, normals, 0.2, 30.0, True)
    np.testing.assert_array_equal(matches.matched, [True, False, True])
    np.testing.assert_array_equal(matches.unweighted, [False, True, False])
    # Vertex 1 draws on the corrupt column: it takes the nearest usable vertex's (x = 0.5) weights.
    np.testing.assert_allclose(matches.weights, [[0.75, 0.25], [0.5, 0.5], [0.5, 0.5]], atol=1e-12)


# --------------------------------------------------------------------------- surface smoothing (stage 3)


def test_surface_smoothing_of_a_spike_on_a_unit_square_by_hand():
    # grid(2, 2) is the unit square cut along 0-3: vertices 1 and 2 hold the
    # right angles, so the sides carry cotangent weight 1/2, the diagonal 0
    # (cot 90 degrees), and every vertex has Voronoi mass 1/4. With length 1,
    # (M - L) x = M x0 for a spike x0 = e_0 reads, by symmetry x1 = x2 = b:
    #   a/4 + 2 (a - b)/2 = 1/4,  b/4 + (b - a)/2 + (b - c)/2 = 0,  c/4 + 2 (c - b)/2 = 0,
    # so a = 17/45, b = 2/9, c = 8/45: the spike spreads, its mass sum(M x) = 1/4 is kept.
    square = grid(2, 2)
    spike = np.array([[1.0], [0.0], [0.0], [0.0]])
    smoothed = smooth_over_surface(spike, square.vertices, square.triangles, 1.0)
    np.testing.assert_allclose(smoothed.ravel(), [17 / 45, 2 / 9, 2 / 9, 8 / 45], atol=1e-12)
    # Lengths are relative to the mesh: three times the square, three times the length.
    np.testing.assert_allclose(smooth_over_surface(spike, 3 * square.vertices, square.triangles, 3.0), smoothed,
                               atol=1e-12)
    # Fixed rows keep their values and hold their neighbours: with 1 and 2 at
    # zero, vertex 0 solves a/4 + a/2 + a/2 = 1/4 (a = 1/5), and so does 3.
    fixed = np.array([False, True, True, False])
    held = smooth_over_surface(np.array([[1.0], [0.0], [0.0], [1.0]]), square.vertices, square.triangles, 1.0, fixed)
    np.testing.assert_allclose(held.ravel(), [0.2, 0.0, 0.0, 0.2], atol=1e-12)
    # Length 0 is off; the input is never modified.
    np.testing.assert_array_equal(smooth_over_surface(spike, square.vertices, square.triangles, 0.0), spike)
    np.testing.assert_array_equal(spike.ravel(), [1, 0, 0, 0])


def test_surface_smoothing_keeps_constants_and_leaves_loose_vertices_alone():
    square = grid(3, 3)
    loose = Mesh(np.vstack([square.vertices, [[5.0, 5.0, 5.0]]]), square.triangles)  # vertex 9 is in no triangle
    rows = np.column_stack([np.full(10, 0.3), np.full(10, 0.7)])
    rows[9] = [1.0, 0.0]
    smoothed = smooth_over_surface(rows, loose.vertices, loose.triangles, 0.5)
    np.testing.assert_allclose(smoothed[:9], [[0.3, 0.7]] * 9, atol=1e-12)
    np.testing.assert_array_equal(smoothed[9], [1.0, 0.0])


def test_default_transfer_smooths_the_copied_ramp_keeping_symmetry_and_mass(body):
    source, weights = body
    target = sleeve()
    plain = transfer_weights(source, weights, target, UNSMOOTHED).weights.matrix
    length = 0.05  # of the body's 1.04 diagonal: 5 cm, beside the sleeve's 3 cm rings
    smoothed = transfer_weights(source, weights, target, TransferOptions(smoothing_length=length)).weights.matrix
    z = target.vertices[:, 2]
    np.testing.assert_allclose(smoothed.sum(axis=1), 1.0, atol=1e-12)
    # Heat is conserved: every bone's area-weighted total over the sleeve stays.
    mass = voronoi_mass(target.vertices, target.triangles)
    np.testing.assert_allclose(mass @ smoothed, mass @ plain, rtol=1e-9)  # to the solver's tolerance
    # The sleeve's symmetry (z -> 1 - z swaps the bones) survives: rings stay
    # rings and the middle ring is half and half.
    upper = smoothed[:, 1]
    levels = np.unique(np.round(z, 9))
    values = np.array([upper[np.isclose(z, h)].mean() for h in levels])
    assert max(np.ptp(upper[np.isclose(z, h)]) for h in levels) < 1e-9
    np.testing.assert_allclose(values, 1.0 - values[::-1], atol=1e-9)
    assert values[levels == 0.5] == pytest.approx(0.5, abs=1e-9)
    # The ramp's kinks at z = 0.4 and 0.6 are rounded (the ring beside each
    # moves by 0.1) and the change fades away from them at a known rate. The
    # sleeve is intrinsically a flat grid of h x s rectangles cut into right
    # triangles, on which the cotangent Laplacian is the five-point stencil
    # (weights s/h along z, h/s around, 0 on the diagonals) and every vertex
    # has mass h s. Where the copy is constant the change d_k of ring k thus
    # solves d_{k+1} - 2 d_k + d_{k-1} = (h / length)^2 d_k: it shrinks by
    # the root r < 1 of r + 1/r = 2 + (h / length)^2 per ring away from a kink.
    change = values - expected_upper(levels)
    assert change[np.isclose(levels, 0.41)] == pytest.approx(0.103, abs=1e-3)
    h, reach = 0.03, length * source.bounding_box_diagonal
    ratio = 1 + (h / reach) ** 2 / 2 - np.sqrt((1 + (h / reach) ** 2 / 2) ** 2 - 1)
    below = (levels > 0.19) & (levels < 0.36)  # rings 0.20 to 0.35: constant copy, 5 rings above the open end
    np.testing.assert_allclose(change[below][:-1] / change[below][1:], ratio, rtol=3e-3)
    assert ratio == pytest.approx(0.566, abs=1e-3)
    assert np.all(np.diff(values) >= -1e-12)  # still rising


def test_surface_smoothing_keeps_protected_rows_and_its_length_is_bounded(body):
    source, weights = body
    target = sleeve()
    top = target.vertices[:, 2] > 0.9
    existing = np.zeros((target.vertex_count, 2))
    existing[top] = [0.25, 0.75]
    result = transfer_weights(source, weights, target, TransferOptions(smoothing_length=0.05), protected=top,
                              protected_weights=Weights(existing, ("upper", "lower")))
    np.testing.assert_allclose(result.weights.matrix[top], [[0.75, 0.25]] * int(top.sum()), atol=1e-12)
    assert set(result.timings) >= {"inpaint", "smooth"}
    panel_maximum = float(np.float32(0.05))  # what the panel's slider at its end passes: 0.0500000007
    widest = transfer_weights(source, weights, target, TransferOptions(smoothing_length=panel_maximum))
    np.testing.assert_allclose(widest.weights.matrix.sum(axis=1), 1.0, atol=1e-12)
    message = "The smoothing length must lie in [0, 0.05] (a fraction of the source's size)."
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        transfer_weights(source, weights, target, TransferOptions(smoothing_length=0.06))


@pytest.mark.parametrize("iterations, drop, falls_back",
                         [(sparse_solve.MAX_ITERATIONS, sparse_solve.DROP_TOLERANCE, False),
                                                          (0, 0.5, True)])
def test_positive_definite_solve_agrees_with_a_complete_factorisation(monkeypatch, iterations, drop, falls_back):
    # The smoothing system of a 30 x 30 grid, 40 right-hand sides (one all
    # zero), solved as a big system would be. With a crude preconditioner and
    # no iteration allowed, the complete factorisation answers instead.
    monkeypatch.setattr(sparse_solve, "COMPLETE_FACTORISATION_LIMIT", 0)
    monkeypatch.setattr(sparse_solve, "MAX_ITERATIONS", iterations)
    monkeypatch.setattr(sparse_solve, "DROP_TOLERANCE", drop)
    complete = []
    monkeypatch.setattr(sparse_solve, "splu", lambda *args, **kwargs: complete.append(1) or splu(*args, **kwargs))
    square = grid(30, 30)
    system = (sp.diags(voronoi_mass(square.vertices, square.triangles))
              - 0.01 * cotangent_laplacian(square.vertices, square.triangles)).tocsc()
    rhs = np.random.default_rng(0).random((900, 40))
    rhs[:, 7] = 0.0
    solved = sparse_solve.solve_positive_definite(system, rhs)
    assert bool(complete) == falls_back
    exact = splu(system).solve(rhs)
    np.testing.assert_allclose(solved, exact, rtol=0, atol=1e-9 * np.abs(exact).max())
    assert np.all(solved[:, 7] == 0.0)
    residual = np.linalg.norm(system @ solved - rhs, axis=0)
    assert np.all(residual <= sparse_solve.RELATIVE_TOLERANCE * np.linalg.norm(rhs, axis=0))


def test_a_target_lying_nine_tenths_on_one_bone_is_bound_wholly_to_it(body):
    # A band around the upper bone reaching down into the blend (z 0.55 to 0.95; 'upper' rises from 0.4 to 0.6):
    # its lowest rows carry some 'lower', a tenth of its weight at most.
    source, weights = body
    band = sleeve(z0=0.55, height=0.4, rings=9)
    blended = transfer_weights(source, weights, band, TransferOptions(rigid_accessory=False))
    lower = blended.weights.matrix[:, 0]
    assert lower.max() > 0.1 and blended.rigid_bone == ""
    result = transfer_weights(source, weights, band)
    np.testing.assert_array_equal(result.weights.matrix, [[0.0, 1.0]] * band.vertex_count)
    assert result.rigid_bone == "upper"
    assert result.summary().endswith("bound wholly to bone 'upper' (a rigid accessory: 90% or more of its weight "
                                     "lay there)")
    # Protected rows keep their own weights and are not judged: the lower half of the band kept wholly on 'lower'
    # would pull 'upper' far under 0.9 if it counted; the rest is bound.
    bottom = band.vertices[:, 2] < 0.75
    kept = Weights(np.column_stack([np.ones(band.vertex_count), np.zeros(band.vertex_count)]), ("lower", "upper"))
    guarded = transfer_weights(source, weights, band, protected=bottom, protected_weights=kept)
    assert guarded.rigid_bone == "upper"
    np.testing.assert_array_equal(guarded.weights.matrix[bottom], [[1.0, 0.0]] * int(bottom.sum()))
    np.testing.assert_array_equal(guarded.weights.matrix[~bottom], [[0.0, 1.0]] * int((~bottom).sum()))


def test_a_target_nine_tenths_on_one_bone_that_touches_the_body_across_the_joint_keeps_its_blend(body):
    # A band from z 0.48 to 0.95: 'upper' holds about 0.92 of its weight, but its rows copied below z 0.5 lie mostly
    # on 'lower' (a head of its own with its neck: it reaches across the joint and must bend there).
    source, weights = body
    band = sleeve(z0=0.48, height=0.47, rings=11)
    result = transfer_weights(source, weights, band)
    assert result.rigid_bone == ""
    below = band.vertices[:, 2] < 0.5
    assert np.all(result.weights.matrix[below, 0] > 0.5)
    share = np.average(result.weights.matrix[:, 1], weights=voronoi_mass(band.vertices, band.triangles))
    assert share > 0.9
    # Only where it is copied from the body does the body tell: with those rows inpainted instead (a hat's brim
    # standing off the neck), nothing copied lies on 'lower', and the band is bound.
    brim = transfer_weights(source, weights, band, inpaint_mask=below)
    assert brim.rigid_bone == "upper"
    np.testing.assert_array_equal(brim.weights.matrix, [[0.0, 1.0]] * band.vertex_count)


def test_a_target_wholly_on_one_bone_already_is_left_as_it_is_without_a_note(body):
    source, weights = body
    cuff = sleeve(z0=0.75, height=0.2, rings=5)
    result = transfer_weights(source, weights, cuff)
    np.testing.assert_array_equal(result.weights.matrix, [[0.0, 1.0]] * cuff.vertex_count)
    assert result.rigid_bone == "" and "rigid" not in result.summary()


def test_a_target_spanning_the_joint_keeps_its_blend(body):
    # A sleeve over both bones (z 0.3 to 0.7): half its weight on each, nothing bound.
    source, weights = body
    target = sleeve(z0=0.3, height=0.4, rings=13)
    result = transfer_weights(source, weights, target)
    assert result.rigid_bone == ""
    np.testing.assert_allclose(result.weights.matrix, transfer_weights(
        source, weights, target, TransferOptions(rigid_accessory=False)).weights.matrix, atol=0)
    assert 0.3 < result.weights.matrix[:, 1].mean() < 0.7
