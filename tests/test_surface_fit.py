"""A known body fitted onto a character (autorig_addon.core.rigging.surface_fit):
the bounding boxes' map, refined on the two surfaces where a part one body
lacks moves a side of its box."""

import numpy as np

from autorig_addon.core.evaluation.skeleton_metrics import symmetric_chamfer
from autorig_addon.core.geometry.bounding_box import bounding_box
from autorig_addon.core.rigging.nearest_character import SURFACE_POINTS, surface_points
from autorig_addon.core.rigging.rig_library import build_rig_library, closest_rig, fitted_rig
from autorig_addon.core.rigging.surface_fit import MIN_GAIN, AxisMap, box_axis_map, fitted_axis_map
from autorig_addon.core.skeleton.key_joints import KEY_JOINTS
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh, procedural_of_kind


def four_legged_box(tail_to: float | None = None) -> Mesh:
    """A trunk along y (its head end at -y, a head box in front), four legs
    and, when ``tail_to`` is given, a thin tail from the trunk's back end to
    y = ``tail_to``."""
    parts = [box_mesh([-0.15, -0.5, 0.35], [0.15, 0.5, 0.65], 0.05),  # trunk
             box_mesh([-0.1, -0.75, 0.55], [0.1, -0.5, 0.8], 0.05)]  # head
    for x in (-0.12, 0.08):
        for y in (-0.45, 0.35):
            parts.append(box_mesh([x, y, 0.0], [x + 0.04, y + 0.1, 0.35], 0.05))
    if tail_to is not None:
        parts.append(box_mesh([-0.02, 0.5, 0.6], [0.02, tail_to, 0.64], 0.05))
    return Mesh.concatenate(parts)


def bounds(mesh: Mesh) -> np.ndarray:
    return bounding_box(mesh.vertices)


def points_on(mesh: Mesh) -> np.ndarray:
    return surface_points(mesh.vertices, mesh.triangles, SURFACE_POINTS)


def test_a_known_body_with_a_tail_the_character_lacks_is_fitted_by_its_surface():
    # A tail 0.15 long (an eighth of the body's length); a tail 0.45 long still pulls the fit 0.06 (least
    # squares pair its points with the trunk's back end).
    known, character = four_legged_box(tail_to=0.65), four_legged_box()
    # Joints of the known body: a hind hip, a front knee, the head; the character has them in the same places.
    joints = np.array([[0.1, 0.4, 0.4], [-0.1, -0.4, 0.2], [0.0, -0.6, 0.7]])
    by_boxes = box_axis_map(bounds(known), bounds(character))(joints)
    fitted = fitted_axis_map(points_on(known), bounds(known), points_on(character), bounds(character))
    # The boxes' map squeezes the body's length by the tail (y: [-0.75, 0.65] onto [-0.75, 0.5]) ...
    assert np.abs(by_boxes - joints).max() > 0.1
    # ... the surfaces put every joint back within a hundredth of the body's length.
    np.testing.assert_allclose(fitted(joints), joints, atol=0.01)
    np.testing.assert_allclose(fitted.scale, 1.0, atol=0.02)
    # And it did so because the surfaces came closer by far more than MIN_GAIN.
    by_boxes_map = box_axis_map(bounds(known), bounds(character))
    gap_by_boxes = symmetric_chamfer(points_on(character), by_boxes_map(points_on(known)))
    assert symmetric_chamfer(points_on(character), fitted(points_on(known))) < (1.0 - MIN_GAIN) * gap_by_boxes


def test_a_body_stretched_along_each_axis_keeps_the_boxes_map():
    known = four_legged_box()
    factors = np.array([1.2, 0.9, 1.1])
    character = Mesh(known.vertices * factors, known.triangles)
    fitted = fitted_axis_map(points_on(known), bounds(known), points_on(character), bounds(character))
    # The boxes' map is already exact; refining would only drift, so it is kept as it is.
    by_boxes = box_axis_map(bounds(known), bounds(character))
    np.testing.assert_array_equal(fitted.scale, by_boxes.scale)
    np.testing.assert_array_equal(fitted.shift, by_boxes.shift)
    np.testing.assert_allclose(fitted.scale, factors, atol=1e-12)
    # A stub of a tail 0.01 long moves the box a hair: refined, the surfaces come 4.7 % closer, under MIN_GAIN.
    assert MIN_GAIN == 0.05
    stub = four_legged_box(tail_to=0.51)
    kept = fitted_axis_map(points_on(stub), bounds(stub), points_on(known), bounds(known))
    np.testing.assert_array_equal(kept.scale, box_axis_map(bounds(stub), bounds(known)).scale)


def test_the_boxes_map_by_hand_and_a_flat_axis_only_shifted():
    mapped = box_axis_map([[0.0, 0.0, 0.0], [1.0, 2.0, 0.0]], [[1.0, 0.0, -1.0], [3.0, 1.0, 0.0]])
    assert isinstance(mapped, AxisMap)
    # x: [0, 1] -> [1, 3]; y: [0, 2] -> [0, 1]; z flat: shifted from centre 0 to centre -0.5.
    np.testing.assert_allclose(mapped([[0.5, 1.0, 0.0], [1.0, 0.0, 0.2]]), [[2.0, 0.5, -0.5], [3.0, 0.0, -0.3]])
    # A flat known body (a sheet at z = 0) fitted onto the same sheet raised 0.2: only shifted along z.
    sheet = np.stack(np.meshgrid(np.linspace(0.0, 1.0, 21), np.linspace(0.0, 1.0, 21)), axis=-1).reshape(-1, 2)
    flat = np.column_stack([sheet, np.zeros(len(sheet))])
    raised = flat + [0.0, 0.0, 0.2]
    fitted = fitted_axis_map(flat, bounding_box(flat), raised, bounding_box(raised))
    np.testing.assert_allclose(fitted(flat), raised, atol=1e-12)
    assert fitted.scale[2] == 1.0


def test_a_relative_with_a_thin_aerial_takes_the_key_joints_where_its_surface_says():
    """The library's biped copied onto the same body under a thin aerial on
    its head, which raises the top of its box by a tenth: the boxes' map
    would lift every key joint with it."""
    sample, _ = procedural_of_kind("biped")
    library = build_rig_library([sample])
    top = sample.vertices[:, 2].max()
    head = sample.vertices[sample.vertices[:, 2] > top - 0.02].mean(axis=0)
    aerial = box_mesh([head[0] - 0.004, head[1] - 0.004, top - 0.01], [head[0] + 0.004, head[1] + 0.004, 1.1 * top],
                      0.01)
    character = Mesh.concatenate([Mesh(sample.vertices, sample.triangles), aerial])
    match = closest_rig(character, "biped", library)
    assert match is not None and match.name == sample.name
    targets = dict(zip(KEY_JOINTS, library.key_joints[0].astype(np.float64)))
    lifted = box_axis_map(library.boxes[0], bounds(character))
    assert max(abs(lifted(targets[name])[2] - targets[name][2]) for name in match.points) > 0.08
    for name, point in match.points.items():
        np.testing.assert_allclose(point, targets[name], atol=0.005, err_msg=name)
    # The whole rig goes the same way, whether the map is fitted again or the key joints' one is passed on.
    rows = library.rig_rows(0)
    for axis_map in (None, match.axis_map):
        rig = fitted_rig(match.name, match.distance, character, library, axis_map=axis_map)
        np.testing.assert_allclose(rig.skeleton.joints, library.rig_joints[rows], atol=0.005)
