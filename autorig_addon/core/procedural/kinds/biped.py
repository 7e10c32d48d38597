"""Bipeds: the Rigify basic human with random proportions, optional fingers,
a tail (tailed humanoids), clothes and gear."""

from __future__ import annotations

import numpy as np

from .. import templates
from ..accessories import add_eyes, add_helmet_or_hat, add_ponytail
from ..cloth import BIPED_TRUNK, add_cape, add_skirt
from ..frames import Y, Z, axis_frame, normalized
from ..heads import Ellipsoid, vertical_head
from ..parts import PART_BODY
from ..random_parameters import SIZE_RANGE
from ..shapes import box_geometry, ellipsoid_geometry, prism_geometry, ring_segments, torus_geometry
from ..tubes import round_radii, scaled_radii, tapered_radii

#: Random factors of the biped's proportions (1 = Rigify basic human).
BIPED_PROPORTIONS = {
    "leg": (0.65, 1.3), "arm": (0.75, 1.3), "torso": (0.8, 1.25), "neck": (0.5, 1.8), "head": (0.8, 1.8),
    "hand": (0.8, 1.4), "foot": (0.8, 1.3), "shoulder": (0.7, 1.4), "hips": (0.75, 1.35),
    "thickness": (0.65, 1.5), "limb_thickness": (0.7, 1.4),
}
#: How far the arms hang below horizontal in the rest pose (0 = T-pose), degrees.
BIPED_ARM_DROP_DEG = (0.0, 50.0)
#: Largest forward bend of the elbow and outward spread of the legs at rest, degrees.
BIPED_ELBOW_BEND_DEG = 25.0
BIPED_LEG_SPREAD_DEG = 10.0
#: Shell semi-axes in template metres, at the joints of each chain.
BIPED_TORSO_RADII = ((0.115, 0.16), (0.105, 0.15), (0.10, 0.135), (0.115, 0.165), (0.075, 0.10), (0.055, 0.055),
                     (0.055, 0.055))
BIPED_TORSO_BULGE = (0.0, 0.0, 0.05, 0.12, 0.0, 0.0)
BIPED_ARM_RADII = ((0.045, 0.045), (0.052, 0.052), (0.04, 0.04), (0.03, 0.03))
BIPED_ARM_BULGE = (0.0, 0.08, 0.1)
BIPED_HAND_RADII = ((0.02, 0.038), (0.016, 0.036))  # (thickness, width)
BIPED_LEG_RADII = ((0.085, 0.085), (0.055, 0.055), (0.04, 0.04))
BIPED_LEG_BULGE = (0.1, 0.15)
BIPED_FOOT_RADII = ((0.042, 0.045), (0.025, 0.042), (0.016, 0.032))  # (height, width)
BIPED_FINGER_RADIUS = 0.009
#: Head semi-axes (across, front-back, up) as fractions of the head bone.
BIPED_HEAD_RADII = (0.48, 0.55, 0.6)
#: Fingers: name, place across the hand (-1 little finger side .. 1 thumb side), phalanx lengths (template metres).
BIPED_FINGERS = (
    ("f_index", 0.6, (0.032, 0.022, 0.018)),
    ("f_middle", 0.2, (0.035, 0.024, 0.019)),
    ("f_ring", -0.2, (0.033, 0.022, 0.018)),
    ("f_pinky", -0.6, (0.026, 0.018, 0.015)),
)
BIPED_THUMB_LENGTHS = (0.025, 0.02, 0.018)


def _add_finger_bones(ch):
    """Rigify-named finger chains on the left hand (template metres)."""
    rig = ch.rig
    wrist, knuckles = rig.head("hand.L"), rig.tail("hand.L")
    along = normalized(knuckles - wrist)
    palm_normal = normalized(Z - np.dot(Z, along) * along)
    thumb_side = normalized(np.cross(along, palm_normal))
    half_width = BIPED_HAND_RADII[1][1]
    names = []
    for base, place, lengths in BIPED_FINGERS:
        direction = normalized(along + 0.2 * place * thumb_side)
        directions = [normalized(direction - 0.15 * k * palm_normal) for k in range(3)]
        chain = [f"{base}.{k + 1:02d}.L" for k in range(3)]
        rig.add_chain(chain, knuckles + place * half_width * thumb_side, directions, lengths, "hand.L")
        names.append(chain)
    thumb_direction = normalized(0.6 * along + 0.8 * thumb_side - 0.3 * palm_normal)
    chain = [f"thumb.{k + 1:02d}.L" for k in range(3)]
    start = wrist + 0.35 * (knuckles - wrist) + 0.7 * half_width * thumb_side
    rig.add_chain(chain, start, [thumb_direction] * 3, BIPED_THUMB_LENGTHS, "hand.L")
    names.append(chain)
    return names


def build_biped(ch, tail_bones: int = 0) -> str:
    """A humanoid (with a tail of ``tail_bones`` bones when not 0); returns the variant."""
    factor = {name: ch.uniform(*limits) for name, limits in BIPED_PROPORTIONS.items()}
    lengths = {
        "spine": factor["torso"], "spine.001": factor["torso"], "spine.002": factor["torso"],
        "spine.003": factor["torso"],
        "spine.004": factor["neck"], "spine.005": factor["neck"], "spine.006": factor["head"],
        "thigh.L": factor["leg"], "shin.L": factor["leg"], "upper_arm.L": factor["arm"], "forearm.L": factor["arm"],
        "hand.L": factor["hand"], "foot.L": factor["foot"], "toe.L": factor["foot"], "heel.02.L": factor["foot"],
        "shoulder.L": factor["shoulder"],
    }
    lateral = {"thigh.L": factor["hips"], "shoulder.L": factor["shoulder"], "upper_arm.L": factor["shoulder"]}
    keep = {row[0] for row in templates.HUMAN}
    with_breasts = ch.chance("breasts")
    if not with_breasts:
        keep.discard("breast.L")
    root = ch.maybe_root()
    ch.place_template(templates.HUMAN, lengths, lateral, keep, root)
    rig = ch.rig
    rig.set_tail("shoulder.L", rig.head("upper_arm.L"))
    elevation = np.arcsin(np.clip(rig.direction("upper_arm.L")[2], -1, 1))
    rig.raise_subtree("upper_arm.L", -np.radians(ch.uniform(*BIPED_ARM_DROP_DEG)) - elevation)
    rig.rotate_subtree("forearm.L", Z, -np.radians(ch.uniform(0.0, BIPED_ELBOW_BEND_DEG)))
    rig.rotate_subtree("thigh.L", Y, -np.radians(ch.uniform(0.0, BIPED_LEG_SPREAD_DEG)))
    fingers = _add_finger_bones(ch) if ch.chance("fingers") else []
    tail = []
    if tail_bones:
        tail = rig.grow_tail("tail", "spine", rig.head("spine") + np.array([0.0, 0.08, 0.0]),
                             normalized([0.0, 1.0, -0.6]), ch.uniform(0.5, 1.2), tail_bones, ch.uniform(-12.0, 12.0))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["biped"]))
    thick = factor["thickness"] * unit
    limb = thick * factor["limb_thickness"]
    ch.settle()

    torso = ["spine", "spine.001", "spine.002", "spine.003", "spine.004", "spine.005"]
    ch.tube("torso", torso, scaled_radii(BIPED_TORSO_RADII, thick), up=-Y, child="spine.006", bulge=BIPED_TORSO_BULGE)
    head = vertical_head(rig, "spine.006", BIPED_HEAD_RADII, 0.45)
    ch.rigid("head", head.geometry(ch.spacing), "spine.006", PART_BODY)
    ch.tube("arm.L", ["shoulder.L", "upper_arm.L", "forearm.L"], scaled_radii(BIPED_ARM_RADII, limb), up=Z, mirror=True,
            bulge=BIPED_ARM_BULGE)
    ch.tube("hand.L", ["hand.L"], scaled_radii(BIPED_HAND_RADII, limb), up=Z, mirror=True)
    for chain in fingers:
        ch.tube(chain[0].split(".")[0] + ".L", chain, round_radii([1.0, 1.0, 1.0, 0.75], BIPED_FINGER_RADIUS * limb),
                up=Z, mirror=True)
    ch.tube("leg.L", ["thigh.L", "shin.L"], scaled_radii(BIPED_LEG_RADII, limb), up=-Y, mirror=True,
            bulge=BIPED_LEG_BULGE)
    ch.tube("foot.L", ["foot.L", "toe.L"], scaled_radii(BIPED_FOOT_RADII, limb), up=Z, mirror=True)
    if with_breasts:
        radii = np.array([0.6, 0.45, 0.55]) * rig.length("breast.L")
        ch.rigid("breast.L", ellipsoid_geometry(rig.point_along("breast.L", 0.55), radii, np.eye(3), ch.spacing),
                 "breast.L", PART_BODY, mirror=True)
    if tail:
        ch.tube("tail", tail, tapered_radii(len(tail), (1.0, 0.25), 0.05 * thick), up=Z)
    _add_gear(ch, head)
    return "tailed_humanoid" if tail else "humanoid"


def _add_gear(ch, head: Ellipsoid):
    """Eyes, headwear, belt, buttons, backpack, sword, shield, garments, hair."""
    rig = ch.rig
    height = rig.points()[:, 2].max()
    if ch.chance("eyes"):
        add_eyes(ch, head, "spine.006")
    add_helmet_or_hat(ch, head, "spine.006")
    if ch.chance("belt"):
        waist = rig.head("spine.001")
        radii = ch.band_ellipse(waist[2], ch.spacing, waist[:2], BIPED_TRUNK)
        minor = ch.uniform(0.008, 0.02) * height
        ch.rigid("belt", torus_geometry(waist, radii + 0.5 * minor, minor, np.eye(3), ch.spacing), "spine.001")
    if ch.chance("buttons"):
        count = ch.integer(2, 6)
        low, high = rig.head("spine.002")[2], rig.tail("spine.003")[2] - 0.3 * rig.length("spine.003")
        radius = ch.uniform(0.008, 0.015) * height
        for k, z in enumerate(np.linspace(low, high, count)):
            bone = "spine.002" if z < rig.head("spine.003")[2] else "spine.003"
            origin = np.array([0.0, rig.head(bone)[1], z])
            front = ch.extent_along(origin, -Y, 1.5 * ch.spacing, BIPED_TRUNK)
            centre = origin - (front + 0.2 * radius) * Y
            ch.rigid(f"button.{k:03d}",
                     ellipsoid_geometry(centre, np.array([radius, 0.5 * radius, radius]), np.eye(3), ch.spacing), bone)
    if ch.chance("backpack"):
        middle = rig.middle("spine.003")
        back = ch.extent_along(middle, Y, 1.5 * ch.spacing, BIPED_TRUNK)
        half = np.array([ch.uniform(0.08, 0.14), ch.uniform(0.04, 0.08), ch.uniform(0.1, 0.16)]) * height
        ch.rigid("backpack", box_geometry(middle + (back + 0.8 * half[1]) * Y, half, np.eye(3)), "spine.003")
    if ch.chance("sword"):
        _add_sword(ch, height)
    if ch.chance("shield"):
        forearm = rig.middle("forearm.L")
        radius = ch.uniform(0.1, 0.16) * height
        centre = forearm - (ch.extent_along(forearm, -Y, ch.spacing, {"arm.L"}) + 0.01 * height) * Y
        shield = prism_geometry(centre, 0.006 * height, (radius, radius), axis_frame(-Y, Z),
                                ring_segments(radius, ch.spacing))
        ch.rigid("shield", shield, "forearm.L")
    if ch.chance("skirt"):
        add_skirt(ch, driven=ch.chance("garment_bones"))
    if ch.chance("cape"):
        add_cape(ch, driven=ch.chance("garment_bones"))
    if ch.chance("ponytail"):
        add_ponytail(ch, head, "spine.006")


def _add_sword(ch, height):
    """A sword on a floating ``weapon`` bone held in the right hand."""
    rig = ch.rig
    grip = rig.tail("hand.R") + 0.3 * (rig.tail("hand.R") - rig.head("hand.R"))
    blade = ch.uniform(0.25, 0.45) * height
    rig.add("weapon", grip, grip - blade * Y, "hand.R")
    grip_radius, grip_half = 0.012 * height, 0.05 * height
    frame = axis_frame(-Y, Z)
    pieces = [
        prism_geometry(grip, grip_half, (grip_radius, grip_radius), frame, 6),
        box_geometry(grip - grip_half * Y, np.array([0.005, 0.06, 0.01]) * height, frame),
        box_geometry(grip - (grip_half + 0.5 * blade) * Y, np.array([0.004, 0.02, 0.5 * blade / height]) * height,
                     frame),
    ]
    for k, piece in enumerate(pieces):
        ch.rigid(f"sword.{k:03d}", piece, "weapon")
