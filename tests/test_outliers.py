"""Non-finite and stray vertices (autorig_addon.core.geometry.outliers), numpy only."""

import re

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.geometry.outliers import (
    INFINITE_COORDINATE,
    non_finite_rows,
    require_finite_positions,
    robust_box,
    rows_for_strays,
    stray_vertices,
    without_vertices,
)


def unit_grid(side=10):
    """(side**3, 3) points on a regular grid filling the unit cube."""
    axis = np.linspace(0.0, 1.0, side)
    return np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)


def test_non_finite_rows_include_blenders_stored_infinity():
    vertices = np.array([
        [0.0, 0.0, 0.0],
        [1e30, -1e30, 5.0],           # huge but finite: kept
        [np.nan, 0.0, 0.0],
        [0.0, np.inf, 0.0],
        [0.0, 0.0, -INFINITE_COORDINATE],
        [float(np.float32(3.4028235e38)), 0.0, 0.0],  # what Blender reads back for inf
    ])
    assert non_finite_rows(vertices).tolist() == [False, False, True, True, True, True]


def test_require_finite_positions_names_the_object_and_local_indices():
    vertices = np.zeros((7, 3))
    vertices[5, 1] = np.inf
    vertices[6, 0] = np.nan
    require_finite_positions(vertices[:4], ("Body",), (0, 4))
    with pytest.raises(InputError, match=re.escape(
            "'Gloves' has 2 vertices at an infinite or undefined (NaN) position (index 1, 2): move or delete them "
            "in Edit Mode first.")):
        require_finite_positions(vertices, ("Body", "Gloves"), (0, 4, 7))


def test_robust_box_leaves_one_percent_out_at_each_end():
    points = unit_grid()  # every coordinate value 100 times: trimming 10 at each end changes nothing
    low, high = robust_box(np.vstack([points, [[5000.0, -7000.0, 0.5]]]))
    np.testing.assert_array_equal(low, [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(high, [1.0, 1.0, 1.0])


def test_strays_are_farther_than_one_robust_size_outside_the_box():
    points = unit_grid()
    size = np.sqrt(3.0)  # the unit cube's diagonal
    near = [1.0 + 0.98 * size, 0.5, 0.5]
    far = [1.0 + 1.02 * size, 0.5, 0.5]
    very_far = [0.5, 0.5, -1e4]
    strays = stray_vertices(np.vstack([points, [near, far, very_far]]))
    assert np.flatnonzero(strays).tolist() == [1000 + 1, 1000 + 2]
    # The rule has no unit: the same at any scale.
    assert np.array_equal(stray_vertices(1e-3 * np.vstack([points, [near, far, very_far]])), strays)


@pytest.mark.parametrize("vertices", [np.zeros((0, 3)), [[0.0, 0, 0], [1e4, 0, 0]], np.ones((50, 3))])
def test_no_strays_without_a_bulk_to_measure_against(vertices):
    assert not stray_vertices(np.asarray(vertices, dtype=float)).any()


def test_without_vertices_drops_touching_triangles_and_renumbers():
    vertices = np.arange(15, dtype=float).reshape(5, 3)
    triangles = np.array([[0, 1, 2], [1, 2, 3], [2, 3, 4]])
    kept, kept_vertices, kept_triangles = without_vertices(vertices, triangles, np.array([0, 0, 0, 0, 1], bool))
    assert kept.tolist() == [0, 1, 2, 3]
    np.testing.assert_array_equal(kept_vertices, vertices[:4])
    assert kept_triangles.tolist() == [[0, 1, 2], [1, 2, 3]]


def test_each_group_of_strays_takes_one_kept_row_whole():
    # A strip of two triangles (0..3), a vertex 4 dragged off but joined to 2 and 3,
    # and a loose triangle 5..7 far off nearest to vertex 1.
    vertices = np.array([
        [0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0],
        [0.2, 50, 0],
        [90, 0, 0], [91, 0, 0], [90, 1, 0],
    ])
    triangles = np.array([[0, 1, 2], [1, 3, 2], [2, 3, 4], [5, 6, 7]])
    drop = np.array([0, 0, 0, 0, 1, 1, 1, 1], dtype=bool)
    kept_rows = np.array([[1.0, 0.0], [0.0, 1.0], [0.5, 0.5], [0.25, 0.75]])
    rows = rows_for_strays(kept_rows, vertices, triangles, drop)
    np.testing.assert_array_equal(rows[:4], kept_rows)
    # Vertex 4 is joined to 2 (0.2 off in x) and 3 (0.8 off): it takes 2's row, not the nearest-in-space mix.
    np.testing.assert_array_equal(rows[4], [0.5, 0.5])
    # The loose triangle is joined to nothing kept: all of it takes vertex 1's row (the nearest, to vertex 5).
    np.testing.assert_array_equal(rows[5:], [[0.0, 1.0]] * 3)
