"""Bone names of the standard biped skeleton for engines and mocap.

The standard skeleton (:mod:`..rigging.standard_skeleton`) is named as
Rigify's metarigs name their bones. Game engines and motion-capture
libraries expect their own humanoid names; a :data:`PRESETS` entry gives,
for each bone of the standard biped, the name under that convention:

* ``mixamo``: Mixamo's ``mixamorig:Hips``, ``mixamorig:LeftForeArm``, ...
  (the names its animations key);
* ``unreal``: Unreal's mannequin (``pelvis``, ``spine_01``, ``upperarm_l``,
  ``calf_l``, ``ball_l``, ``index_01_l``);
* ``unity``: Unity's Humanoid avatar bones (``Hips``, ``Chest``,
  ``LeftUpperArm``, ``LeftToes``), which Godot's ``SkeletonProfileHumanoid``
  shares (``godot``);
* ``vrm``: VRM 1.0's humanoid bones (``hips``, ``upperChest``,
  ``leftLowerLeg``).

:func:`renamed` turns a skeleton's names from any preset into another, so
the presets round-trip; bones a preset does not know (a prop, a tail)
keep their names. Quadrupeds keep Rigify's names: no engine profile above
names a four-legged body.
"""

from __future__ import annotations

from ..errors import InputError

#: The standard biped's bones in Rigify's names, the reference every preset maps.
RIGIFY_BONES = (
    "spine", "spine.001", "spine.002", "spine.003", "neck", "head",
    "shoulder.L", "upper_arm.L", "forearm.L", "hand.L", "thigh.L", "shin.L", "foot.L", "toe.L",
    "shoulder.R", "upper_arm.R", "forearm.R", "hand.R", "thigh.R", "shin.R", "foot.R", "toe.R",
)
#: Rigify's finger names (``..rigging.fingers.FINGER_NAMES``), each 3 bones
#: ``.01`` to ``.03``; a biped has them when its hands have separable fingers.
RIGIFY_FINGERS = ("thumb", "f_index", "f_middle", "f_ring", "f_pinky")
#: The finger bones, left hand then right, each finger knuckle to tip.
FINGER_BONES = tuple(f"{finger}.{joint:02d}{side}" for side in (".L", ".R") for finger in RIGIFY_FINGERS
                     for joint in (1, 2, 3))


def _sided(midline: tuple, limb: tuple, left: str, right: str, fingers: tuple) -> dict:
    """A preset's names in :data:`RIGIFY_BONES` then :data:`FINGER_BONES`
    order; ``limb`` holds ``{}`` where the side goes, ``fingers`` one name
    per bone of :data:`RIGIFY_FINGERS` (``{}`` for the side)."""
    names = list(midline) + [name.format(left) for name in limb] + [name.format(right) for name in limb]
    names += [name.format(left) for name in fingers] + [name.format(right) for name in fingers]
    return dict(zip(RIGIFY_BONES + FINGER_BONES, names))


def _finger_names(pattern: str, digits: tuple, joints: tuple, thumb_joints: tuple | None = None) -> tuple:
    """One name per finger bone: ``pattern`` formatted with ``side`` (left
    as ``{side}``), ``digit`` and ``joint``; the thumb's joints may differ."""
    return tuple(pattern.replace("{digit}", digit).replace("{joint}", joint)
                 for index, digit in enumerate(digits)
                 for joint in (thumb_joints if index == 0 and thumb_joints else joints))


_PHALANGES = ("Proximal", "Intermediate", "Distal")
_METACARPAL_THUMB = ("Metacarpal", "Proximal", "Distal")
_DIGITS = ("Thumb", "Index", "Middle", "Ring", "Little")


_MIXAMO = _sided(("mixamorig:Hips", "mixamorig:Spine", "mixamorig:Spine1", "mixamorig:Spine2", "mixamorig:Neck",
                  "mixamorig:Head"),
                 ("mixamorig:{}Shoulder", "mixamorig:{}Arm", "mixamorig:{}ForeArm", "mixamorig:{}Hand",
                  "mixamorig:{}UpLeg", "mixamorig:{}Leg", "mixamorig:{}Foot", "mixamorig:{}ToeBase"),
                 "Left", "Right",
                 _finger_names("mixamorig:{}Hand{digit}{joint}", ("Thumb", "Index", "Middle", "Ring", "Pinky"),
                               ("1", "2", "3")))
_UNREAL = _sided(("pelvis", "spine_01", "spine_02", "spine_03", "neck_01", "head"),
                 ("clavicle_{}", "upperarm_{}", "lowerarm_{}", "hand_{}", "thigh_{}", "calf_{}", "foot_{}", "ball_{}"),
                 "l", "r",
                 _finger_names("{digit}_{joint}_{}", ("thumb", "index", "middle", "ring", "pinky"), ("01", "02", "03")))
_UNITY = _sided(("Hips", "Spine", "Chest", "UpperChest", "Neck", "Head"),
                ("{}Shoulder", "{}UpperArm", "{}LowerArm", "{}Hand", "{}UpperLeg", "{}LowerLeg", "{}Foot", "{}Toes"),
                "Left", "Right", _finger_names("{}{digit}{joint}", _DIGITS, _PHALANGES))
_VRM = _sided(("hips", "spine", "chest", "upperChest", "neck", "head"),
              ("{}Shoulder", "{}UpperArm", "{}LowerArm", "{}Hand", "{}UpperLeg", "{}LowerLeg", "{}Foot", "{}Toes"),
              "left", "right", _finger_names("{}{digit}{joint}", _DIGITS, _PHALANGES, _METACARPAL_THUMB))

#: Preset name -> {Rigify name: preset name}, in the panel's order; Rigify first (the default).
PRESETS = {
    "rigify": {name: name for name in RIGIFY_BONES + FINGER_BONES},
    "mixamo": _MIXAMO,
    "unreal": _UNREAL,
    "unity": _UNITY,
    "vrm": _VRM,
    # Godot's profile names the thumb as VRM 1.0 does (metacarpal, proximal, distal).
    "godot": {**_UNITY, **{bone: _VRM[bone][0].upper() + _VRM[bone][1:] for bone in FINGER_BONES
                           if bone.startswith("thumb")}},
}
DEFAULT_PRESET = "rigify"
#: What the panel and ``--help`` say of each preset.
PRESET_LABELS = {
    "rigify": "Rigify (Blender's metarigs: spine, upper_arm.L)",
    "mixamo": "Mixamo (mixamorig:Hips, mixamorig:LeftArm)",
    "unreal": "Unreal mannequin (pelvis, upperarm_l)",
    "unity": "Unity Humanoid (Hips, LeftUpperArm)",
    "vrm": "VRM humanoid (hips, leftUpperArm)",
    "godot": "Godot SkeletonProfileHumanoid (Hips, LeftUpperArm)",
}


#: Each preset's short name, as the panel's menus show it.
PRESET_TITLES = {preset: label.split(" (")[0] for preset, label in PRESET_LABELS.items()}


def preset_of(names) -> str | None:
    """The preset whose names the skeleton uses most (at least its hips, an
    upper arm and a thigh), or None."""
    names = set(names)
    best, best_count = None, 0
    for preset, mapping in PRESETS.items():
        found = sum(1 for name in mapping.values() if name in names)
        needed = (mapping["spine"], mapping["upper_arm.L"], mapping["thigh.L"])
        if all(name in names for name in needed) and found > best_count:
            best, best_count = preset, found
    return best


def renamed(names, preset: str) -> dict:
    """Old name -> new name for the bones of a standard biped skeleton named
    by any preset, to be named by ``preset``; bones no preset knows are left out.

    Raises
    ------
    InputError for an unknown preset, or a skeleton that is not a standard
    biped under any preset (a quadruped, a free-form skeleton).
    """
    if preset not in PRESETS:
        raise InputError(f"Unknown bone-name preset '{preset}': use one of {', '.join(PRESETS)}.")
    current = preset_of(names)
    if current is None:
        raise InputError("Only a standard biped skeleton can take engine bone names (its bones named as one of "
                         f"{', '.join(PRESETS)}); predict it with the Biped template first.")
    source, target = PRESETS[current], PRESETS[preset]
    present = set(names)
    return {source[bone]: target[bone] for bone in RIGIFY_BONES + FINGER_BONES if source[bone] in present}



def preset_names(names, preset: str) -> tuple[tuple, bool]:
    """The skeleton's names under ``preset``, and whether they could be given:
    a skeleton that is not a standard biped keeps its names.

    Raises
    ------
    InputError for an unknown preset.
    """
    names = tuple(names)
    if preset not in PRESETS:
        raise InputError(f"Unknown bone-name preset '{preset}': use one of {', '.join(PRESETS)}.")
    try:
        mapping = renamed(names, preset)
    except InputError:
        return names, False
    return tuple(mapping.get(name, name) for name in names), True
