"""The arms' rest pose measured from a skeleton (autorig_addon.core.skeleton.rest_pose)."""

import pytest

from autorig_addon.core.skeleton.naming import LEFT_SIDE
from autorig_addon.core.skeleton.rest_pose import (
    A_POSE,
    ARMS_DOWN,
    ARMS_RAISED,
    ASYMMETRIC,
    T_POSE,
    arm_angle,
    arm_pose,
)
from autorig_addon.core.types import Skeleton
from geometry_fixtures import arm_posed_humanoid


@pytest.mark.parametrize(
    ("degrees", "label"),
    [(0.0, T_POSE), (10.0, T_POSE), (35.0, A_POSE), (50.0, A_POSE), (70.0, ARMS_DOWN), (85.0, ARMS_DOWN),
     (-40.0, ARMS_RAISED)],
)
def test_arm_pose_of_generated_figures(degrees, label):
    pose = arm_pose(arm_posed_humanoid(degrees, degrees))
    assert pose.left_degrees == pytest.approx(degrees, abs=1e-9)
    assert pose.right_degrees == pytest.approx(degrees, abs=1e-9)
    assert pose.label == label


def zero_ad_name(mixamo_name: str) -> str:
    """0 A.D.'s naming: ``mixamorig:LeftForeArm`` -> ``forearm_L``."""
    name = mixamo_name.removeprefix("mixamorig:")
    for side, suffix in (("Left", "_L"), ("Right", "_R")):
        if name.startswith(side):
            return name[len(side):].lower() + suffix
    return name.lower()


def test_arm_pose_reads_names_of_other_rigs_and_notes_it():
    # 0 A.D.'s humans: shoulder_L, arm_L, forearm_L, hand_L, arms about 70 degrees down.
    mixamo = arm_posed_humanoid(70.0, 70.0)
    zero_ad = Skeleton(mixamo.joints, mixamo.parents, tuple(zero_ad_name(name) for name in mixamo.names))
    assert zero_ad.names[5:9] == ("shoulder_L", "arm_L", "forearm_L", "hand_L")
    pose = arm_pose(zero_ad)
    assert pose.label == ARMS_DOWN
    assert pose.note == "rest pose: arms down (arms 70 and 70 degrees below horizontal, left and right)"


def test_arms_at_different_angles_are_asymmetric():
    pose = arm_pose(arm_posed_humanoid(5.0, 65.0))
    assert (pose.label, round(pose.left_degrees), round(pose.right_degrees)) == (ASYMMETRIC, 5, 65)


def test_front_legs_named_as_arms_are_not_arms():
    # 0 A.D.'s animals name their front legs l_upperarm ... l_finger, down to the ground.
    joints = [[0, 0.5, 1.0], [0.2, 0.5, 1.0], [0.2, 0.5, 0.5], [0.2, 0.5, 0.1], [0.2, 0.5, 0.0],
              [-0.2, 0.5, 1.0], [-0.2, 0.5, 0.5], [-0.2, 0.5, 0.1], [-0.2, 0.5, 0.0], [0, -0.5, 1.3]]
    names = ("spine", "l_upperarm", "l_forearm", "l_hand", "l_finger",
             "r_upperarm", "r_forearm", "r_hand", "r_finger", "head")
    animal = Skeleton(joints, [-1, 0, 1, 2, 3, 0, 5, 6, 7, 0], names)
    assert arm_angle(animal, LEFT_SIDE) is None
    assert arm_pose(animal) is None


def test_a_skeleton_without_side_names_has_no_arm_pose():
    skeleton = arm_posed_humanoid(0.0, 0.0)
    anonymous = Skeleton(skeleton.joints, skeleton.parents, tuple(f"bone_{k}" for k in range(len(skeleton.names))))
    assert arm_pose(anonymous) is None
