"""Point-to-segment distances (autorig_addon.core.geometry.segments), numbers by hand."""

import numpy as np

from autorig_addon.core.geometry import segments
from autorig_addon.core.geometry.segments import (
    closest_segments,
    nearest_points_on_segments,
    paired_point_segment_distances,
    paired_segment_parameters,
    point_segment_distances,
    polyline_arc_lengths,
    segment_parameters,
)


def test_point_segment_distances_clamp_to_the_ends_and_treat_points():
    heads = np.array([[0.0, 0, 0], [0, 0, 0]])
    tails = np.array([[2.0, 0, 0], [0, 0, 0]])  # the second bone has no length
    points = np.array([[1.0, 3, 0], [-3, 4, 0], [5, 0, 0]])
    np.testing.assert_allclose(point_segment_distances(points, heads, tails), [[3, np.sqrt(10)], [5, 5], [3, 5]])


def test_parameters_and_nearest_points_by_hand():
    heads, tails = np.array([[0.0, 0, 0]]), np.array([[4.0, 0, 0]])
    points = np.array([[1.0, 2, 0], [-1, 0, 0], [9, 1, 0]])
    np.testing.assert_allclose(segment_parameters(points, heads, tails)[:, 0], [0.25, 0.0, 1.0])
    np.testing.assert_allclose(nearest_points_on_segments(points, heads, tails)[:, 0],
                               [[1, 0, 0], [0, 0, 0], [4, 0, 0]])


def test_paired_distances_match_the_diagonal_of_all_pairs():
    rng = np.random.default_rng(5)
    points, heads, tails = rng.normal(size=(6, 3)), rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    tails[2] = heads[2]
    np.testing.assert_allclose(
        paired_point_segment_distances(points, heads, tails), np.diag(point_segment_distances(points, heads, tails)),
        atol=1e-12
    )


def test_paired_parameters_and_distances_by_hand():
    # Segment i pairs with point i: the third lies beyond the tail, the
    # fourth before the head, the fifth on a zero-length segment.
    heads = np.array([[0.0, 0, 0], [0, 0, 0], [0, 0, 0], [1, 1, 1], [2, 2, 2]])
    tails = np.array([[2.0, 0, 0], [0, 0, 4], [0, 2, 0], [1, 1, 3], [2, 2, 2]])
    points = np.array([[1.0, 3, 0], [1, 0, 1], [0, 5, 4], [1, 2, 0], [2, 5, 6]])
    np.testing.assert_allclose(paired_segment_parameters(points, heads, tails), [0.5, 0.25, 1.0, 0.0, 0.0],
                               atol=1e-15)
    np.testing.assert_allclose(paired_point_segment_distances(points, heads, tails), [3, 1, 5, np.sqrt(2), 5],
                               atol=1e-15)


def test_closest_segments_by_hand():
    starts = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    ends = np.array([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])  # the second is a point
    points = np.array([[0.5, 0.3, 0.0], [-1.0, 0.0, 0.0], [2.0, 0.0, 0.4], [1.6, 0.0, 0.0], [1.5, 0.0, 0.0]])
    index, distance = closest_segments(points, starts, ends)
    # The last point is equally far (0.5) from both: the lower index wins.
    np.testing.assert_array_equal(index, [0, 0, 1, 1, 0])
    np.testing.assert_allclose(distance, [0.3, 1.0, 0.4, 0.4, 0.5])


def test_chunking_gives_the_same_answer_as_brute_force(monkeypatch):
    rng = np.random.default_rng(3)
    points = rng.normal(size=(1000, 3))
    starts, ends = rng.normal(size=(7, 3)), rng.normal(size=(7, 3))
    whole_index, whole_distance = closest_segments(points, starts, ends)
    monkeypatch.setattr(segments, "CHUNK_BYTES", 24 * 7 * 64)  # 64 points a chunk
    chunk_index, chunk_distance = closest_segments(points, starts, ends)
    np.testing.assert_array_equal(whole_index, chunk_index)
    np.testing.assert_allclose(whole_distance, chunk_distance, rtol=1e-12)
    # Sample every segment densely; the closest sample is within one step of the exact distance.
    t = np.linspace(0.0, 1.0, 2001)[:, None, None]
    samples = (starts[None] + t * (ends - starts)[None]).reshape(-1, 3)
    brute = np.linalg.norm(points[:, None, :] - samples[None], axis=2).min(axis=1)
    step = np.linalg.norm(ends - starts, axis=1).max() / 2000
    assert np.all(whole_distance <= brute + 1e-12)
    assert np.all(brute - whole_distance <= step)


def test_polyline_arc_lengths_by_hand():
    polyline = np.array([[0.0, 0, 0], [2, 0, 0], [2, 3, 0]])
    points = np.array([[1.0, 1, 0], [3, 1.5, 0], [-1, 0, 0], [5, 9, 0]])
    np.testing.assert_allclose(polyline_arc_lengths(points, polyline), [1.0, 3.5, 0.0, 5.0])
