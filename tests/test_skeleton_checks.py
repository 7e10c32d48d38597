"""Whether Blender can hold a skeleton (autorig_addon.core.skeleton.checks), worked by hand."""

import re

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.skeleton.checks import (
    MAX_NAME_BYTES,
    MIN_BONE_LENGTH_FRACTION,
    MIN_EXTENT,
    check_buildable,
    skeleton_extent,
    zero_length_bones,
)
from autorig_addon.core.types import Skeleton


def skeleton_with_lengths(short_lengths, names=None):
    """A 2-long bone up z from the origin, plus one bone per entry of
    ``short_lengths`` along z from (k, 0, 0): extent max(2, ...) along z."""
    count = 1 + len(short_lengths)
    joints = np.array([[0.0, 0.0, 0.0]] + [[0.1 * (k + 1), 0.0, 0.0] for k in range(len(short_lengths))])
    tails = joints + np.array([[0.0, 0.0, 2.0]] + [[0.0, 0.0, length] for length in short_lengths])
    names = names or tuple(["root"] + [f"b{k}" for k in range(len(short_lengths))])
    return Skeleton(joints, [-1] + [0] * (count - 1), names, tails)


def test_extent_is_the_longest_side_of_the_box_of_joints_and_tails():
    skeleton = Skeleton([[0, 0, 0], [0, 0, 2]], [-1, 0], ("a", "b"), [[0, 0, 2], [1, 0, 2]])
    assert skeleton_extent(skeleton) == 2.0
    point = Skeleton([[1, 1, 1]], [-1], ("p",), [[1, 1, 1]])
    assert skeleton_extent(point) == MIN_EXTENT


def test_zero_length_bones_are_those_under_the_fraction_of_the_extent():
    # Extent 2 (the root along z), so the limit is 2e-5.
    assert MIN_BONE_LENGTH_FRACTION == 1e-5
    skeleton = skeleton_with_lengths([1.9e-5, 2.1e-5, 0.5])
    np.testing.assert_array_equal(zero_length_bones(skeleton), [1])


def test_check_buildable_accepts_real_bones():
    check_buildable(skeleton_with_lengths([2.1e-5, 0.5]))


def test_check_buildable_names_the_zero_length_bones():
    with pytest.raises(InputError, match=re.escape("1 bone(s) have zero length (b0); Blender cannot keep them.")):
        check_buildable(skeleton_with_lengths([1e-6, 0.5]))
    # Six short bones: five are named, all are counted.
    with pytest.raises(InputError, match=re.escape(
            "6 bone(s) have zero length (b0, b1, b2, b3, b4); Blender cannot keep them.")):
        check_buildable(skeleton_with_lengths([0.0] * 6))


def test_check_buildable_refuses_empty_and_non_finite_skeletons():
    with pytest.raises(InputError, match="^The skeleton has no bones.$"):
        check_buildable(Skeleton(np.zeros((0, 3)), [], ()))
    with pytest.raises(InputError, match="^The skeleton has NaN or infinite joint positions.$"):
        check_buildable(Skeleton([[0, 0, 0], [0, 0, np.nan]], [-1, 0], ("a", "b")))
    with pytest.raises(InputError, match="^The skeleton has NaN or infinite joint positions.$"):
        check_buildable(Skeleton([[0, 0, 0]], [-1], ("a",), [[0, 0, np.inf]]))


def test_check_buildable_counts_name_length_in_utf8_bytes():
    assert MAX_NAME_BYTES == 63
    fits = "é" * 31 + "a"  # 63 bytes
    check_buildable(skeleton_with_lengths([0.5], names=("root", fits)))
    too_long = "é" * 32  # 32 characters, 64 bytes
    with pytest.raises(InputError, match=re.escape(f"Bone name too long for Blender (63 bytes max): '{too_long}'.")):
        check_buildable(skeleton_with_lengths([0.5], names=("root", too_long)))
