"""Generalised winding numbers (autorig_addon.core.geometry.winding): known answers on boxes, closed and open."""

import numpy as np
import pytest

from autorig_addon.core.geometry.winding import PAIRS_PER_CHUNK, winding_numbers
from geometry_fixtures import box_mesh


def open_box(missing_face_normal_axis: int = 2):
    """The unit cube, outward wound, without its top face (the one at the axis' upper bound)."""
    box = box_mesh((0, 0, 0), (1, 1, 1), 0.25)
    top = (box.vertices[box.triangles][:, :, missing_face_normal_axis] > 0.999).all(axis=1)
    return box.vertices, box.triangles[~top]


def test_a_closed_box_winds_once_around_its_inside_and_not_around_its_outside():
    box = box_mesh((0, 0, 0), (1, 1, 1), 0.25)
    points = np.array([[0.5, 0.5, 0.5], [0.9, 0.1, 0.2], [2.0, 0.5, 0.5], [-0.1, 0.5, 0.5], [0.5, 0.5, 7.0]])
    np.testing.assert_allclose(winding_numbers(points, box.vertices, box.triangles), [1, 1, 0, 0, 0], atol=1e-9)
    # Wound inward, the same box gives -1 inside.
    np.testing.assert_allclose(winding_numbers(points[:1], box.vertices, box.triangles[:, ::-1]), [-1], atol=1e-9)


def test_a_box_without_its_top_still_winds_five_sixths_around_its_centre():
    """Each face of a cube subtends a sixth of the sphere at its centre: without one, 5/6."""
    vertices, triangles = open_box()
    centre, outside = np.array([[0.5, 0.5, 0.5]]), np.array([[0.5, 0.5, 3.0]])
    assert winding_numbers(centre, vertices, triangles)[0] == pytest.approx(5 / 6, abs=1e-9)
    assert abs(winding_numbers(outside, vertices, triangles)[0]) < 0.05


def test_many_points_are_measured_in_chunks_with_the_same_answer():
    vertices, triangles = open_box()
    points = np.random.default_rng(0).uniform(-0.5, 1.5, (PAIRS_PER_CHUNK // len(triangles) * 2 + 7, 3))
    whole = winding_numbers(points, vertices, triangles)
    step = PAIRS_PER_CHUNK // len(triangles)
    # Points of the first, the second and the last (partial) chunk, each measured alone.
    picked = np.r_[0:5, step:step + 5, len(points) - 5:len(points)]
    one_by_one = np.array([winding_numbers(points[index][None], vertices, triangles)[0] for index in picked])
    np.testing.assert_allclose(whole[picked], one_by_one, atol=1e-12)
    assert len(whole) == len(points)
