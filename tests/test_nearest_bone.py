"""Nearest-bone weights (autorig_addon.core.skinning.nearest_bone), numbers by hand."""

import re

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.skinning.nearest_bone import nearest_bone_weights
from autorig_addon.core.types import Mesh, Skeleton
from geometry_fixtures import cylinder, two_bone_skeleton


def test_two_bone_cylinder_splits_at_the_joint():
    # Radius 0.1, height 1, rings every 0.05; bones lower (0 to 0.5) and upper (0.5 to 1).
    mesh = cylinder(radius=0.1, height=1.0, segments=8, rings=21)
    weights = nearest_bone_weights(mesh, two_bone_skeleton())
    z = mesh.vertices[:, 2]
    assert weights.bone_names == ("lower", "upper")
    # A side vertex at height z < 0.5 is 0.1 from the lower bone and
    # sqrt(0.01 + (0.5 - z)^2) > 0.1 from the upper one, and the reverse above.
    np.testing.assert_array_equal(weights.matrix[z < 0.5 - 1e-9], [[1.0, 0.0]] * int(np.sum(z < 0.5 - 1e-9)))
    np.testing.assert_array_equal(weights.matrix[z > 0.5 + 1e-9], [[0.0, 1.0]] * int(np.sum(z > 0.5 + 1e-9)))
    # On the joint ring both bones are 0.1 away: the first bone wins the tie.
    on_joint = np.isclose(z, 0.5)
    assert on_joint.sum() == 8
    np.testing.assert_array_equal(weights.matrix[on_joint, 0], np.ones(8))


def test_non_deform_bones_get_no_column():
    skeleton = Skeleton(
        joints=[[0, 0, 0], [0, 0, 0.5], [0.05, 0.0, 0.2]], parents=[-1, 0, 0], names=("lower", "upper", "control"),
        tails=[[0, 0, 0.5], [0, 0, 1.0], [0.05, 0.0, 0.3]], deform=[True, True, False],
    )
    mesh = cylinder(radius=0.1, height=1.0, segments=6, rings=11)
    weights = nearest_bone_weights(mesh, skeleton)
    assert weights.bone_names == ("lower", "upper")
    # The control bone is 0.05 from the +x side vertices at z = 0.2 and 0.3
    # ("lower" is 0.1 away); without a column it changes nothing.
    assert np.sum(np.isclose(mesh.vertices[:, 0], 0.1) & (np.abs(mesh.vertices[:, 2] - 0.25) < 0.06)) == 2
    np.testing.assert_array_equal(weights.matrix, nearest_bone_weights(mesh, two_bone_skeleton()).matrix)


def test_skeleton_without_deform_bones_is_an_input_error():
    skeleton = Skeleton([[0, 0, 0]], [-1], ("only",), [[0, 0, 1]], [False])
    message = "The skeleton has no deform bones: turn on Deform for the bones that should move the mesh."
    with pytest.raises(InputError, match=f"^{re.escape(message)}$"):
        nearest_bone_weights(Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]), skeleton)
