"""Where each bone of Rigify's basic metarigs goes for a standard skeleton.

A standard skeleton (:mod:`.standard_skeleton`) has Rigify's layout and,
for the limbs, its names; Rigify's *Basic Human* and *Basic Quadruped*
metarigs number the midline as one ``spine`` chain and add bones we do not
predict (a heel across the back of each human foot, breasts and pelvis
helpers). :func:`metarig_placement` says where every bone of the metarig
goes, so the Blender side can add Rigify's own metarig (its rig types,
connections and options), move its bones there and let Rigify generate the
control rig:

* human: ``spine`` to ``spine.003`` as ours, ``spine.004`` and ``spine.005``
  our neck halved, ``spine.006`` our head; ``heel.02`` across the heel on
  the ground behind the ankle, a little wider than the foot is long times
  0.6 (the metarig's proportion); limbs as ours.
* quadruped: ``spine.004`` (hips) to ``spine.008`` our hips-to-neck spine
  in five, ``spine.009`` and ``spine.010`` our neck halved, ``spine.011``
  our head; the tail ``spine.003`` (at the hips) to ``spine`` (its tip)
  our tail in four, or left out with no tail; limbs as ours.

The breast and pelvis helpers are left out: they deform the chest and hips
only in Rigify's own proportions. Positions are in the skeleton's space.

A biped with fingers (:mod:`.fingers`) gets, as Rigify's full *Human*
metarig has them and the basic one has not, :func:`finger_bones`: per
side ``palm.01`` to ``palm.04`` (one per finger but the thumb, index
first) parented to ``hand``, each from :data:`PALM_START` of the way from
the wrist to its finger's knuckle to the knuckle, ``limbs.super_palm`` on
``palm.01``; ``thumb.01`` and ``f_index.01`` parented to ``palm.01``,
``f_middle.01`` to ``palm.02``, ``f_ring.01`` to ``palm.03``,
``f_pinky.01`` to ``palm.04``, ``.02`` and ``.03`` connected to the bone
before, ``limbs.super_finger`` on each ``.01``. Each bone's roll comes from
the hand's axes as the Human metarig has them: a palm's and a finger's Z
axis along the hand's X axis (toward the palm; mirrored on the right), the
thumb's Z axis against the hand's Z axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..skeleton.name_presets import DEFAULT_PRESET, preset_names
from ..types import Skeleton
from .fingers import FINGER_BONES, FINGER_NAMES, finger_bone_names
from .standard_skeleton import BIPED, QUADRUPED

#: Rigify's metarig of each kind (the operator ``object.armature_<name>_metarig_add``).
METARIGS = {BIPED: "basic_human", QUADRUPED: "basic_quadruped"}
#: Metarig bones never placed: removed from the metarig before generation.
HELPER_BONES = ("breast.L", "breast.R", "pelvis.L", "pelvis.R")
#: The quadruped metarig's tail, from the hips to the tip.
QUADRUPED_TAIL = ("spine.003", "spine.002", "spine.001", "spine")
#: Limb bones that keep their names, per kind.
LIMB_BONES = {
    BIPED: ("shoulder", "upper_arm", "forearm", "hand", "thigh", "shin", "foot", "toe"),
    QUADRUPED: ("shoulder", "front_thigh", "front_shin", "front_foot", "front_toe", "thigh", "shin", "foot", "toe"),
}
#: The human heel bone's half width and its distance behind the ankle, as
#: shares of the foot's length (ankle to ball, seen from above): the
#: metarig's 0.04 and 0.03 for a 0.13 foot.
HEEL_HALF_WIDTH, HEEL_BEHIND = 0.3, 0.25
#: A palm bone starts this share of the way from the wrist to its finger's
#: knuckle (the Human metarig's palm bones: 0.36 to 0.38).
PALM_START = 0.35
#: Rigify's rig types of the palm (on ``palm.01``) and of each finger (on its ``.01``).
PALM_RIG, FINGER_RIG = "limbs.super_palm", "limbs.super_finger"
#: Rigify parameters of each finger's ``.01`` bone. The Human metarig's
#: fingers are curled, so Rigify's automatic axis (the curl's plane) finds
#: the bend; a found finger may be straight or bent sideways, so the curl is
#: about the X axis that :attr:`MetarigBone.up` gives (toward the palm:
#: Rigify's ``X``, the automatic axis' own sign). IK location as the Human
#: metarig's.
FINGER_PARAMETERS = (("primary_rotation_axis", "X"), ("ik_local_location", False))
#: Rigify's bone collections for fingers (the Human metarig's): the controls, and the finger tweaks.
FINGER_COLLECTION, FINGER_DETAIL_COLLECTION = "Fingers", "Fingers (Detail)"
#: Rotation mode of the palm bones (the Human metarig's).
PALM_ROTATION_MODE = "YXZ"


@dataclass(frozen=True)
class MetarigBone:
    """A bone added to Rigify's basic metarig (:func:`finger_bones`).

    Attributes
    ----------
    name, parent : str
    head, tail : (3,) float64, in the skeleton's space
    connected : bool, its head on its parent's tail, connected
    rig_type : str, Rigify's rig type ("" for none)
    up : (axis, sign): its Z axis points along ``sign`` times the placed
        hand's ``axis`` (``"x"`` or ``"z"``) of the same side
    """

    name: str
    parent: str
    head: np.ndarray
    tail: np.ndarray
    connected: bool
    rig_type: str
    up: tuple


def skeleton_kind(names) -> str:
    """``biped`` or ``quadruped`` from a standard skeleton's bone names."""
    names = set(names)
    if {"front_thigh.L", "front_thigh.R", "thigh.L", "thigh.R"} <= names:
        return QUADRUPED
    if {"upper_arm.L", "upper_arm.R", "thigh.L", "thigh.R", "head", "neck"} <= names:
        return BIPED
    raise InputError("Rigify needs a standard biped or quadruped skeleton (bones named upper_arm.L, thigh.L, ... or "
                     "front_thigh.L, ...): predict the skeleton with the Biped or Quadruped template.")


def _split(start: np.ndarray, end: np.ndarray, count: int) -> list:
    return [start + (end - start) * step / count for step in range(count + 1)]


def metarig_placement(skeleton: Skeleton) -> tuple[str, dict, tuple]:
    """Where Rigify's metarig bones go for ``skeleton``.

    Returns
    -------
    (kind, placement, removed): ``placement`` maps each metarig bone to
    ``(head, tail)`` (3,) arrays; ``removed`` names the metarig's bones to
    delete.

    Raises
    ------
    InputError when the skeleton is not a standard biped or quadruped.
    """
    # A biped named for an engine is placed by its Rigify names.
    skeleton = Skeleton(skeleton.joints, skeleton.parents, preset_names(skeleton.names, DEFAULT_PRESET)[0],
                        skeleton.tails, skeleton.deform)
    kind = skeleton_kind(skeleton.names)
    index = {name: k for k, name in enumerate(skeleton.names)}

    def head(name):
        return skeleton.joints[index[name]]

    def tail(name):
        return skeleton.tails[index[name]]

    placement = {}
    for base in LIMB_BONES[kind]:
        for side in (".L", ".R"):
            if base + side in index:
                placement[base + side] = (head(base + side), tail(base + side))
    missing = [name for name in ("spine", "neck", "head") if name not in index]
    if missing:
        raise InputError(f"The skeleton has no {', '.join(missing)} bone; Rigify needs the standard skeleton's spine.")
    hips, neck, crown = head("spine"), head("neck"), tail("head")
    skull = head("head")
    removed = list(HELPER_BONES)
    if kind == BIPED:
        spine = [head(name) for name in ("spine", "spine.001", "spine.002", "spine.003")] + [neck]
        chain = ("spine", "spine.001", "spine.002", "spine.003")
        neck_points = _split(neck, skull, 2)
        for name, start, end in zip(chain + ("spine.004", "spine.005", "spine.006"), spine[:-1] + neck_points[:2]
                                    + [skull], spine[1:] + neck_points[1:] + [crown]):
            placement[name] = (start, end)
        for side, sign in ((".L", 1.0), (".R", -1.0)):
            ankle, ball = head("foot" + side), tail("foot" + side)
            length = max(float(np.linalg.norm((ball - ankle)[:2])), 1e-3)
            forward = (ball - ankle)[:2] / length
            centre = np.array([ankle[0], ankle[1], tail("toe" + side)[2]])
            centre[:2] -= forward * HEEL_BEHIND * length
            across = np.array([-forward[1], forward[0], 0.0]) * sign
            if across[0] * sign < 0:
                across = -across
            placement["heel.02" + side] = (centre - across * HEEL_HALF_WIDTH * length,
                                           centre + across * HEEL_HALF_WIDTH * length)
        return kind, placement, tuple(removed)
    torso = _split(hips, neck, 5)
    for step, name in enumerate(("spine.004", "spine.005", "spine.006", "spine.007", "spine.008")):
        placement[name] = (torso[step], torso[step + 1])
    neck_points = _split(neck, skull, 2)
    placement["spine.009"] = (neck_points[0], neck_points[1])
    placement["spine.010"] = (neck_points[1], neck_points[2])
    placement["spine.011"] = (skull, crown)
    if "tail" in index:
        tail_end = tail([name for name in skeleton.names if name.startswith("tail")][-1])
        points = _split(head("tail"), tail_end, len(QUADRUPED_TAIL))
        for step, name in enumerate(QUADRUPED_TAIL):
            placement[name] = (points[step], points[step + 1])
    else:
        removed += QUADRUPED_TAIL
    return kind, placement, tuple(removed)


def finger_bones(skeleton: Skeleton) -> tuple:
    """The palm and finger bones to add to Rigify's basic human metarig for
    ``skeleton``'s fingers (see the module docstring), parents first; empty
    without fingers.

    Returns
    -------
    tuple of MetarigBone
    """
    names = preset_names(skeleton.names, DEFAULT_PRESET)[0]
    index = {name: k for k, name in enumerate(names)}
    added = []
    for side, sign in ((".L", 1.0), (".R", -1.0)):
        hand = "hand" + side
        present = [finger for finger in FINGER_NAMES if finger_bone_names(finger, side)[0] in index]
        if hand not in index or not present:
            continue
        wrist = skeleton.joints[index[hand]]
        palms = {}
        for number, finger in enumerate((finger for finger in present if finger != FINGER_NAMES[0]), start=1):
            knuckle = skeleton.joints[index[finger_bone_names(finger, side)[0]]]
            palm = f"palm.{number:02d}{side}"
            palms[finger] = palm
            added.append(MetarigBone(palm, hand, wrist + PALM_START * (knuckle - wrist), knuckle.copy(), False,
                                     PALM_RIG if number == 1 else "", ("x", sign)))
        first_palm = f"palm.01{side}"
        for finger in present:
            thumb = finger == FINGER_NAMES[0]
            parent = first_palm if thumb else palms[finger]
            for number, name in enumerate(finger_bone_names(finger, side)[:FINGER_BONES]):
                k = index[name]
                added.append(MetarigBone(name, parent, skeleton.joints[k].copy(), skeleton.tails[k].copy(), number > 0,
                                         FINGER_RIG if number == 0 else "", ("z", -1.0) if thumb else ("x", sign)))
                parent = name
    return tuple(added)
