"""Long chains: snakes, tentacled creatures and ropes."""

from __future__ import annotations

import numpy as np

from ...skeleton.naming import chain_names
from ..accessories import add_eyes
from ..frames import Y, Z, axis_frame, normalized
from ..heads import Ellipsoid
from ..parts import PART_BODY
from ..polylines import resample_polyline
from ..random_parameters import SIZE_RANGE
from ..rig_builder import curling_directions, shrinking_lengths
from ..tubes import round_radii, tapered_radii

LONG_CHAIN_VARIANTS = ("snake", "tentacles", "rope")
#: Bones along a snake or rope; tentacles per side and bones per tentacle.
SNAKE_BONES = (10, 33)
ROPE_BONES = (12, 41)
TENTACLES_PER_SIDE = (2, 5)
TENTACLE_BONES = (6, 15)
#: Each tentacle bone is this fraction of the length of the one before.
TENTACLE_SHRINK = 0.92
#: Points the snake's and the rope's centre curves are sampled at before
#: the bones are spaced evenly along them.
CURVE_SAMPLES = 256


def build_snake(ch) -> str:
    """A snake along a sine wave on the ground; returns the variant."""
    rig = ch.rig
    root = ch.maybe_root()
    count = ch.integer(*SNAKE_BONES)
    amplitude, wavelength, phase = ch.uniform(0.0, 0.12), ch.uniform(0.3, 0.7), ch.uniform(0.0, 2 * np.pi)
    y = np.linspace(0.5, -0.5, CURVE_SAMPLES)
    curve = np.column_stack([amplitude * np.sin(2 * np.pi * y / wavelength + phase), y, np.zeros_like(y)])
    head_share = ch.uniform(0.03, 0.06)
    joints = resample_polyline(curve[: int(CURVE_SAMPLES * (1 - head_share))], count + 1)
    names = rig.add_path(chain_names("spine", count), joints, root)
    rig.add("head", joints[-1], curve[-1], names[-1])
    radius = ch.uniform(0.012, 0.03)
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["long_chain"]), axis=None)
    rig.transform_all(lambda p: p + np.array([0.0, 0.0, radius * unit]))
    ch.settle()
    r = radius * unit
    position = np.linspace(0.0, 1.0, count + 1)
    profile = np.interp(position, [0.0, 0.25, 0.85, 1.0], [0.12, 1.0, 1.0, 0.75])
    ch.tube("body", names, profile[:, None] * np.array([0.85 * r, r]), up=Z, child="head")
    head = Ellipsoid(rig.middle("head"), np.array([0.9 * r, 1.3 * r, max(0.55 * rig.length("head"), 1.2 * r)]),
                     axis_frame(rig.direction("head"), Z))
    ch.rigid("head", head.geometry(ch.spacing), "head", PART_BODY)
    if ch.chance("eyes"):
        add_eyes(ch, head, "head", forward=rig.direction("head") * 0.6)
    return "snake"


def build_tentacles(ch) -> str:
    """An upright mantle with curling tentacles on both sides; returns the variant."""
    rig = ch.rig
    root = ch.maybe_root()
    body = rig.add_chain(chain_names("body", 2), [0.0, 0.0, 0.0], [Z, Z], [0.5, 0.5], root)
    per_side = ch.integer(*TENTACLES_PER_SIDE)
    count = ch.integer(*TENTACLE_BONES)
    length, curl = ch.uniform(1.5, 3.5), ch.uniform(5.0, 20.0)
    lengths = shrinking_lengths(count, length, TENTACLE_SHRINK)
    tentacles = []
    for k in range(per_side):
        angle = np.pi * (k + 0.5) / per_side
        outward = np.array([np.sin(angle), -np.cos(angle), 0.0])
        start = 0.3 * outward + np.array([0.0, 0.0, 0.1])
        direction = normalized(outward + np.array([0.0, 0.0, -0.8]))
        directions = curling_directions(direction, np.cross(outward, Z), -np.radians(curl), count)
        tentacles.append(rig.add_chain(chain_names(f"tentacle_{k + 1}", count, ".L"), start, directions, lengths,
                                       body[0]))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["long_chain"]), axis=None)
    ch.settle()
    mantle = ch.uniform(0.35, 0.6) * unit
    ch.tube("mantle", body, round_radii([1.0, 1.1, 0.5], mantle), up=-Y, bulge=[0.2, 0.3])
    for chain in tentacles:
        ch.tube(chain[0], chain, tapered_radii(len(chain), (0.22, 0.03), mantle), up=Z, mirror=True)
    if ch.chance("eyes"):
        add_eyes(ch, Ellipsoid(rig.head("body.001"), np.full(3, 1.1 * mantle), np.eye(3)), "body.001")
    return "tentacles"


def build_rope(ch) -> str:
    """A rope along a random smooth curve; returns the variant."""
    rig = ch.rig
    root = ch.maybe_root()
    count = ch.integer(*ROPE_BONES)
    t = np.linspace(0.0, 1.0, CURVE_SAMPLES)
    frequencies = ch.rng.uniform(0.5, 2.0, size=3)
    phases = ch.rng.uniform(0.0, 2 * np.pi, size=3)
    amplitudes = ch.rng.uniform(0.05, 0.25, size=3)
    curve = np.column_stack([amplitudes[k] * np.sin(2 * np.pi * frequencies[k] * t + phases[k]) for k in range(3)])
    curve[:, 1] += t
    names = rig.add_path(chain_names("segment", count), resample_polyline(curve, count + 1), root)
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["long_chain"]), axis=None)
    ch.settle()
    r = ch.uniform(0.008, 0.025) * unit
    profile = np.interp(np.linspace(0, 1, count + 1), [0.0, 0.05, 0.95, 1.0], [0.7, 1.0, 1.0, 0.7])
    ch.tube("rope", names, round_radii(profile, r), up=Z)
    return "rope"


def build_long_chain(ch) -> str:
    """A snake, tentacled creature or rope, as likely; returns the variant."""
    return {"snake": build_snake, "tentacles": build_tentacles, "rope": build_rope}[ch.pick(LONG_CHAIN_VARIANTS)](ch)
