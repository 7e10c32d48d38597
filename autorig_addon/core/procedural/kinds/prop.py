"""Props: a door, a desk lamp or a chest, made of rigid pieces on 1 to 4 bones."""

from __future__ import annotations

import numpy as np

from ..frames import X, Y, Z, axis_frame, normalized
from ..shapes import box_geometry, cone_geometry, prism_geometry, ring_segments, sphere_geometry

PROP_VARIANTS = ("door", "lamp", "chest")


def build_door(ch) -> str:
    """A door on a hinge bone, maybe in a frame and with a handle; returns the variant."""
    rig = ch.rig
    width, height, thickness = ch.uniform(0.6, 1.2), ch.uniform(1.8, 2.5), ch.uniform(0.03, 0.07)
    post = ch.uniform(0.05, 0.12)
    has_frame = ch.chance("door_frame")
    has_handle = ch.chance("door_handle")
    parent = None
    if has_frame:
        parent = rig.add("frame", [-0.5 * post, 0.0, 0.0], [-0.5 * post, 0.0, height], None)
    rig.add("door", [0.0, 0.0, 0.0], [0.0, 0.0, height], parent)
    knob = np.array([0.88 * width, -0.5 * thickness - 0.03, 0.45 * height])
    if has_handle:
        rig.add("handle", knob, knob - np.array([0.12, 0.0, 0.0]), "door")
    ch.settle()
    gap = 0.003
    ch.rigid("door", box_geometry([0.5 * width, 0.0, 0.5 * height],
                                  [0.5 * width - gap, 0.5 * thickness, 0.5 * height - gap], np.eye(3)), "door")
    if has_frame:
        depth = 1.5 * thickness
        post_height = 0.5 * (height + post)
        ch.rigid("frame_post_hinge", box_geometry([-0.5 * post, 0.0, post_height],
                                                  [0.5 * post, depth, post_height], np.eye(3)), "frame")
        ch.rigid("frame_post_latch", box_geometry([width + 0.5 * post, 0.0, post_height],
                                                  [0.5 * post, depth, post_height], np.eye(3)), "frame")
        ch.rigid("frame_lintel", box_geometry([0.5 * width, 0.0, height + 0.5 * post],
                                              [0.5 * width, depth, 0.5 * post], np.eye(3)), "frame")
    if has_handle:
        stem = prism_geometry(knob + np.array([0.0, 0.015, 0.0]), 0.015, (0.008, 0.008), axis_frame(Y, Z), 8)
        lever = box_geometry(knob - np.array([0.06, 0.0, 0.0]), [0.012, 0.06, 0.008], axis_frame(-X, Z))
        ch.rigid("handle_stem", stem, "handle")
        ch.rigid("handle_lever", lever, "handle")
    return "door"


def build_lamp(ch) -> str:
    """A desk lamp: base, one or two arms and a shade; returns the variant."""
    rig = ch.rig
    base_radius, base_height = ch.uniform(0.08, 0.15), ch.uniform(0.02, 0.05)
    rig.add("base", [0.0, 0.0, 0.0], [0.0, 0.0, base_height], None)
    lower = rig.add_chain(["arm_lower"], rig.tail("base"), [normalized([0.0, -ch.uniform(0.0, 0.6), 1.0])],
                          [ch.uniform(0.25, 0.5)], "base")
    arms = list(lower)
    if ch.chance("lamp_upper_arm"):
        arms += rig.add_chain(["arm_upper"], rig.tail("arm_lower"), [normalized([0.0, -1.0, ch.uniform(-0.3, 0.6)])],
                              [ch.uniform(0.2, 0.45)], "arm_lower")
    shade_length = ch.uniform(0.1, 0.2)
    rig.add_chain(["shade"], rig.tail(arms[-1]), [normalized([0.0, -0.6, -1.0])], [shade_length], arms[-1])
    ch.settle()
    ch.rigid("base", prism_geometry(np.array([0.0, 0.0, 0.5 * base_height]), 0.5 * base_height,
                                    (base_radius, base_radius), np.eye(3), ring_segments(base_radius, ch.spacing)),
             "base")
    rod = 0.012
    for arm in arms:
        ch.rigid(arm, prism_geometry(rig.middle(arm), 0.5 * rig.length(arm), (rod, rod),
                                     axis_frame(rig.direction(arm), X), 8), arm)
        ch.rigid(f"{arm}_joint", sphere_geometry(rig.head(arm), 1.8 * rod, ch.spacing), arm)
    ch.rigid("shade_joint", sphere_geometry(rig.head("shade"), 1.8 * rod, ch.spacing), "shade")
    mouth = ch.uniform(0.06, 0.12)
    direction = rig.direction("shade")
    ch.rigid("shade", cone_geometry(rig.tail("shade"), mouth, 0.9 * shade_length, axis_frame(-direction, X),
                                    ch.spacing), "shade")
    ch.rigid("bulb", sphere_geometry(rig.tail("shade") - 0.2 * shade_length * direction, 0.35 * mouth, ch.spacing),
             "shade")
    return "lamp"


def build_chest(ch) -> str:
    """A chest with a hinged lid and maybe a lock; returns the variant."""
    rig = ch.rig
    width, depth, height, lid = (ch.uniform(0.5, 1.0), ch.uniform(0.35, 0.6), ch.uniform(0.25, 0.45),
                                  ch.uniform(0.08, 0.2))
    rig.add("base", [0.0, 0.0, 0.0], [0.0, 0.0, height], None)
    rig.add("lid", [-0.5 * width, 0.5 * depth, height], [0.5 * width, 0.5 * depth, height], "base")
    has_lock = ch.chance("chest_lock")
    if has_lock:
        rig.add("lock", [0.0, -0.5 * depth - 0.01, height - 0.03], [0.0, -0.5 * depth - 0.01, height + 0.03], "base")
    ch.settle()
    ch.rigid("base", box_geometry([0.0, 0.0, 0.5 * height], [0.5 * width, 0.5 * depth, 0.5 * height], np.eye(3)),
             "base")
    ch.rigid("lid", box_geometry([0.0, 0.0, height + 0.5 * lid + 0.002], [0.5 * width, 0.5 * depth, 0.5 * lid],
                                 np.eye(3)), "lid")
    if has_lock:
        ch.rigid("lock", box_geometry([0.0, -0.5 * depth - 0.012, height], [0.03, 0.01, 0.04], np.eye(3)), "lock")
    return "chest"


def build_prop(ch) -> str:
    """A door, lamp or chest, as likely; returns the variant."""
    return {"door": build_door, "lamp": build_lamp, "chest": build_chest}[ch.pick(PROP_VARIANTS)](ch)
