"""Loose parts bound wholly to one bone (core/skinning/rigid_parts.py): a
piece whose weights lie mostly on one bone moves as one piece; a piece that
spans a joint keeps its blend."""

import numpy as np
import pytest

from autorig_addon.core.skinning.rigid_parts import RIGID_SHARE, loose_parts, rigid_weights
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh


def joined(*meshes: Mesh) -> Mesh:
    offsets = np.cumsum([0] + [mesh.vertex_count for mesh in meshes[:-1]])
    return Mesh(np.concatenate([mesh.vertices for mesh in meshes]),
                np.concatenate([mesh.triangles + offset for mesh, offset in zip(meshes, offsets)]))


@pytest.fixture
def robot():
    """A head plate (0.92 on the head bone), an arm bar spanning the elbow
    (half on each bone along its length), an eye that is left unweighted."""
    plate = box_mesh([0.0, 0.0, 1.0], [0.4, 0.4, 1.4], 0.05)
    bar = box_mesh([1.0, 0.0, 0.0], [1.1, 0.1, 1.0], 0.05)
    eye = box_mesh([0.1, -0.06, 1.2], [0.15, -0.01, 1.25], 0.05)
    mesh = joined(plate, bar, eye)
    weights = np.zeros((mesh.vertex_count, 3))
    plate_rows = np.arange(plate.vertex_count)
    weights[plate_rows] = [0.92, 0.08, 0.0]
    bar_rows = plate.vertex_count + np.arange(bar.vertex_count)
    lower = bar.vertices[:, 2] < 0.5
    weights[bar_rows[lower]] = [0.0, 0.9, 0.1]
    weights[bar_rows[~lower]] = [0.0, 0.1, 0.9]
    return mesh, weights, plate_rows, bar_rows


def test_a_piece_mostly_on_one_bone_moves_wholly_with_it_and_one_spanning_a_joint_keeps_its_blend(robot):
    mesh, weights, plate_rows, bar_rows = robot
    rigid, count = rigid_weights(mesh, weights)
    assert count == 1
    np.testing.assert_array_equal(rigid[plate_rows], np.tile([1.0, 0.0, 0.0], (len(plate_rows), 1)))
    np.testing.assert_array_equal(rigid[bar_rows], weights[bar_rows])
    # The eye had no weight and gets none.
    eye_rows = np.arange(bar_rows[-1] + 1, mesh.vertex_count)
    assert not rigid[eye_rows].any()
    np.testing.assert_allclose(rigid[rigid.any(axis=1)].sum(axis=1), 1.0)


def test_the_share_decides_and_seams_do_not_split_a_piece(robot):
    mesh, weights, plate_rows, _ = robot
    # Each box's six faces are not welded to each other, yet each box is one part.
    assert len(np.unique(loose_parts(mesh))) == 3
    assert len(np.unique(loose_parts(mesh)[plate_rows])) == 1
    # The plate holds 0.92 on its bone: rigid at the default share, not at 0.95.
    assert RIGID_SHARE <= 0.92
    same, count = rigid_weights(mesh, weights, share=0.95)
    assert count == 0 and np.array_equal(same, weights)


def test_a_one_piece_mesh_is_left_as_it_is():
    mesh = box_mesh([0.0, 0.0, 0.0], [0.2, 0.2, 1.0], 0.05)
    weights = np.where(mesh.vertices[:, [2]] < 0.5, [[0.9, 0.1]], [[0.95, 0.05]])
    same, count = rigid_weights(mesh, weights)
    assert count == 0 and np.array_equal(same, weights)
