"""Plane sections of meshes (autorig_addon.core.geometry.plane_section): outlines known by hand."""

import numpy as np

from autorig_addon.core.geometry.plane_section import plane_section
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh, cylinder


def _centre(section) -> np.ndarray:
    return (section.midpoints * section.lengths[:, None]).sum(axis=0) / section.lengths.sum()


def test_a_box_cut_across_gives_its_square_outline():
    section = plane_section(box_mesh([0, 0, 0], [1, 1, 1], 0.3), [0.2, 0.7, 0.4], [0, 0, 2.0])
    np.testing.assert_allclose(section.lengths.sum(), 4.0, atol=1e-12)
    np.testing.assert_allclose(section.starts[:, 2], 0.4, atol=1e-12)
    np.testing.assert_allclose(section.ends[:, 2], 0.4, atol=1e-12)
    np.testing.assert_allclose(_centre(section), [0.5, 0.5, 0.4], atol=1e-12)


def test_vertices_on_the_plane_count_each_edge_in_it_once():
    # Spacing 0.25 puts rows of vertices at z = 0.5: the outline runs along the faces' edges there.
    section = plane_section(box_mesh([0, 0, 0], [1, 1, 1], 0.25), [0, 0, 0.5], [0, 0, 1])
    assert len(np.unique(section.loops)) == 1
    np.testing.assert_allclose(section.lengths.sum(), 4.0, atol=1e-12)
    np.testing.assert_allclose(_centre(section), [0.5, 0.5, 0.5], atol=1e-12)


def test_a_slanted_cut_through_a_cylinder_is_one_ellipse_round_its_axis():
    tube = cylinder(radius=0.1, height=1.0, segments=24, rings=11, capped=False)
    normal = np.array([0.0, np.sin(np.radians(30)), np.cos(np.radians(30))])
    section = plane_section(tube, [0, 0, 0.5], normal)
    assert len(np.unique(section.loops)) == 1
    np.testing.assert_allclose((section.midpoints - [0, 0, 0.5]) @ normal, 0.0, atol=1e-12)
    # The ellipse's centre is on the axis; its ends along the slant rise and fall 0.1 tan 30° about it.
    np.testing.assert_allclose(_centre(section), [0, 0, 0.5], atol=2e-3)
    points = np.concatenate([section.starts, section.ends])
    np.testing.assert_allclose(np.hypot(points[:, 0], points[:, 1]).max(), 0.1, atol=1e-12)
    np.testing.assert_allclose(np.abs(points[:, 2] - 0.5).max(), 0.1 * np.tan(np.radians(30)), atol=1e-12)


def test_two_tubes_give_two_loops_and_keep_keeps_their_labels():
    left, right = cylinder(radius=0.1, capped=False), cylinder(radius=0.05, capped=False)
    both = Mesh(np.concatenate([left.vertices - [0.5, 0, 0], right.vertices + [0.5, 0, 0]]),
                np.concatenate([left.triangles, right.triangles + len(left.vertices)]))
    section = plane_section(both, [0, 0, 0.33], [0, 0, 1])
    labels = np.unique(section.loops)
    assert len(labels) == 2
    perimeters = sorted(section.lengths[section.loops == label].sum() for label in labels)
    chord = 2 * np.sin(np.pi / 24)
    np.testing.assert_allclose(perimeters, [24 * 0.05 * chord, 24 * 0.1 * chord], atol=1e-12)
    right_only = section.keep(section.midpoints[:, 0] > 0)
    np.testing.assert_allclose(_centre(right_only), [0.5, 0, 0.33], atol=1e-12)
    assert len(np.unique(right_only.loops)) == 1


def _split_at_columns(tube: Mesh, segments: int, columns) -> Mesh:
    """``tube`` (a :func:`cylinder`) with its vertices split along the given columns of its sides, as an exporter
    splits them at UV seams: the faces before each column take copies."""
    vertices, triangles = tube.vertices, tube.triangles.copy()
    for column in columns:
        ids = np.arange(column, len(tube.vertices), segments)
        copies = np.arange(len(vertices), len(vertices) + len(ids))
        moved = np.full(len(vertices), -1)
        moved[ids] = copies
        before = np.isin(triangles, np.arange((column - 1) % segments, len(tube.vertices), segments)).any(axis=1)
        rows = np.isin(triangles, ids) & before[:, None]
        triangles[rows] = moved[triangles[rows]]
        vertices = np.concatenate([vertices, tube.vertices[ids]])
    return Mesh(vertices, triangles)


def test_seams_of_split_vertices_do_not_break_the_loop():
    tube = cylinder(radius=0.1, capped=False, segments=24)
    seamed = _split_at_columns(tube, 24, (0, 12))
    assert len(seamed.vertices) == len(tube.vertices) + 2 * 21
    section = plane_section(seamed, [0, 0, 0.52], [0, 0.1, 1])
    assert len(np.unique(section.loops)) == 1
    np.testing.assert_allclose(section.lengths.sum(), plane_section(tube, [0, 0, 0.52], [0, 0.1, 1]).lengths.sum(),
                               atol=1e-12)


def test_a_plane_that_misses_the_mesh_cuts_nothing():
    section = plane_section(box_mesh([0, 0, 0], [1, 1, 1], 0.5), [0, 0, 2.0], [0, 0, 1])
    assert section.starts.shape == (0, 3) and section.ends.shape == (0, 3) and section.loops.shape == (0,)
