"""Key joints read from bone names, and the animator's key-joint score."""

import numpy as np
import pytest

from autorig_addon.core.evaluation.key_joint_metrics import KEY_JOINT_FRACTION, key_joint_score, score_key_joints
from autorig_addon.core.skeleton.key_joints import KEY_JOINTS, KeyJoints, key_joints
from autorig_addon.core.types import Skeleton
from geometry_fixtures import box_mesh

#: Real rigs' names (as the development set's files spell them) and the bone
#: each key role must come from.
RIGS = {
    "mixamo": (
        ["mixamorig:Hips", "mixamorig:Spine", "mixamorig:Neck", "mixamorig:Head", "mixamorig:LeftShoulder",
         "mixamorig:LeftArm", "mixamorig:LeftForeArm", "mixamorig:LeftHand", "mixamorig:RightArm",
         "mixamorig:RightForeArm", "mixamorig:RightHand", "mixamorig:LeftUpLeg", "mixamorig:LeftLeg",
         "mixamorig:LeftFoot", "mixamorig:RightUpLeg", "mixamorig:RightLeg", "mixamorig:RightFoot"],
        {"hips": "mixamorig:Hips", "neck": "mixamorig:Neck", "shoulder.L": "mixamorig:LeftArm",
         "wrist.R": "mixamorig:RightHand", "knee.L": "mixamorig:LeftLeg", "ankle.R": "mixamorig:RightFoot"}),
    "quaternius_kaykit": (
        ["root", "hips", "spine", "chest", "upperarm.l", "lowerarm.l", "wrist.l", "hand.l", "upperarm.r",
         "lowerarm.r", "wrist.r", "hand.r", "head", "upperleg.l", "lowerleg.l", "foot.l", "upperleg.r", "lowerleg.r",
         "foot.r"],
        {"hips": "hips", "head": "head", "wrist.L": "wrist.l", "elbow.R": "lowerarm.r", "hip.L": "upperleg.l"}),
    "3ds_max_biped": (
        ["bip01", "bip01 pelvis", "bip01 spine", "bip01 neck", "bip01 head", "bip01 l clavicle", "bip01 l upperarm",
         "bip01 l forearm", "bip01 l hand", "bip01 r upperarm", "bip01 r forearm", "bip01 r hand", "bip01 l thigh",
         "bip01 l calf", "bip01 l foot", "bip01 r thigh", "bip01 r calf", "bip01 r foot"],
        {"hips": "bip01 pelvis", "shoulder.L": "bip01 l upperarm", "knee.R": "bip01 r calf"}),
    "zeroad_human": (
        ["hip", "spine", "chest", "shoulder_L", "arm_L", "forearm_L", "hand_L", "shoulder_R", "arm_R", "forearm_R",
         "hand_R", "neck", "head", "thigh_L", "leg_L", "foot_L", "thigh_R", "leg_R", "foot_R", "knee_L", "knee_R"],
        # knee_L is an IK target there; the knee is the head of leg_L.
        {"shoulder.L": "arm_L", "knee.L": "leg_L", "knee.R": "leg_R", "ankle.L": "foot_L"}),
    "zeroad_horse": (
        ["root", "spine", "neck", "head", "l_shoulder", "l_upperarm", "l_arm", "l_forearm", "l_hand", "r_shoulder",
         "r_upperarm", "r_arm", "r_forearm", "r_hand", "l_femur", "l_thigh", "l_leg", "l_shin", "l_foot", "r_femur",
         "r_thigh", "r_leg", "r_shin", "r_foot"],
        {"shoulder.L": "l_upperarm", "elbow.L": "l_arm", "wrist.L": "l_forearm", "hip.R": "r_thigh",
         "knee.R": "r_leg", "ankle.R": "r_shin"}),
    "quaternius_animal": (
        ["Body", "Back", "Torso", "Neck1", "Head", "FrontShoulder.L", "FrontUpperLeg.L", "FrontLowerLeg.L", "FF.L",
         "FrontShoulder.R", "FrontUpperLeg.R", "FrontLowerLeg.R", "FF.R", "BackShoulder.L", "BackLeg.L",
         "BackUpperLeg.L", "BackLowerLeg.L", "BackShoulder.R", "BackLeg.R", "BackUpperLeg.R", "BackLowerLeg.R"],
        {"hips": "Back", "shoulder.L": "FrontUpperLeg.L", "wrist.R": "FF.R", "hip.L": "BackLeg.L",
         "knee.L": "BackUpperLeg.L", "ankle.L": "BackLowerLeg.L"}),
    "quaternius_dinosaur": (
        ["root", "Body", "BackLeg.L", "BackUpLeg.L", "BackLowLeg.L", "BackFoot.L", "BackLeg.R", "BackUpLeg.R",
         "BackLowLeg.R", "BackFoot.R", "Hips", "Torso", "Neck", "Head", "FrontUpLeg.L", "FrontLowLeg.L",
         "FrontFoot.L", "FrontUpLeg.R", "FrontLowLeg.R", "FrontFoot.R"],
        # Here BackLeg sits on the midline above the hip.
        {"hip.L": "BackUpLeg.L", "knee.L": "BackLowLeg.L", "ankle.L": "BackFoot.L"}),
    "rigify_human_metarig": (
        ["spine", "spine.001", "spine.002", "spine.003", "spine.004", "spine.005", "spine.006", "shoulder.L",
         "upper_arm.L", "forearm.L", "hand.L", "shoulder.R", "upper_arm.R", "forearm.R", "hand.R", "thigh.L",
         "shin.L", "foot.L", "thigh.R", "shin.R", "foot.R"],
        {"hips": "spine", "neck": "spine.004", "head": "spine.006", "elbow.L": "forearm.L"}),
}


@pytest.mark.parametrize("convention", sorted(RIGS))
def test_each_naming_convention_finds_its_rigs_key_joints(convention):
    names, expected = RIGS[convention]
    joints = np.arange(3 * len(names), dtype=float).reshape(-1, 3)
    found = key_joints(names, joints)
    assert found.convention == convention
    for role, bone in expected.items():
        assert names[found.bones[role]] == bone, role
        np.testing.assert_array_equal(found.positions[role], joints[names.index(bone)])
    assert list(found.bones) == [role for role in KEY_JOINTS if role in found.bones]


def test_the_predictors_rigify_names_give_all_fifteen_key_joints():
    names = ["spine", "spine.001", "neck", "head", "shoulder.L", "upper_arm.L", "forearm.L", "hand.L", "shoulder.R",
             "upper_arm.R", "forearm.R", "hand.R", "thigh.L", "shin.L", "foot.L", "toe.L", "thigh.R", "shin.R",
             "foot.R", "toe.R"]
    found = key_joints(names, np.zeros((len(names), 3)))
    assert found.convention == "rigify" and tuple(found.bones) == KEY_JOINTS
    assert names[found.bones["hips"]] == "spine" and names[found.bones["shoulder.R"]] == "upper_arm.R"
    # A quadruped's front legs take the arm roles.
    legs = ["spine", "neck", "head", "front_thigh.L", "front_shin.L", "front_foot.L", "thigh.L", "shin.L", "foot.L"]
    quadruped = key_joints(legs, np.zeros((len(legs), 3)))
    assert {role: legs[index] for role, index in quadruped.bones.items() if role.endswith(".L")} == {
        "shoulder.L": "front_thigh.L", "elbow.L": "front_shin.L", "wrist.L": "front_foot.L", "hip.L": "thigh.L",
        "knee.L": "shin.L", "ankle.L": "foot.L"}


def test_unknown_names_give_no_key_joints():
    found = key_joints(["Node_2", "Node_3", "Node_4"], np.zeros((3, 3)))
    assert found.convention == "" and found.bones == {} and found.positions == {}


def test_sides_named_from_the_viewer_are_swapped_to_the_characters_own():
    # 0 A.D.'s cattle: the bone named _L lies on the character's right (-x when its left is +x).
    names = ["Bovidae_pelvis", "Bovidae_FrontThigh_L", "Bovidae_FrontThigh_R"]
    joints = np.array([[0.0, 0.0, 1.0], [-0.2, 0.0, 1.0], [0.2, 0.0, 1.0]])
    as_named = key_joints(names, joints)
    assert as_named.positions["shoulder.L"][0] == -0.2
    turned = key_joints(names, joints, left_direction=[1.0, 0.0, 0.0])
    assert turned.positions["shoulder.L"][0] == 0.2 and turned.positions["shoulder.R"][0] == -0.2
    # A character whose left is -x keeps the names as they are.
    kept = key_joints(names, joints, left_direction=[-1.0, 0.0, 0.0])
    assert kept.positions["shoulder.L"][0] == -0.2


def test_key_joint_score_counts_missing_and_misplaced_joints_as_wrong():
    reference = KeyJoints("rigify", {}, {"hips": np.zeros(3), "head": np.array([0.0, 0.0, 1.0]),
                                         "knee.L": np.array([0.1, 0.0, 0.3])})
    predicted = KeyJoints("rigify", {}, {"hips": np.array([0.04, 0.0, 0.0]), "head": np.array([0.0, 0.0, 1.2]),
                                         "wrist.L": np.array([0.1, 0.0, 0.3])})
    scores = key_joint_score(predicted, reference, tolerance=0.05)
    # hips within 0.05, head 0.2 off, knee missing (the wrist in its place is another role).
    assert scores["key_joints"] == pytest.approx(1 / 3) and scores["key_joints_present"] == pytest.approx(2 / 3)
    assert scores["key_joint_count"] == 3
    assert scores["key_joint_errors"]["hips"] == pytest.approx(0.04)
    assert scores["key_joint_errors"]["head"] == pytest.approx(0.2) and scores["key_joint_errors"]["knee.L"] is None


def test_score_key_joints_uses_the_characters_size_and_skips_rigs_without_limbs():
    mesh = box_mesh([-0.5, -0.25, 0.0], [0.5, 0.25, 2.0], 0.25)  # largest side 2: tolerance 0.1
    names = ("hips", "thigh.L", "thigh.R")
    reference = Skeleton(np.array([[0.0, 0.0, 1.0], [0.2, 0.0, 0.9], [-0.2, 0.0, 0.9]]), np.array([-1, 0, 0]), names)
    moved = Skeleton(reference.joints + [0.0, 0.0, 0.08], reference.parents, names)
    scores = score_key_joints(moved, mesh, reference, size=2.0)
    assert KEY_JOINT_FRACTION * 2.0 == pytest.approx(0.1)
    assert scores["key_joints"] == 1.0 and scores["key_joint_errors"]["hips"] == pytest.approx(0.04)
    too_far = Skeleton(reference.joints + [0.0, 0.0, 0.12], reference.parents, names)
    assert score_key_joints(too_far, mesh, reference, size=2.0)["key_joints"] == 0.0
    # A fish's Head alone says no limb: not scored.
    fish = Skeleton(np.array([[0.0, 0.0, 1.0]]), np.array([-1]), ("Head",))
    assert score_key_joints(fish, mesh, fish, size=2.0) == {}


def test_a_reference_named_from_the_viewer_is_scored_by_the_characters_own_sides():
    # The artist's thigh.L lies at -X on a character facing -Y: its own right. A prediction with thigh.L at +X
    # (its own left) is right once the split says the sides were named from the viewer.
    mesh = box_mesh([-0.5, -0.25, 0.0], [0.5, 0.25, 2.0], 0.25)
    names = ("hips", "thigh.L", "thigh.R")
    reference = Skeleton(np.array([[0.0, 0.0, 1.0], [-0.2, 0.0, 0.9], [0.2, 0.0, 0.9]]), np.array([-1, 0, 0]), names)
    predicted = Skeleton(np.array([[0.0, 0.0, 1.0], [0.2, 0.0, 0.9], [-0.2, 0.0, 0.9]]), np.array([-1, 0, 0]), names)
    assert score_key_joints(predicted, mesh, reference, size=2.0)["key_joints"] == pytest.approx(1.0 / 3.0)
    told = score_key_joints(predicted, mesh, reference, size=2.0, sides_named_from_the_viewer=True)
    assert told["key_joints"] == 1.0 and told["key_joint_errors"]["hip.L"] == pytest.approx(0.0)
