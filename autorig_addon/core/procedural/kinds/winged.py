"""Winged creatures: birds (the Rigify bird, here) or dragons (:mod:`.dragon`)."""

from __future__ import annotations

import numpy as np

from .. import templates
from ..accessories import add_eyes
from ..frames import Y, Z, axis_frame
from ..heads import head_ellipsoid
from ..parts import PART_BODY
from ..random_parameters import SIZE_RANGE
from ..shapes import box_geometry
from ..tubes import scaled_radii
from .dragon import build_dragon

BIRD_PROPORTIONS = {
    "wing": (0.8, 1.8), "neck": (0.7, 2.5), "leg": (0.6, 2.2), "beak": (0.6, 2.5),
    "tail": (0.6, 1.8), "head": (0.8, 1.4), "thickness": (0.8, 1.4),
}
#: Wing raise at rest, degrees.
BIRD_WING_RAISE_DEG = (-20.0, 25.0)
#: Shell semi-axes in template metres (the Rigify bird is 0.2 m tall).
BIRD_TORSO_RADII = ((0.022, 0.02), (0.03, 0.026), (0.03, 0.026), (0.02, 0.018))  # (height, width)
BIRD_TAIL_RADII = ((0.016, 0.014), (0.01, 0.009), (0.006, 0.006), (0.004, 0.004))
BIRD_NECK_RADII = ((0.016, 0.015), (0.012, 0.012), (0.011, 0.011), (0.011, 0.011))
BIRD_UPPER_BEAK_RADII = ((0.006, 0.007), (0.004, 0.005), (0.001, 0.0012))
BIRD_LOWER_BEAK_RADII = ((0.004, 0.006), (0.003, 0.004), (0.001, 0.001))
BIRD_LEG_RADII = ((0.008, 0.008), (0.005, 0.005), (0.003, 0.003), (0.0025, 0.0025), (0.0015, 0.0015))
BIRD_WING_RADII = ((0.008, 0.008), (0.006, 0.012), (0.005, 0.016), (0.004, 0.014), (0.002, 0.006))  # (thickness, chord)
#: Head semi-axes (across, up, along) as fractions of the head bone.
BIRD_HEAD_RADII = (0.3, 0.32, 0.35)
#: Feather chord and thickness as fractions of the feather's length.
BIRD_FEATHER_SHAPE = (0.28, 0.04)
#: Probability that a winged character is a bird rather than a dragon.
BIRD_PROBABILITY = 0.5


def build_bird(ch) -> str:
    """A bird with box feathers on its wings and tail; returns the variant."""
    factor = {name: ch.uniform(*limits) for name, limits in BIRD_PROPORTIONS.items()}
    groups = {
        "wing": ("Wing.L", "Wing.001.L", "Wing.002.L", "w_feather.001.L", "w_feather.002.L", "w_feather.003.L",
                 "w_feather.004.L"),
        "neck": ("spine.006", "neck.001", "neck.002"), "leg": ("thigh.L", "shin.L", "foot.L", "toe.L"),
        "beak": ("beak.001.T", "beak.002.T", "beak.001.B", "beak.002.B"),
        "tail": ("spine.002", "spine.001", "spine", "t_feather.L"),
        "head": ("head",),
    }
    lengths = {bone: factor[group] for group, bones in groups.items() for bone in bones}
    root = ch.maybe_root()
    ch.place_template(templates.BIRD, lengths, None, None, root)
    rig = ch.rig
    rig.set_tail("shoulder.L", rig.head("Wing.L"))
    rig.raise_subtree("Wing.L", np.radians(ch.uniform(*BIRD_WING_RAISE_DEG)))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["bird"]))
    thick = factor["thickness"] * unit
    ch.settle()
    ch.tube("torso", ["spine.003", "spine.004", "spine.005"], scaled_radii(BIRD_TORSO_RADII, thick), up=Z,
            bulge=[0.15, 0.15, 0.1])
    ch.tube("tail", ["spine.002", "spine.001", "spine"], scaled_radii(BIRD_TAIL_RADII, thick), up=Z)
    ch.tube("neck", ["spine.006", "neck.001", "neck.002"], scaled_radii(BIRD_NECK_RADII, thick), up=-Y, child="head")
    head = head_ellipsoid(rig, "head", BIRD_HEAD_RADII, 0.25, factor["thickness"] / np.sqrt(factor["head"]))
    ch.rigid("head", head.geometry(ch.spacing), "head", PART_BODY)
    beak = thick * np.sqrt(factor["beak"])
    ch.tube("beak_upper", ["beak.001.T", "beak.002.T"], scaled_radii(BIRD_UPPER_BEAK_RADII, beak), up=Z)
    ch.tube("beak_lower", ["beak.001.B", "beak.002.B"], scaled_radii(BIRD_LOWER_BEAK_RADII, beak), up=Z)
    ch.tube("leg.L", ["thigh.L", "shin.L", "foot.L", "toe.L"], scaled_radii(BIRD_LEG_RADII, thick), up=-Y, mirror=True)
    ch.tube("wing.L", ["shoulder.L", "Wing.L", "Wing.001.L", "Wing.002.L"], scaled_radii(BIRD_WING_RADII, thick), up=Z,
            mirror=True)
    chord, thickness = BIRD_FEATHER_SHAPE
    for feather in ("w_feather.001.L", "w_feather.002.L", "w_feather.003.L", "w_feather.004.L", "t_feather.L"):
        length = rig.length(feather)
        box = box_geometry(rig.middle(feather), np.array([thickness, chord, 0.5]) * length,
                           axis_frame(rig.direction(feather), Z))
        ch.rigid(feather, box, feather, mirror=True)
    add_eyes(ch, head, "eye.L", forward=-0.4 * Y)
    return "bird"


def build_winged(ch) -> str:
    """A bird or a dragon, as likely; returns the variant."""
    return build_bird(ch) if ch.rng.random() < BIRD_PROBABILITY else build_dragon(ch)
