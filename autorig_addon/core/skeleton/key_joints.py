"""The key joints an animator reaches for first, read from bone names.

An animator judges a rig by fifteen joints: the hips, the neck, the head, and
on each side the shoulder, elbow, wrist, hip, knee and ankle. Each is the
*head* of one bone: the shoulder is where the upper arm starts, the elbow the
forearm, the wrist the hand, the hip the thigh, the knee the shin, the ankle
the foot. A quadruped's front legs take the arm roles (the first bone of the
leg below the body, the next, the next) and its hind legs the leg roles.

Artists name those bones in many ways. A :class:`NamingConvention` says, for
one family of rigs, which bone plays each role; :func:`key_joints` tries
every convention in :data:`CONVENTIONS` and keeps the one that finds the most
roles. The conventions were written from the rigs of the development set
(``../shared/data/characters``) and checked on them joint by joint (heights
ordered hip > knee > ankle, shoulder > wrist away from the midline, ...);
``tests/test_key_joints.py`` builds one rig per convention.

Names are compared without case and without a namespace
(``mixamorig:LeftArm`` reads as ``leftarm``). A role a rig does not have
(KayKit rigs have no neck, Kenney's minis no elbow) is simply absent:
callers score only the roles the reference has.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .hierarchy import ancestors
from .naming import mirror_name

#: Roles on the midline, then the roles every side has.
MIDLINE_ROLES = ("hips", "neck", "head")
SIDE_ROLES = ("shoulder", "elbow", "wrist", "hip", "knee", "ankle")
LEFT, RIGHT = ".L", ".R"
#: The fifteen key joints, in report order.
KEY_JOINTS = MIDLINE_ROLES + tuple(role + side for side in (LEFT, RIGHT) for role in SIDE_ROLES)
#: Index in :data:`KEY_JOINTS` of each key joint's mirror twin (its own on the midline).
KEY_JOINT_TWINS = tuple(KEY_JOINTS.index(mirror_name(name)) for name in KEY_JOINTS)
#: Placeholder for the side spelling in a convention's bone names.
SIDE = "{s}"


@dataclass(frozen=True)
class NamingConvention:
    """Which bone plays each key role in one family of rigs.

    Attributes
    ----------
    name : str, shown in reports
    roles : dict mapping a role of :data:`MIDLINE_ROLES` or
        :data:`SIDE_ROLES` to bone names to try in order; side roles write
        the side as ``{s}``
    sides : tuple of (left, right) spellings tried in order for ``{s}``
    requires : names (``{s}`` read as the left spelling of one side pair)
        that must all exist for the convention to apply; it tells apart rigs whose words
        mean different things (a Quaternius animal's ``BackLeg`` is its hip,
        a Quaternius dinosaur's a bone on the midline above it)
    """

    name: str
    roles: dict
    sides: tuple = ((".L", ".R"),)
    requires: tuple = field(default=())

    def bone_names(self, names) -> dict:
        """The key role -> bone index this convention finds in ``names``."""
        lookup = {}
        for index, name in enumerate(names):
            lookup.setdefault(_plain(name), index)
        if self.requires and not any(
            all(_plain(required.replace(SIDE, left)) in lookup for required in self.requires)
            for left, _ in self.sides
        ):
            return {}
        found = {}
        for role, candidates in self.roles.items():
            if role in MIDLINE_ROLES:
                index = _first(lookup, candidates, "")
                if index is not None:
                    found[role] = index
                continue
            for side_index, side in enumerate((LEFT, RIGHT)):
                for pair in self.sides:
                    index = _first(lookup, candidates, pair[side_index])
                    if index is not None:
                        found[role + side] = index
                        break
        return found


def _plain(name: str) -> str:
    return str(name).rsplit(":", 1)[-1].strip().lower()


def _first(lookup: dict, candidates, side: str):
    for candidate in candidates:
        index = lookup.get(_plain(candidate.replace(SIDE, side)))
        if index is not None:
            return index
    return None


def _convention(name, hips=(), neck=(), head=(), shoulder=(), elbow=(), wrist=(), hip=(), knee=(), ankle=(),
                sides=((".L", ".R"),), requires=()) -> NamingConvention:
    roles = dict(hips=hips, neck=neck, head=head, shoulder=shoulder, elbow=elbow, wrist=wrist, hip=hip, knee=knee,
                 ankle=ankle)
    return NamingConvention(name, {role: tuple(names) for role, names in roles.items() if names}, sides, requires)


#: Every convention known, the predicted skeletons' own (Rigify's) first.
CONVENTIONS = (
    # Rigify's metarigs as the predictor names them (``neck``, ``head``;
    # quadrupeds' front legs ``front_thigh``...), Red Eclipse's split limbs
    # (``thigh.L.01``) and SuperTuxKart's rigs.
    _convention(
        "rigify", hips=("hips", "pelvis", "spine"), neck=("neck",), head=("head",),
        shoulder=("upper_arm{s}", "upper_arm{s}.01", "front_thigh{s}"),
        elbow=("forearm{s}", "forearm{s}.01", "front_shin{s}"), wrist=("hand{s}", "front_foot{s}"),
        hip=("thigh{s}", "thigh{s}.01"), knee=("shin{s}", "shin{s}.01"), ankle=("foot{s}",)),
    # Rigify's own numbering: the human metarig's neck and head are
    # ``spine.004`` and ``spine.006``; the quadruped's hips ``spine.004``
    # (``spine`` to ``spine.003`` are its tail).
    _convention(
        "rigify_human_metarig", hips=("spine",), neck=("spine.004",), head=("spine.006",),
        shoulder=("upper_arm{s}",), elbow=("forearm{s}",), wrist=("hand{s}",), hip=("thigh{s}",), knee=("shin{s}",),
        ankle=("foot{s}",), requires=("upper_arm{s}", "spine.006")),
    _convention(
        "rigify_quadruped_metarig", hips=("spine.004",), shoulder=("front_thigh{s}",), elbow=("front_shin{s}",),
        wrist=("front_foot{s}",), hip=("thigh{s}",), knee=("shin{s}",), ankle=("foot{s}",),
        requires=("front_thigh{s}", "spine.004")),
    # Mixamo (with or without the ``mixamorig:`` namespace).
    _convention(
        "mixamo", hips=("Hips",), neck=("Neck",), head=("Head",), shoulder=("{s}Arm",), elbow=("{s}ForeArm",),
        wrist=("{s}Hand",), hip=("{s}UpLeg",), knee=("{s}Leg",), ankle=("{s}Foot",), sides=(("Left", "Right"),),
        requires=("{s}UpLeg",)),
    # Quaternius humanoids, mechs and monsters; KayKit (``wrist.l`` is the
    # wrist, its ``hand.l`` the palm); OpenClonk's wipf (``upperarm_l``).
    _convention(
        "quaternius_kaykit", hips=("Hips", "spine lower"), neck=("Neck", "Neck1"), head=("Head",),
        shoulder=("UpperArm{s}",), elbow=("LowerArm{s}",), wrist=("wrist{s}", "Hand{s}", "Fist{s}", "Palm{s}"),
        hip=("UpperLeg{s}",), knee=("LowerLeg{s}",), ankle=("Foot{s}",), sides=((".L", ".R"), ("_l", "_r")),
        requires=("UpperArm{s}",)),
    # Quaternius animals: ``BackLeg`` is the hip joint, ``FF``/``FFB`` the feet.
    _convention(
        "quaternius_animal", hips=("Back",), neck=("Neck1",), head=("Head",), shoulder=("FrontUpperLeg{s}",),
        elbow=("FrontLowerLeg{s}",), wrist=("FF{s}",), hip=("BackLeg{s}",), knee=("BackUpperLeg{s}",),
        ankle=("BackLowerLeg{s}",), requires=("BackUpperLeg{s}",)),
    # Quaternius dinosaurs and rat: ``BackLeg`` sits on the midline above the hip.
    _convention(
        "quaternius_dinosaur", hips=("Hips",), neck=("Neck",), head=("Head",), shoulder=("FrontUpLeg{s}",),
        elbow=("FrontLowLeg{s}",), wrist=("FrontFoot{s}",), hip=("BackUpLeg{s}",), knee=("BackLowLeg{s}",),
        ankle=("BackFoot{s}",), requires=("BackUpLeg{s}",)),
    # Unreal's mannequin (GDQuest's Mannequiny).
    _convention(
        "unreal", hips=("pelvis",), neck=("neck_01",), head=("head",), shoulder=("upperarm{s}",),
        elbow=("lowerarm{s}",), wrist=("hand{s}",), hip=("thigh{s}",), knee=("calf{s}",), ankle=("foot{s}",),
        sides=((".l", ".r"), ("_l", "_r")), requires=("calf{s}",)),
    # 3ds Max Biped (Nexuiz; its renamed rigs call the arm ``arm``, ``arm1``,
    # ``arm2`` from the clavicle and the leg ``leg``, ``leg1``).
    _convention(
        "3ds_max_biped", hips=("bip01 pelvis", "bip001 pelvis"), neck=("bip01 neck", "bip001 neck"),
        head=("bip01 head", "bip001 head"), shoulder=("bip01 {s} upperarm", "bip001 {s} upperarm", "bip01 {s} arm1"),
        elbow=("bip01 {s} forearm", "bip001 {s} forearm", "bip01 {s} arm2"),
        wrist=("bip01 {s} hand", "bip001 {s} hand"), hip=("bip01 {s} thigh", "bip001 {s} thigh", "bip01 {s} leg"),
        knee=("bip01 {s} calf", "bip001 {s} calf", "bip01 {s} leg1"), ankle=("bip01 {s} foot", "bip001 {s} foot"),
        sides=(("l", "r"),)),
    # 0 A.D. humans (``knee_L`` and ``elbow_L`` there are IK targets, not joints).
    _convention(
        "zeroad_human", hips=("hip",), neck=("neck",), head=("head",), shoulder=("arm{s}",), elbow=("forearm{s}",),
        wrist=("hand{s}",), hip=("thigh{s}",), knee=("leg{s}",), ankle=("foot{s}",), sides=(("_L", "_R"),),
        requires=("arm{s}", "leg{s}")),
    # 0 A.D. horses: ``l_upperarm``, ``l_arm``, ``l_forearm`` down the front
    # leg; ``l_thigh``, ``l_leg``, ``l_shin`` down the hind leg.
    _convention(
        "zeroad_horse", hips=("spine",), neck=("neck",), head=("head",), shoulder=("{s}upperarm",),
        elbow=("{s}arm",), wrist=("{s}forearm",), hip=("{s}thigh",), knee=("{s}leg",), ankle=("{s}shin",),
        sides=(("l_", "r_"),), requires=("{s}femur",)),
    # 0 A.D. cats, deer, rabbits, donkey: clavicle, upperarm, forearm, hand; thigh, calf, foot.
    _convention(
        "zeroad_mammal", hips=("pelvis",), neck=("neck",), head=("head",), shoulder=("{s}upperarm",),
        elbow=("{s}forearm",), wrist=("{s}hand",), hip=("{s}thigh",), knee=("{s}calf",), ankle=("{s}foot",),
        sides=(("l_", "r_"),), requires=("{s}calf",)),
    # 0 A.D. cattle (sides spelled ``_L`` and ``_left`` within one leg).
    _convention(
        "zeroad_bovid", hips=("Bovidae_pelvis",), neck=("Bovidae_Neck",), head=("Bovidae_Head",),
        shoulder=("Bovidae_FrontThigh{s}",), elbow=("Bovidae_FrontCalf{s}",), wrist=("Bovidae_FrontFoot{s}",),
        hip=("Bovidae_RearThigh{s}",), knee=("Bovidae_RearCalf{s}",), ankle=("Bovidae_RearFoot{s}",),
        sides=(("_L", "_R"), ("_left", "_right"))),
    # 0 A.D. African and Asian elephants (``Elephantidae_Arm_L``).
    _convention(
        "zeroad_elephantidae", hips=("Elephantidae_Pelvis",), neck=("Elephantidae_Vertebrae_Cervical",),
        head=("Elephantidae_Head",), shoulder=("Elephantidae_Arm{s}",), elbow=("Elephantidae_Forearm{s}",),
        wrist=("Elephantidae_Hand{s}",), hip=("Elephantidae_Leg{s}",), knee=("Elephantidae_Shin{s}",),
        ankle=("Elephantidae_Foot{s}",), sides=(("_L", "_R"),)),
    # 0 A.D. war elephants and sheep (``arm_left``, ``Shin_Left``).
    _convention(
        "zeroad_limbs", hips=("pelvis", "Body_Rear"), neck=("neck",), head=("head",), shoulder=("arm{s}",),
        elbow=("forearm{s}",), wrist=("hand{s}",), hip=("leg{s}",), knee=("shin{s}",), ankle=("foot{s}",),
        sides=(("_left", "_right"),), requires=("shin{s}",)),
    # 0 A.D. pigs (the shin's head lies at the origin in every file, so the
    # hind knee is left out).
    _convention(
        "zeroad_boar", hips=("Boar_Rear",), neck=("Boar_Neck",), head=("Boar_Head",),
        shoulder=("Boar_Front_Leg{s}",), elbow=("Boar_Forearm{s}",), wrist=("Boar_Front_Foot{s}",),
        hip=("Boar_Back_Leg{s}",), ankle=("Boar_Back_Foot{s}",), sides=(("_Left", "_Right"),)),
    # SuperTuxKart's beach characters (``arm.L``, ``arm_1.L``, ``leg_1.L``, ``feet.L``).
    _convention(
        "stk_beach", hips=("body",), head=("head",), shoulder=("arm{s}",), elbow=("arm_1{s}",), wrist=("hand{s}",),
        hip=("leg{s}",), knee=("leg_1{s}",), ankle=("feet{s}",), requires=("arm_1{s}",)),
    # 0 A.D. dogs, wolf and fox: FrontLeg1..3, BackLeg1..3.
    _convention(
        "zeroad_canid", hips=("Fox_pelvis", "mastiff", "spine1"), neck=("Neck1", "Fox_Neck1"),
        head=("Head", "Fox_head"),
        shoulder=("FrontLeg1{s}", "Fox_FrontLeg1{s}"), elbow=("FrontLeg2{s}", "Fox_FrontLeg2{s}"),
        wrist=("FrontLeg3{s}", "Fox_FrontLeg3{s}"), hip=("BackLeg1{s}", "Fox_BackLeg1{s}", "Fox_Fox_BackLeg1{s}"),
        knee=("BackLeg2{s}", "Fox_BackLeg2{s}"), ankle=("BackLeg3{s}", "Fox_BackLeg3{s}"), sides=(("_L", "_R"),)),
    # 0 A.D. camels and giraffes: ``left_f_leg_top`` (front), ``left_r_leg_top`` (rear).
    _convention(
        "zeroad_camelid", hips=("main_pelvis",), neck=("neck_01",), head=("head",), shoulder=("{s}f_leg_top",),
        elbow=("{s}f_leg_mid",), wrist=("{s}f_leg_bottom",), hip=("{s}r_leg_top",), knee=("{s}r_leg_mid",),
        ankle=("{s}r_leg_bottom",), sides=(("left_", "right_"),)),
    # OpenClonk's Clonks.
    _convention(
        "openclonk", hips=("skeleton_hips", "skeleton_body"), neck=("skeleton_neck",), head=("skeleton_head",),
        shoulder=("skeleton_arm_upper{s}",), elbow=("skeleton_arm_lower{s}",), wrist=("skeleton_arm_hand{s}",),
        hip=("skeleton_leg_upper{s}",), knee=("skeleton_leg_lower{s}",), ankle=("skeleton_foot_ball{s}",)),
    # SuperTuxKart's monkey (``Bone.Arm_Upper.L``).
    _convention(
        "stk_bone", hips=("Bone.Hips", "Bone.Spine"), neck=("Bone.Neck",), head=("Bone.Head",),
        shoulder=("Bone.Arm_Upper{s}",), elbow=("Bone.Arm_Lower{s}",), wrist=("Bone.Hand{s}",),
        hip=("Bone.Leg_Upper{s}",), knee=("Bone.Leg_Lower{s}",), ankle=("Bone.Foot{s}",)),
    # MakeHuman's default skeleton (the bundled CC0 body).
    _convention(
        "makehuman", hips=("root",), neck=("neck01",), head=("head",), shoulder=("upperarm01{s}",),
        elbow=("lowerarm01{s}",), wrist=("wrist{s}",), hip=("upperleg01{s}",), knee=("lowerleg01{s}",),
        ankle=("foot{s}",), requires=("upperleg01{s}",)),
    # Kenney's mini characters: one bone per arm and leg.
    _convention(
        "kenney", hips=("torso",), head=("head",), shoulder=("arm{s}",), hip=("leg{s}",),
        sides=(("-left", "-right"),), requires=("arm{s}",)),
    # Godot's platformer demo (``l-forearm``).
    _convention(
        "godot_platformer", hips=("hip",), neck=("neck",), head=("head",), shoulder=("{s}arm",),
        elbow=("{s}forearm",), wrist=("{s}hand",), hip=("{s}thigh",), knee=("{s}leg",), ankle=("{s}foot",),
        sides=(("l-", "r-"),)),
    # Assimp's test character (``B_UpperArm_Left``).
    _convention(
        "assimp_bcn", hips=("B_Root_Pelvis_L",), neck=("B_Neck",), head=("B_Head",), shoulder=("B_UpperArm{s}",),
        elbow=("B_ForeArm{s}",), wrist=("B_Hand{s}",), hip=("B_Hip{s}",), knee=("B_Knee{s}",),
        ankle=("B_Ankle{s}",), sides=(("_Left", "_Right"),)),
)


@dataclass(frozen=True)
class KeyJoints:
    """Key joints found in a skeleton.

    Attributes
    ----------
    convention : str, the convention that found them ("" for none)
    bones : dict mapping each found role of :data:`KEY_JOINTS` to the bone index
    positions : dict mapping each found role to its (3,) position (the bone's head)
    """

    convention: str
    bones: dict
    positions: dict


def key_joints(names, joints, left_direction=None, parents=None) -> KeyJoints:
    """The key joints of a skeleton, read from its bone names.

    Parameters
    ----------
    names : sequence of str, bone names
    joints : (j, 3) array, bone heads
    parents : optional (j,) int array. When given and the rig's hips bone
        is not one the legs hang from, the hips are the joint they do hang
        from (:func:`leg_root`) if it lies nearer the hip joints: Quaternius'
        monsters put ``Hips`` below the hip joints beside the legs, which hang
        from ``Body`` at their height.
    left_direction : optional (3,) array, the character's left in the
        joints' space. When given, a pair of side roles whose ``.L`` joint
        lies further right than its ``.R`` twin is swapped: some artists
        name sides from the viewer (0 A.D.'s cattle), and a reference must
        say the character's own left.

    Returns
    -------
    KeyJoints from the convention that finds the most roles (the first listed
    on a tie); empty when none finds any.
    """
    joints = np.asarray(joints, dtype=np.float64).reshape(-1, 3)
    best_name, best = "", {}
    for convention in CONVENTIONS:
        found = convention.bone_names(names)
        if len(found) > len(best):
            best_name, best = convention.name, found
    if left_direction is not None:
        left_direction = np.asarray(left_direction, dtype=np.float64).reshape(3)
        for role in SIDE_ROLES:
            left, right = best.get(role + LEFT), best.get(role + RIGHT)
            if left is not None and right is not None and (joints[left] - joints[right]) @ left_direction < 0:
                best[role + LEFT], best[role + RIGHT] = right, left
    if parents is not None and "hip" + LEFT in best and "hip" + RIGHT in best:
        best = _hips_the_legs_hang_from(best, joints, np.asarray(parents, dtype=np.int64).reshape(-1))
    ordered = {role: best[role] for role in KEY_JOINTS if role in best}
    return KeyJoints(best_name, ordered, {role: joints[index].copy() for role, index in ordered.items()})


#: A joint is on the midline between the thighs when it lies within this
#: share of half their spacing from the plane halfway between them.
MIDLINE_SHARE = 0.25


def _hips_the_legs_hang_from(found: dict, joints: np.ndarray, parents: np.ndarray) -> dict:
    left, right = found["hip" + LEFT], found["hip" + RIGHT]
    hips = found.get("hips")
    if hips is not None and hips in ancestors(parents, left):
        return found
    root = leg_root(joints, parents, left, right)
    if root is None:
        return found
    middle = (joints[left] + joints[right]) / 2.0
    if hips is None or np.linalg.norm(joints[root] - middle) < np.linalg.norm(joints[hips] - middle):
        found = {**found, "hips": root}
    return found


def leg_root(joints: np.ndarray, parents: np.ndarray, left_thigh: int, right_thigh: int):
    """The first ancestor of the left thigh on the midline between the thighs, or None."""
    across = joints[left_thigh] - joints[right_thigh]
    half = float(np.linalg.norm(across)) / 2.0
    if half <= 0.0:
        return None
    across /= 2.0 * half
    middle = (joints[left_thigh] + joints[right_thigh]) / 2.0
    return next((joint for joint in ancestors(parents, left_thigh)
                 if abs(float((joints[joint] - middle) @ across)) <= MIDLINE_SHARE * half), None)
