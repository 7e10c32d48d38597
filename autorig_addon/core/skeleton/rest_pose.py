"""The rest pose of a character's arms: T-pose, A-pose or arms down.

Artists rig in different rest poses (OpenClonk's Clonks in T-pose, Red
Eclipse's players in A-pose, 0 A.D.'s humans with their arms about 70
degrees down), and a network that learns joint positions sees the pose.
:func:`arm_pose` measures it from the skeleton's names and joints alone
(:func:`arm_angle`): each arm's angle below the horizontal, labelled by
:func:`pose_label`. A quadruped's front legs (0 A.D.'s animals name them
``l_upperarm``, ``l_hand``) end at the ground and are not arms.
"""

from __future__ import annotations

from typing import NamedTuple, Optional

import numpy as np

from ..types import Skeleton
from .hierarchy import children_lists
from .naming import LEFT_SIDE, NO_SIDE, RIGHT_SIDE, bone_side

#: Arms less than this many degrees below (or above) the horizontal are a T-pose.
T_POSE_MAX_DEGREES = 20.0
#: Arms up to this many degrees below the horizontal are an A-pose; lower, arms down.
A_POSE_MAX_DEGREES = 55.0
#: Two arms further apart than this many degrees are reported as asymmetric.
ASYMMETRIC_DEGREES = 30.0
#: An arm starts at least this share of the joints' height above the lowest joint (shoulders, not hips).
MIN_SHOULDER_HEIGHT_FRACTION = 0.55
#: An arm ends at least this share of the height above the lowest joint; lower, it is a front leg.
MIN_HAND_HEIGHT_FRACTION = 0.3

T_POSE, A_POSE, ARMS_DOWN, ARMS_RAISED, ASYMMETRIC = "T-pose", "A-pose", "arms down", "arms raised", "asymmetric"


class ArmPose(NamedTuple):
    """The arms of a rest pose.

    Attributes
    ----------
    left_degrees, right_degrees : float
        Angle of each arm below the horizontal (negative above it).
    label : str
        :data:`T_POSE`, :data:`A_POSE`, :data:`ARMS_DOWN`, :data:`ARMS_RAISED` or :data:`ASYMMETRIC`.
    """

    left_degrees: float
    right_degrees: float
    label: str

    @property
    def note(self) -> str:
        """One line for a character's notes."""
        return (f"rest pose: {self.label} (arms {self.left_degrees:.0f} and {self.right_degrees:.0f} degrees below "
                "horizontal, left and right)")


def pose_label(degrees: float) -> str:
    """The name of an arm angle below the horizontal (see the thresholds above)."""
    if degrees < -T_POSE_MAX_DEGREES:
        return ARMS_RAISED
    if degrees <= T_POSE_MAX_DEGREES:
        return T_POSE
    return A_POSE if degrees <= A_POSE_MAX_DEGREES else ARMS_DOWN


def _path_to_farthest(joints: np.ndarray, parents: np.ndarray, children: list, root: int) -> list[int]:
    """Joints from ``root`` down to its descendant farthest from it (``[root]`` without descendants)."""
    below, stack = [], list(children[root])
    while stack:
        joint = stack.pop()
        below.append(joint)
        stack.extend(children[joint])
    if not below:
        return [root]
    end = max(below, key=lambda joint: (float(np.linalg.norm(joints[joint] - joints[root])), -joint))
    path = [end]
    while path[-1] != root:
        path.append(int(parents[path[-1]]))
    return path[::-1]


def arm_angle(skeleton: Skeleton, side: int) -> Optional[float]:
    """Degrees below the horizontal of the arm on ``side`` (:data:`.naming.LEFT_SIDE` or
    :data:`.naming.RIGHT_SIDE`), or None when the skeleton has no arm there.

    The arm is the longest chain of deform joints named for that side
    (:func:`.naming.bone_side`) starting under a joint named for no side,
    high on the body (:data:`MIN_SHOULDER_HEIGHT_FRACTION`) and ending above
    the feet (:data:`MIN_HAND_HEIGHT_FRACTION`). Its angle is that of the
    line from the chain's second joint (the upper arm, past a clavicle; the
    first when the chain has two joints) to its farthest joint, z up.
    """
    bones = skeleton.deform_subset()
    joints, parents = bones.joints, bones.parents
    heights = joints[:, 2] - joints[:, 2].min()
    height_range = float(heights.max())
    if height_range <= 0.0:
        return None
    sides = np.array([bone_side(name) for name in bones.names], dtype=np.int64)
    children = children_lists(parents)
    best, best_reach = None, 0.0
    for root in range(len(joints)):
        if sides[root] != side or (parents[root] >= 0 and sides[parents[root]] != NO_SIDE):
            continue
        if heights[root] < MIN_SHOULDER_HEIGHT_FRACTION * height_range:
            continue
        path = _path_to_farthest(joints, parents, children, root)
        reach = float(np.linalg.norm(joints[path[-1]] - joints[root]))
        if len(path) >= 2 and heights[path[-1]] >= MIN_HAND_HEIGHT_FRACTION * height_range and reach > best_reach:
            best, best_reach = path, reach
    if best is None:
        return None
    arm = joints[best[-1]] - joints[best[1] if len(best) >= 3 else best[0]]
    return float(np.degrees(np.arctan2(-arm[2], np.linalg.norm(arm[:2]))))


def arm_pose(skeleton: Skeleton) -> Optional[ArmPose]:
    """The rest pose of a character's arms (see :func:`arm_angle`), or None
    when it lacks a left or a right arm (z up, any facing)."""
    left, right = arm_angle(skeleton, LEFT_SIDE), arm_angle(skeleton, RIGHT_SIDE)
    if left is None or right is None:
        return None
    if abs(left - right) > ASYMMETRIC_DEGREES:
        return ArmPose(left, right, ASYMMETRIC)
    return ArmPose(left, right, pose_label((left + right) / 2.0))
