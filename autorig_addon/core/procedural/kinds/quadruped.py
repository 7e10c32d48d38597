"""Quadrupeds: the Rigify basic quadruped with random proportions, a grown
tail, ears and gear. Its skeleton, body and gear also make the dragon
(:mod:`.dragon`)."""

from __future__ import annotations

import numpy as np

from .. import templates
from ..accessories import add_collar, add_eyes, add_horns, add_saddle
from ..cloth import add_blanket
from ..frames import Y, Z, normalized
from ..heads import Ellipsoid, head_ellipsoid
from ..parts import PART_BODY
from ..random_parameters import SIZE_RANGE
from ..tubes import scaled_radii, tapered_radii

#: Random factors of the quadruped's proportions (1 = Rigify basic quadruped).
QUADRUPED_PROPORTIONS = {
    "body": (0.75, 1.35), "neck": (0.6, 2.5), "head": (0.7, 1.6), "leg": (0.6, 1.6),
    "width": (0.75, 1.3), "thickness": (0.75, 1.5), "tail": (0.3, 2.2),
}
#: Bones in the tail chain.
QUADRUPED_TAIL_BONES = (2, 6)
#: Neck raise and head pitch at rest, degrees.
QUADRUPED_NECK_RAISE_DEG = (-10.0, 35.0)
QUADRUPED_HEAD_PITCH_DEG = (-25.0, 10.0)
#: Shell semi-axes (height, width) in template metres at the joints of each chain.
QUADRUPED_TORSO_RADII = ((0.12, 0.10), (0.14, 0.12), (0.16, 0.13), (0.16, 0.13), (0.15, 0.12), (0.12, 0.10))
QUADRUPED_NECK_RADII = ((0.10, 0.08), (0.075, 0.065), (0.065, 0.06))
QUADRUPED_SNOUT_RADII = ((0.065, 0.055), (0.035, 0.03))
QUADRUPED_HIND_LEG_RADII = ((0.085, 0.085), (0.06, 0.06), (0.035, 0.035), (0.03, 0.03), (0.025, 0.025))
QUADRUPED_FRONT_LEG_RADII = ((0.07, 0.07), (0.065, 0.065), (0.045, 0.045), (0.03, 0.03), (0.028, 0.028), (0.025, 0.025))
QUADRUPED_TAIL_RADII = (0.045, 0.012)
#: Cranium semi-axes (across, up, along) as fractions of the head bone.
QUADRUPED_CRANIUM_RADII = (0.36, 0.38, 0.45)
#: Spine bones of the torso, hips to chest.
QUADRUPED_TORSO = ("spine.004", "spine.005", "spine.006", "spine.007", "spine.008")


def quadruped_skeleton(ch, proportions, tail_bones):
    """Place the quadruped template with proportions drawn from
    ``proportions``, grow a tail of ``tail_bones`` (low, high) bones and
    maybe ears. Returns the drawn factors, the tail and the ear bones."""
    factor = {name: ch.uniform(*limits) for name, limits in proportions.items()}
    lengths = {name: factor["body"] for name in QUADRUPED_TORSO}
    lengths.update({"spine.009": factor["neck"], "spine.010": factor["neck"], "spine.011": factor["head"]})
    for name in ("thigh.L", "shin.L", "foot.L", "toe.L", "shoulder.L", "front_thigh.L", "front_shin.L", "front_foot.L",
                 "front_toe.L"):
        lengths[name] = factor["leg"]
    lateral = {"thigh.L": factor["width"], "shoulder.L": factor["width"]}
    root = ch.maybe_root()
    ch.place_template(templates.QUADRUPED, lengths, lateral, None, root)
    rig = ch.rig
    rig.set_tail("shoulder.L", rig.head("front_thigh.L"))
    rig.raise_subtree("spine.009", np.radians(ch.uniform(*QUADRUPED_NECK_RAISE_DEG)))
    rig.raise_subtree("spine.011", np.radians(ch.uniform(*QUADRUPED_HEAD_PITCH_DEG)))
    count = ch.integer(tail_bones[0], tail_bones[1] + 1)
    tail = rig.grow_tail("tail", "spine.004", rig.head("spine.004"), normalized([0.0, 1.0, -0.34]),
                         0.45 * factor["tail"], count, ch.uniform(-6.0, 10.0))
    ears = []
    if ch.chance("ears"):
        cranium = head_ellipsoid(rig, "spine.011", QUADRUPED_CRANIUM_RADII, 0.25, np.sqrt(factor["thickness"]))
        root_point = cranium.centre + 0.8 * (cranium.surface_point(np.array([0.6, 0.3, 1.0])) - cranium.centre)
        length = ch.uniform(0.6, 2.0) * cranium.radii.max()
        direction = normalized([ch.uniform(0.2, 1.0), ch.uniform(0.0, 0.6), 1.0])
        ears = rig.add_chain(["ear.L"], root_point, [direction], [length], "spine.011")
    return factor, tail, ears


def quadruped_body(ch, factor, unit, tail, ears) -> Ellipsoid:
    """Body shells of a quadruped skeleton scaled by ``unit``; returns the cranium."""
    rig = ch.rig
    thick = factor["thickness"] * unit
    ch.tube("torso", list(QUADRUPED_TORSO), scaled_radii(QUADRUPED_TORSO_RADII, thick), up=Z,
            bulge=[0.0, 0.05, 0.05, 0.05, 0.0])
    ch.tube("neck", ["spine.009", "spine.010"], scaled_radii(QUADRUPED_NECK_RADII, thick), up=Z, child="spine.011")
    ch.tube("snout", ["spine.011"], scaled_radii(QUADRUPED_SNOUT_RADII, thick * np.sqrt(factor["head"])), up=Z)
    cranium = head_ellipsoid(rig, "spine.011", QUADRUPED_CRANIUM_RADII, 0.25, np.sqrt(factor["thickness"]))
    ch.rigid("cranium", cranium.geometry(ch.spacing), "spine.011", PART_BODY)
    ch.tube("tail", tail, tapered_radii(len(tail), QUADRUPED_TAIL_RADII, thick), up=Z)
    ch.tube("hind_leg.L", ["thigh.L", "shin.L", "foot.L", "toe.L"], scaled_radii(QUADRUPED_HIND_LEG_RADII, thick),
            up=-Y, mirror=True, bulge=[0.15, 0.05, 0.0, 0.0])
    ch.tube("front_leg.L", ["shoulder.L", "front_thigh.L", "front_shin.L", "front_foot.L", "front_toe.L"],
            scaled_radii(QUADRUPED_FRONT_LEG_RADII, thick), up=-Y, mirror=True)
    for ear in ears:
        width = 0.3 * rig.length(ear)
        ch.tube("ear.L", [ear], [(0.3 * width, width), (0.08 * width, 0.2 * width)], up=-Y, mirror=True)
    return cranium


def quadruped_gear(ch, cranium: Ellipsoid, factor, unit):
    """Eyes, horns, collar and a blanket or saddle."""
    if ch.chance("eyes"):
        add_eyes(ch, cranium, "spine.011")
    if ch.chance("horns"):
        add_horns(ch, cranium, "spine.011")
    if ch.chance("collar"):
        add_collar(ch, "spine.010", np.array(QUADRUPED_NECK_RADII[1][::-1]) * factor["thickness"] * unit * 1.1)
    if ch.chance("blanket"):
        add_blanket(ch, "spine.008", "spine.005", 1.4 * QUADRUPED_TORSO_RADII[3][1] * factor["thickness"] * unit)
    elif ch.chance("saddle"):
        add_saddle(ch, "spine.006", QUADRUPED_TORSO_RADII[3][1] * factor["thickness"] * unit)


def build_quadruped(ch) -> str:
    """A four-legged animal; returns the variant."""
    factor, tail, ears = quadruped_skeleton(ch, QUADRUPED_PROPORTIONS, QUADRUPED_TAIL_BONES)
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["quadruped"]), axis=1)
    ch.settle()
    cranium = quadruped_body(ch, factor, unit, tail, ears)
    quadruped_gear(ch, cranium, factor, unit)
    return "quadruped"
