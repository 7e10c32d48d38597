"""Tailed creatures: theropods, lizards and tailed humanoids (a biped with a
tail, :mod:`.biped`)."""

from __future__ import annotations

import numpy as np

from ...skeleton.naming import chain_names
from ..accessories import add_eyes, add_horns, add_spikes
from ..frames import Y, Z, normalized
from ..heads import head_ellipsoid
from ..random_parameters import SIZE_RANGE
from ..tubes import scaled_radii, tapered_radii
from .biped import build_biped

TAILED_VARIANTS = ("theropod", "lizard", "tailed_humanoid")
#: Tail bones of tailed creatures, and of tailed humanoids.
TAILED_TAIL_BONES = (6, 15)
TAILED_HUMANOID_TAIL_BONES = (4, 11)
#: Shell semi-axes (height, width), in units of the hip height (theropod) or body length (lizard).
THEROPOD_TORSO_RADII = ((0.2, 0.17), (0.24, 0.2), (0.22, 0.18), (0.16, 0.14))
THEROPOD_NECK_RADII = ((0.12, 0.11), (0.09, 0.085), (0.08, 0.075))
THEROPOD_HEAD_RADII = ((0.11, 0.09), (0.05, 0.045))
THEROPOD_JAW_RADII = ((0.035, 0.07), (0.02, 0.035))
THEROPOD_LEG_RADII = ((0.13, 0.13), (0.075, 0.075), (0.045, 0.045), (0.035, 0.035), (0.025, 0.025))
THEROPOD_ARM_RADII = ((0.045, 0.045), (0.035, 0.035), (0.025, 0.025), (0.018, 0.018))
THEROPOD_TAIL_RADII = (0.17, 0.02)
LIZARD_TORSO_RADII = ((0.05, 0.07), (0.06, 0.09), (0.06, 0.09), (0.05, 0.07))
LIZARD_NECK_RADII = ((0.045, 0.06), (0.04, 0.05))
LIZARD_HEAD_RADII = ((0.04, 0.05), (0.015, 0.02))
LIZARD_LEG_RADII = ((0.03, 0.03), (0.022, 0.022), (0.016, 0.016), (0.01, 0.01))
LIZARD_TAIL_RADII = (0.05, 0.006)


def _grow_tail_and_settle(ch, droop, length_range, bend_range_deg):
    """Grow a tail back from the hips (``droop`` down per unit back; length
    and per-bone bend in degrees drawn from the ranges), scale the creature
    to its drawn length and mirror it. Returns the tail bones and the scale."""
    rig = ch.rig
    tail = rig.grow_tail("tail", "spine", rig.head("spine"), normalized([0.0, 1.0, -droop]), ch.uniform(*length_range),
                         ch.integer(*TAILED_TAIL_BONES), ch.uniform(*bend_range_deg))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["tailed"]), axis=1)
    ch.settle()
    return tail, unit


def build_theropod(ch) -> str:
    """A two-legged dinosaur with small arms and a long tail; returns the variant."""
    rig = ch.rig
    root = ch.maybe_root()
    torso, neck, head, legs, arms, thick = (ch.uniform(0.6, 1.0), ch.uniform(0.4, 1.0), ch.uniform(0.3, 0.5),
                                            ch.uniform(0.8, 1.2), ch.uniform(0.3, 1.0), ch.uniform(0.8, 1.3))
    spine = rig.add_chain(chain_names("spine", 3), [0.0, 0.0, 1.0],
                          [normalized([0, -1, 0.1]), normalized([0, -1, 0.2]), normalized([0, -1, 0.3])],
                          torso * np.array([0.36, 0.34, 0.3]), root)
    neck_bones = rig.add_chain(["spine.003", "spine.004"], rig.tail("spine.002"),
                               [normalized([0, -0.5, 1.0]), normalized([0, -0.8, 0.6])],
                               neck * np.array([0.5, 0.5]), "spine.002")
    rig.add_chain(["head"], rig.tail("spine.004"), [normalized([0, -1.0, -0.15])], [head], "spine.004")
    rig.add("jaw", rig.head("head") + np.array([0.0, -0.1 * head, -0.12 * head]),
            rig.tail("head") + np.array([0.0, 0.1 * head, -0.15 * head]), "head")
    leg = rig.add_chain(["thigh.L", "shin.L", "foot.L", "toe.L"], [0.15, 0.05, 0.95],
                        [normalized([0.05, -0.45, -1]), normalized([0, 0.5, -1]), normalized([0, -0.2, -1]),
                         normalized([0, -1, -0.05])],
                        legs * np.array([0.5, 0.5, 0.3, 0.18]), "spine")
    chest = rig.middle("spine.002")
    arm = rig.add_chain(["upper_arm.L", "forearm.L", "hand.L"], chest + np.array([0.12, 0.0, -0.12]),
                        [normalized([0.3, -0.5, -0.8]), normalized([0.1, -0.9, 0.1]), normalized([0, -1, -0.3])],
                        arms * np.array([0.2, 0.18, 0.08]), "spine.002")
    tail, unit = _grow_tail_and_settle(ch, 0.1, (1.0, 2.2), (-3.0, 4.0))
    scale = thick * unit
    ch.tube("torso", spine, scaled_radii(THEROPOD_TORSO_RADII, scale), up=Z, bulge=[0.05, 0.1, 0.05])
    ch.tube("neck", neck_bones, scaled_radii(THEROPOD_NECK_RADII, scale), up=Z, child="head")
    ch.tube("head", ["head"], scaled_radii(THEROPOD_HEAD_RADII, scale * np.sqrt(head / 0.4)), up=Z, bulge=[0.2])
    ch.tube("jaw", ["jaw"], scaled_radii(THEROPOD_JAW_RADII, scale * np.sqrt(head / 0.4)), up=Z)
    ch.tube("tail", tail, tapered_radii(len(tail), THEROPOD_TAIL_RADII, scale), up=Z)
    ch.tube("leg.L", leg, scaled_radii(THEROPOD_LEG_RADII, scale), up=-Y, mirror=True, bulge=[0.2, 0.1, 0.0, 0.0])
    ch.tube("arm.L", arm, scaled_radii(THEROPOD_ARM_RADII, scale), up=Z, mirror=True)
    snout = head_ellipsoid(rig, "head", (0.28, 0.3, 0.45), 0.3, thick)
    if ch.chance("eyes"):
        add_eyes(ch, snout, "head", forward=-0.5 * Y)
    if ch.chance("horns"):
        add_horns(ch, snout, "head")
    if ch.chance("spikes"):
        add_spikes(ch, spine + neck_bones + tail[: len(tail) // 2])
    return "theropod"


def build_lizard(ch) -> str:
    """A low, sprawling four-legged lizard; returns the variant."""
    rig = ch.rig
    root = ch.maybe_root()
    legs, thick = ch.uniform(0.7, 1.5), ch.uniform(0.8, 1.4)
    spine = rig.add_chain(chain_names("spine", 3), [0.0, 0.2, 0.2], [-Y] * 3, [0.15, 0.15, 0.15], root)
    neck = rig.add_chain(["spine.003"], rig.tail("spine.002"), [normalized([0, -1, 0.15])], [ch.uniform(0.06, 0.15)],
                         "spine.002")
    rig.add_chain(["head"], rig.tail("spine.003"), [normalized([0, -1, -0.05])], [ch.uniform(0.12, 0.2)], "spine.003")
    sprawl = [normalized([1.0, 0.1, -0.05]), normalized([0.1, 0.1, -1.0]), normalized([0.2, -0.8, -0.1])]
    hind = rig.add_chain(["thigh.L", "shin.L", "foot.L"], [0.06, 0.17, 0.19], sprawl,
                         legs * np.array([0.12, 0.12, 0.06]), "spine")
    front_sprawl = [normalized([1.0, -0.1, -0.05]), normalized([0.1, -0.1, -1.0]), normalized([0.2, -0.8, -0.1])]
    front = rig.add_chain(["upper_arm.L", "forearm.L", "hand.L"], rig.tail("spine.002") + np.array([0.06, 0.03, -0.01]),
                          front_sprawl, legs * np.array([0.1, 0.1, 0.05]), "spine.002")
    tail, unit = _grow_tail_and_settle(ch, 0.05, (0.6, 1.3), (-2.0, 2.0))
    scale = thick * unit
    ch.tube("torso", spine, scaled_radii(LIZARD_TORSO_RADII, scale), up=Z)
    ch.tube("neck", neck, scaled_radii(LIZARD_NECK_RADII, scale), up=Z, child="head")
    ch.tube("head", ["head"], scaled_radii(LIZARD_HEAD_RADII, scale), up=Z)
    ch.tube("tail", tail, tapered_radii(len(tail), LIZARD_TAIL_RADII, scale), up=Z)
    ch.tube("hind_leg.L", hind, scaled_radii(LIZARD_LEG_RADII, scale), up=Z, mirror=True)
    ch.tube("front_leg.L", front, scaled_radii(LIZARD_LEG_RADII, scale), up=Z, mirror=True)
    head = head_ellipsoid(rig, "head", (0.25, 0.2, 0.4), 0.3, thick)
    if ch.chance("eyes"):
        add_eyes(ch, head, "head", forward=-0.3 * Y)
    if ch.chance("spikes"):
        add_spikes(ch, spine + tail[: len(tail) // 2])
    return "lizard"


def build_tailed(ch) -> str:
    """A theropod, lizard or tailed humanoid, as likely; returns the variant."""
    variant = ch.pick(TAILED_VARIANTS)
    if variant == "theropod":
        return build_theropod(ch)
    if variant == "lizard":
        return build_lizard(ch)
    return build_biped(ch, tail_bones=ch.integer(*TAILED_HUMANOID_TAIL_BONES))
