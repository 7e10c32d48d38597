"""Optional pieces shared by several kinds: eyes, helmets and hats, horns,
back spikes, collars, saddles and hair.

Most are rigid (moved by exactly one bone); the ponytail hangs on bones of
its own. Each function draws its own numbers from the builder ``ch``
(a :class:`.character_builder.CharacterBuilder`) and adds the parts.
"""

from __future__ import annotations

import numpy as np

from ..skeleton.naming import LEFT_SUFFIX, chain_names
from .frames import X, Y, Z, axis_frame, normalized
from .heads import Ellipsoid
from .parts import PART_DRIVEN
from .shapes import (
    box_geometry,
    cone_geometry,
    ellipsoid_geometry,
    prism_geometry,
    ring_segments,
    sphere_geometry,
    torus_geometry,
)
from .tubes import round_radii

#: Eye radius as a fraction of the head's smallest semi-axis.
EYE_SIZE_RANGE = (0.12, 0.3)
#: How far apart the eyes sit: sideways component of the gaze direction.
EYE_SPREAD_RANGE = (0.25, 0.9)


def add_eyes(ch, head: Ellipsoid, bone: str, forward=-Y):
    """Two spheres on the head surface, one per side, each moved only by
    ``bone``. A ``.L`` bone is an eye bone of its own: it is moved to the
    eye's centre, looking out, and its ``.R`` twin moves the right eye."""
    radius = ch.uniform(*EYE_SIZE_RANGE) * head.radii.min()
    direction = normalized(forward + ch.uniform(*EYE_SPREAD_RANGE) * X + ch.uniform(0.1, 0.5) * Z)
    surface = head.surface_point(direction)
    centre = surface - 0.4 * radius * direction
    centre[0] = max(centre[0], 1.05 * radius)
    geometry = sphere_geometry(centre, radius, ch.spacing)
    if bone.endswith(LEFT_SUFFIX):
        ch.rig.place(bone, centre, centre + 2.0 * radius * direction)
    ch.rigid("eye.L", geometry, bone, mirror=True)


def add_helmet_or_hat(ch, head: Ellipsoid, bone: str):
    """Maybe a helmet (a dome cut flat), else maybe a hat (crown and brim)."""
    if ch.chance("helmet"):
        radii = head.radii * ch.uniform(1.08, 1.2)
        cut = np.arccos(ch.uniform(-0.1, 0.3))
        ch.rigid("helmet", ellipsoid_geometry(head.centre, radii, np.eye(3), ch.spacing, cut), bone)
    elif ch.chance("hat"):
        top = head.centre + np.array([0.0, 0.0, 0.75 * head.radii[2]])
        crown_height = ch.uniform(0.5, 1.5) * head.radii[2]
        crown_radius = ch.uniform(0.6, 0.9) * head.radii[0]
        segments = ring_segments(crown_radius, ch.spacing)
        crown = prism_geometry(top + [0, 0, 0.5 * crown_height], 0.5 * crown_height, (crown_radius, crown_radius),
                               np.eye(3), segments)
        ch.rigid("hat", crown, bone)
        brim_radius = ch.uniform(1.3, 2.0) * head.radii[0]
        brim = prism_geometry(top, 0.04 * head.radii[2], (brim_radius, brim_radius), np.eye(3),
                              ring_segments(brim_radius, ch.spacing))
        ch.rigid("hat_brim", brim, bone)


def add_horns(ch, head: Ellipsoid, bone: str):
    """A cone on each side of the head, rooted inside it."""
    root = head.surface_point(np.array([ch.uniform(0.3, 0.8), -ch.uniform(0.0, 0.6), 1.0]))
    direction = normalized(np.array([ch.uniform(0.1, 0.8), ch.uniform(-0.6, 0.6), 1.0]))
    length = ch.uniform(0.5, 2.0) * head.radii.max()
    radius = ch.uniform(0.12, 0.3) * head.radii.min()
    base = root - 0.3 * length * direction
    ch.rigid("horn.L", cone_geometry(base, radius, 1.3 * length, axis_frame(direction, X), ch.spacing), bone,
             mirror=True)


def add_spikes(ch, bones):
    """A cone on the back over the middle of each bone, moved by that bone."""
    height_scale = ch.uniform(0.5, 1.5)
    for k, bone in enumerate(bones):
        middle = ch.rig.middle(bone)
        top = ch.extent_along(middle, Z, 2.0 * ch.spacing)
        if top <= 0.0:
            continue
        height = height_scale * max(top, ch.spacing)
        radius = 0.35 * height
        base = middle + (top - 0.25 * height) * Z
        direction = normalized(Z + 0.4 * ch.rig.direction(bone))
        ch.rigid(f"spike.{k:03d}", cone_geometry(base, radius, height, axis_frame(direction, X), ch.spacing), bone)


def add_collar(ch, bone: str, radii: np.ndarray):
    """A ring around a neck bone's head; ``radii`` (2,) of the neck there."""
    direction = ch.rig.direction(bone)
    minor = 0.25 * radii.min()
    frame = axis_frame(direction, Z)
    centre = ch.rig.head(bone) + 0.3 * ch.rig.length(bone) * direction
    ch.rigid("collar", torus_geometry(centre, radii + minor, minor, frame, ch.spacing), bone)


def add_saddle(ch, bone: str, size: float):
    """A box on the torso's back over the middle of ``bone``."""
    middle = ch.rig.middle(bone)
    top = ch.extent_along(middle, Z, 2.0 * ch.spacing, {"torso"})
    half = np.array([0.6, 0.8, 0.25]) * size
    ch.rigid("saddle", box_geometry(middle + (top + 0.5 * half[2]) * Z, half, np.eye(3)), bone)


def add_ponytail(ch, head: Ellipsoid, bone: str):
    """A hair chain hanging from the back of the head on its own bones."""
    start = head.centre + np.array([0.0, 0.8 * head.radii[1], 0.3 * head.radii[2]])
    length = ch.uniform(1.0, 3.0) * head.radii[2]
    directions = [normalized([0.0, 0.8, -0.3]), normalized([0.0, 0.35, -1.0]), normalized([0.0, 0.1, -1.0])]
    names = ch.rig.add_chain(chain_names("hair", 3), start, directions, [0.3 * length, 0.35 * length, 0.35 * length],
                             bone)
    radius = ch.uniform(0.2, 0.4) * head.radii[0]
    ch.tube("ponytail", names, round_radii([1.0, 0.9, 0.7, 0.3], radius), up=Y, part_type=PART_DRIVEN)
