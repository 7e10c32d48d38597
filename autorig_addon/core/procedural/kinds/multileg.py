"""Many-legged creatures: insects (3 leg pairs), spiders (4) and centipedes
(one pair per spine bone)."""

from __future__ import annotations

import numpy as np

from ...skeleton.naming import chain_names
from ..accessories import add_eyes
from ..frames import Y, Z, axis_frame, normalized
from ..heads import head_ellipsoid
from ..parts import PART_BODY
from ..random_parameters import SIZE_RANGE
from ..shapes import cone_geometry, ellipsoid_geometry
from ..tubes import round_radii, tapered_radii

MULTILEG_VARIANTS = ("insect", "spider", "centipede")
#: Leg segment elevations (degrees above horizontal) and shares of the leg length.
MULTILEG_LEG_ELEVATIONS_DEG = (-10.0, 40.0, -60.0, -80.0)
MULTILEG_LEG_SHARES = (0.1, 0.35, 0.38, 0.17)
CENTIPEDE_LEG_ELEVATIONS_DEG = (20.0, -50.0, -80.0)
CENTIPEDE_LEG_SHARES = (0.35, 0.4, 0.25)
#: Front legs point this far forward, back legs as far backward (degrees).
MULTILEG_LEG_YAW_DEG = 45.0
#: Leg pairs of a centipede.
CENTIPEDE_PAIRS = (6, 13)


def build_multileg(ch) -> str:
    """An insect, spider or centipede; returns the variant."""
    rig = ch.rig
    variant = ch.pick(MULTILEG_VARIANTS)
    root = ch.maybe_root()
    if variant == "centipede":
        pairs = ch.integer(*CENTIPEDE_PAIRS)
        body_radius = ch.uniform(0.025, 0.05)
        segment = 1.0 / pairs
        body = rig.add_chain(chain_names("spine", pairs), [0.0, -0.5, 0.0], [Y] * pairs, [segment] * pairs, root)
        rig.add("head", [0.0, -0.5, 0.0], [0.0, -0.5 - 1.5 * segment, 0.01], body[0])
        attach = [(name, rig.middle(name)) for name in body]
        leg_length, elevations, shares = ch.uniform(0.12, 0.3), CENTIPEDE_LEG_ELEVATIONS_DEG, CENTIPEDE_LEG_SHARES
        abdomen = []
        head_radii = (0.9, 0.6, 0.6)
    else:
        pairs = 3 if variant == "insect" else 4
        thorax = ch.uniform(0.22, 0.35) if variant == "insect" else ch.uniform(0.25, 0.35)
        body_radius = ch.uniform(0.07, 0.1) if variant == "insect" else ch.uniform(0.1, 0.15)
        rig.add("thorax", [0.0, -0.5 * thorax, 0.0], [0.0, 0.5 * thorax, 0.0], root)
        head_length = ch.uniform(0.12, 0.2) if variant == "insect" else ch.uniform(0.06, 0.1)
        rig.add("head", [0.0, -0.5 * thorax, 0.01], [0.0, -0.5 * thorax - head_length, 0.02], "thorax")
        count = ch.integer(2, 4) if variant == "insect" else 1
        abdomen_length = ch.uniform(0.35, 0.7)
        abdomen = rig.add_chain(chain_names("abdomen", count), rig.tail("thorax"),
                                [normalized([0.0, 1.0, ch.uniform(-0.3, 0.3)])] * count,
                                [abdomen_length / count] * count, "thorax")
        spots = np.linspace(-0.3, 0.3, pairs) * thorax
        attach = [("thorax", np.array([0.0, y, 0.0])) for y in spots]
        leg_length = ch.uniform(0.5, 1.1) if variant == "insect" else ch.uniform(0.9, 1.6)
        elevations, shares = MULTILEG_LEG_ELEVATIONS_DEG, MULTILEG_LEG_SHARES
        head_radii = (0.6, 0.5, 0.6) if variant == "insect" else (0.9, 0.7, 0.8)
    legs = []
    yaws = np.radians(np.linspace(MULTILEG_LEG_YAW_DEG, -MULTILEG_LEG_YAW_DEG, pairs))
    for k, ((parent, centre), yaw) in enumerate(zip(attach, yaws)):
        start = centre + np.array([0.6 * body_radius, 0.0, -0.2 * body_radius])
        directions = [np.array([np.cos(e) * np.cos(yaw), -np.cos(e) * np.sin(yaw), np.sin(e)])
                      for e in np.radians(elevations)]
        legs.append(rig.add_chain(chain_names(f"leg_{k + 1:02d}", len(shares), ".L"), start, directions,
                                  leg_length * np.array(shares), parent))
    antennae = []
    if variant != "spider" and ch.chance("antennae"):
        start = rig.tail("head") + np.array([0.3 * body_radius, 0.0, 0.3 * body_radius])
        length = ch.uniform(0.2, 0.6)
        antennae = rig.add_chain(chain_names("antenna", 2, ".L"), start,
                                 [normalized([0.4, -1.0, 0.7]), normalized([0.6, -1.0, 0.2])],
                                 [0.5 * length, 0.5 * length], "head")
    wings = []
    if variant == "insect" and ch.chance("insect_wings"):
        start = np.array([0.3 * body_radius, -0.1 * thorax, 0.9 * body_radius])
        wings = rig.add_chain(["wing.L"], start, [normalized([1.0, ch.uniform(0.3, 1.0), 0.15])],
                              [ch.uniform(0.5, 1.0)], "thorax")
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["multileg"]), axis=None)
    radius = body_radius * unit
    ch.settle()

    head = head_ellipsoid(rig, "head", head_radii, 0.5)
    ch.rigid("head", head.geometry(ch.spacing), "head", PART_BODY)
    if variant == "centipede":
        ch.tube("body", body, np.full((len(body) + 1, 2), radius) * np.array([0.8, 1.0]), up=Z)
    else:
        ch.tube("thorax", ["thorax"], [(0.8 * radius, radius), (0.9 * radius, radius)], up=Z, bulge=[0.2])
        profile = np.interp(np.linspace(0, 1, len(abdomen) + 1), [0.0, 0.4, 1.0],
                            [1.0, 1.6 if variant == "spider" else 1.3, 0.5])
        ch.tube("abdomen", abdomen, profile[:, None] * radius * np.array([0.9, 1.0]), up=Z, bulge=[0.15] * len(abdomen))
    leg_radius = ch.uniform(0.02, 0.04) * leg_length * unit
    for chain in legs:
        ch.tube(chain[0], chain, tapered_radii(len(chain), (1.0, 0.35), leg_radius), up=Z, mirror=True)
    if antennae:
        ch.tube("antenna.L", antennae, round_radii([1.0, 0.8, 0.5], 0.3 * leg_radius), up=Z, mirror=True)
    for wing in wings:
        length = rig.length(wing)
        frame = axis_frame(Z, rig.direction(wing))
        ch.rigid("wing.L",
                 ellipsoid_geometry(rig.middle(wing), np.array([0.5, 0.22, 0.015]) * length, frame, ch.spacing),
                 wing, mirror=True)
    if ch.chance("eyes"):
        add_eyes(ch, head, "head")
    if abdomen and ch.chance("stinger"):
        tip = abdomen[-1]
        length = 0.4 * rig.length(tip)
        ch.rigid("stinger", cone_geometry(rig.tail(tip) - 0.3 * length * rig.direction(tip), 0.3 * radius, 1.3 * length,
                                          axis_frame(rig.direction(tip), Z), ch.spacing), tip)
    return variant
