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
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..skeleton.name_presets import DEFAULT_PRESET, preset_names
from ..types import Skeleton
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
