"""Whether Blender can hold a skeleton as an armature, checked on the arrays.

Blender deletes zero-length bones when it leaves Edit Mode and truncates
long bone names, so a skeleton with either would come back changed; the
armature builder refuses it up front with :func:`check_buildable`.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..types import Skeleton

#: A bone shorter than this fraction of the skeleton's extent
#: (:func:`skeleton_extent`) has zero length: Blender would delete it on
#: leaving Edit Mode, and it has no direction to measure distances along.
MIN_BONE_LENGTH_FRACTION = 1e-5
#: Longest bone name Blender keeps, in UTF-8 bytes; longer names are
#: truncated, which could merge two bones.
MAX_NAME_BYTES = 63
#: Bones named in a refusal before the rest are only counted.
MAX_LISTED_BONES = 5
#: Extent used for a skeleton whose joints and tails all lie at one point,
#: so that fractions of it stay defined (skeleton units).
MIN_EXTENT = 1e-12


def skeleton_extent(skeleton: Skeleton) -> float:
    """Longest side of the axis-aligned box around the joints and tails.

    Returns
    -------
    float, at least :data:`MIN_EXTENT` (skeleton units). A bone from
    (0, 0, 0) to (0, 0, 2) with a child to (1, 0, 2) has extent 2.
    """
    points = np.vstack([skeleton.joints, skeleton.tails])
    return max(float(np.ptp(points, axis=0).max()), MIN_EXTENT) if len(points) else MIN_EXTENT


def zero_length_bones(skeleton: Skeleton) -> np.ndarray:
    """(k,) int64 indices of the bones shorter than
    :data:`MIN_BONE_LENGTH_FRACTION` of :func:`skeleton_extent`."""
    return np.flatnonzero(skeleton.bone_lengths < MIN_BONE_LENGTH_FRACTION * skeleton_extent(skeleton))


def check_buildable(skeleton: Skeleton) -> None:
    """Raise :class:`InputError` if Blender cannot hold ``skeleton`` as it is.

    Refused: no bones, NaN or infinite positions, zero-length bones
    (:func:`zero_length_bones`) and names longer than
    :data:`MAX_NAME_BYTES` bytes.
    """
    if skeleton.bone_count == 0:
        raise InputError("The skeleton has no bones.")
    if not (np.all(np.isfinite(skeleton.joints)) and np.all(np.isfinite(skeleton.tails))):
        raise InputError("The skeleton has NaN or infinite joint positions.")
    short = zero_length_bones(skeleton)
    if len(short):
        names = ", ".join(skeleton.names[i] for i in short[:MAX_LISTED_BONES])
        raise InputError(f"{len(short)} bone(s) have zero length ({names}); Blender cannot keep them.")
    long_names = [name for name in skeleton.names if len(name.encode("utf-8")) > MAX_NAME_BYTES]
    if long_names:
        raise InputError(f"Bone name too long for Blender ({MAX_NAME_BYTES} bytes max): '{long_names[0]}'.")
