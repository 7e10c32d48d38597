"""Dragons: a quadruped (:mod:`.quadruped`) with a long neck and tail,
membrane wings on finger chains, and back spikes."""

from __future__ import annotations

import numpy as np

from ...geometry.segments import polyline_arc_lengths
from ...skeleton.naming import chain_names
from ..accessories import add_spikes
from ..frames import Y, Z, normalized
from ..part_weights import joint_blend_weights, stack_weight_blocks, sum_weight_blocks
from ..parts import PART_BODY, Part
from ..polylines import cumulative_lengths, points_at_fractions, segment_lengths
from ..random_parameters import SIZE_RANGE
from ..shapes import face_towards, grid_samples, grid_triangles
from ..tubes import round_radii
from .quadruped import (
    QUADRUPED_PROPORTIONS,
    QUADRUPED_TORSO,
    QUADRUPED_TORSO_RADII,
    quadruped_body,
    quadruped_gear,
    quadruped_skeleton,
)

DRAGON_PROPORTIONS = dict(QUADRUPED_PROPORTIONS, neck=(1.2, 2.8), tail=(1.5, 3.0), head=(0.9, 1.5))
#: Bones in the tail chain.
DRAGON_TAIL_BONES = (6, 13)
#: Dragon wings: span as a multiple of the torso length, fingers per wing.
DRAGON_WING_SPAN = (1.0, 2.0)
DRAGON_FINGERS = (2, 5)
#: Membrane vertices across each gap between two fingers.
MEMBRANE_STRIP_SAMPLES = 4
#: The membrane starts this far along each finger, where the fingers have
#: spread apart (they all meet at the wrist).
MEMBRANE_START_FRACTION = 0.1


def _add_wing_bones(ch, factor):
    """Arm and finger chains of a membrane wing on the left (template metres)."""
    rig = ch.rig
    height, width = np.array(QUADRUPED_TORSO_RADII[4]) * factor["thickness"]
    middle = rig.middle("spine.008")
    attach = middle + np.array([0.5 * width, 0.0, 0.7 * height])
    torso_length = np.linalg.norm(rig.tail("spine.008") - rig.head("spine.004"))
    span = ch.uniform(*DRAGON_WING_SPAN) * torso_length
    arm = rig.add_chain(chain_names("wing", 2, ".L"), attach,
                        [normalized([1.0, 0.15, 0.5]), normalized([1.0, -0.25, -0.1])],
                        [0.3 * span, 0.35 * span], "spine.008")
    count = ch.integer(DRAGON_FINGERS[0], DRAGON_FINGERS[1])
    fingers = []
    for k in range(count):
        angle = np.radians(15.0 + 70.0 * k / max(count - 1, 1))
        direction = normalized([np.cos(angle), np.sin(angle), -0.15 - 0.1 * k])
        length = (0.55 - 0.08 * k) * span
        names = chain_names(f"wing_finger_{k + 1}", 2, ".L")
        fingers.append(rig.add_chain(names, rig.tail(arm[-1]), [direction, normalized(direction + 0.2 * Y)],
                                     [0.55 * length, 0.45 * length], arm[-1]))
    return arm, fingers


def _add_membrane(ch, fingers, flank_polyline, torso_bones):
    """An open wing membrane spanning the finger chains and the body flank;
    each vertex blends the weights of the two columns it lies between."""
    rig = ch.rig
    columns = [rig.path_points(chain) for chain in fingers] + [flank_polyline]
    longest = max(segment_lengths(c).sum() for c in columns)
    rows = grid_samples(4, longest, ch.spacing)
    fractions = np.linspace(MEMBRANE_START_FRACTION, 1.0, rows)
    column_points, column_weights = [], []
    for chain, polyline in zip(fingers, columns[:-1]):
        joint_arc = cumulative_lengths(polyline)
        weights = joint_blend_weights(fractions * joint_arc[-1], joint_arc, ch.blend, True, False)
        column_points.append(points_at_fractions(polyline, fractions))
        column_weights.append(([rig.deforming_parent(chain[0])] + list(chain), weights))
    flank = points_at_fractions(flank_polyline, fractions)
    torso_path = rig.path_points(torso_bones)
    column_points.append(flank)
    column_weights.append((list(torso_bones),
                           joint_blend_weights(polyline_arc_lengths(flank, torso_path), cumulative_lengths(torso_path),
                                               ch.blend, False, False)))
    grid_points, grid_weights = [], []
    for c in range(len(column_points) - 1):
        shares = np.linspace(0.0, 1.0, MEMBRANE_STRIP_SAMPLES + 1)
        shares = shares if c == len(column_points) - 2 else shares[:-1]
        for share in shares:
            grid_points.append((1.0 - share) * column_points[c] + share * column_points[c + 1])
            (names_a, weights_a), (names_b, weights_b) = column_weights[c], column_weights[c + 1]
            grid_weights.append(sum_weight_blocks([(names_a, (1.0 - share) * weights_a), (names_b, share * weights_b)]))
    # Vertices go row by row (a row = one fraction along every grid column);
    # the weight blocks come column by column, so reorder them the same way.
    vertices = np.stack(grid_points, axis=1).reshape(-1, 3)
    names, by_column = stack_weight_blocks(grid_weights)
    weights = by_column.reshape(len(grid_points), rows, len(names)).transpose(1, 0, 2).reshape(-1, len(names))
    triangles = face_towards(vertices, grid_triangles(rows, len(grid_points)), Z)
    ch.add_part(Part("wing_membrane.L", PART_BODY, False, vertices, triangles, names, weights), mirror=True)


def build_dragon(ch) -> str:
    """A winged quadruped; returns the variant."""
    factor, tail, ears = quadruped_skeleton(ch, DRAGON_PROPORTIONS, DRAGON_TAIL_BONES)
    arm, fingers = _add_wing_bones(ch, factor)
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["dragon"]), axis=1)
    ch.settle()
    cranium = quadruped_body(ch, factor, unit, tail, ears)
    rig = ch.rig
    height, width = np.array(QUADRUPED_TORSO_RADII[4]) * factor["thickness"] * unit
    ch.tube("wing_arm.L", arm, round_radii([0.12, 0.09, 0.06], height), up=Y, mirror=True)
    for chain in fingers:
        ch.tube(chain[0].replace(".L", "") + ".L", chain, round_radii([1.0, 0.8, 0.4], 0.04 * height), up=Z,
                mirror=True)
    hips = rig.head("spine.005") + np.array([0.5 * width, 0.0, 0.5 * height])
    flank = np.stack([rig.head(arm[0]), hips])
    _add_membrane(ch, fingers, flank, list(QUADRUPED_TORSO))
    quadruped_gear(ch, cranium, factor, unit)
    if ch.chance("spikes"):
        add_spikes(ch, ["spine.005", "spine.006", "spine.007"] + tail[: len(tail) // 2])
    return "dragon"
