"""Garments: open sheets offset from the body (skirt, cape, blanket).

A garment either takes the body's weights at its closest body point
(:meth:`.character_builder.CharacterBuilder.cloth`, part type ``cloth``) or,
for skirts and capes, gets bone chains of its own placed on its surface,
outside the body, and weights that follow those bones (part type
``driven``).
"""

from __future__ import annotations

import numpy as np

from ..geometry.segments import polyline_arc_lengths
from ..skeleton.naming import LEFT_SUFFIX, chain_names, mirror_name
from .frames import Y, Z
from .part_weights import joint_blend_weights, sum_weight_blocks
from .parts import PART_DRIVEN, Part
from .polylines import cumulative_lengths
from .shapes import face_towards, grid_samples, grid_triangles, lathe, ring_segments

#: Gap between a clothing shell and the body, as a fraction of the skeleton's
#: bounding-box diagonal; each garment draws one value from this range.
CLOTH_GAP_RANGE = (0.006, 0.02)
#: Body shells of a biped that clothing wraps (arms and tails pass through garments).
BIPED_TRUNK = frozenset({"torso", "leg.L", "leg.R"})
#: Skirt bone chains around the waist (even counts keep the rig symmetric).
SKIRT_CHAIN_COUNTS = (4, 6, 8)


def _garment_gap(ch) -> float:
    return ch.uniform(*CLOTH_GAP_RANGE) * ch.size


def add_blanket(ch, front_bone: str, back_bone: str, half_width: float):
    """A cloth sheet draped over the torso's back between two spine bones."""
    y_front = ch.rig.head(front_bone)[1]
    y_back = ch.rig.head(back_bone)[1]
    rows = grid_samples(3, abs(y_back - y_front), ch.spacing)
    columns = grid_samples(3, 2 * half_width, ch.spacing)
    x, y = np.meshgrid(np.linspace(-half_width, half_width, columns), np.linspace(y_front, y_back, rows))
    grid = np.stack([x, y], axis=-1)
    z = ch.drape(grid, [0, 1], 2, _garment_gap(ch), {"torso"})
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    triangles = face_towards(vertices, grid_triangles(rows, columns), Z)
    ch.cloth("blanket", vertices, triangles, {"torso"})


def add_skirt(ch, driven: bool):
    """An open skirt on a biped from the waist down, offset from the body.

    ``driven``: give it two-bone chains of its own on its surface, around
    the waist; otherwise it takes the body's weights at the closest body point.
    """
    rig = ch.rig
    top, hem = rig.head("spine.001")[2], rig.head("shin.L")[2] + ch.uniform(-0.2, 0.5) * rig.length("thigh.L")
    centre_y = rig.head("spine")[1]
    gap = _garment_gap(ch)
    rows = grid_samples(3, top - hem, ch.spacing)
    heights = np.linspace(top, hem, rows)
    radii = np.array([ch.band_ellipse(z, ch.spacing, np.array([0.0, centre_y]), BIPED_TRUNK) for z in heights]) + gap
    radii = np.maximum.accumulate(radii, axis=0)  # flare out, never in, going down
    centres = np.column_stack([np.zeros(rows), np.full(rows, centre_y), heights])
    tangents = np.repeat(-Z[None], rows, axis=0)
    normals = np.repeat(-Y[None], rows, axis=0)
    segments = ring_segments(float(radii.max()), ch.spacing) + 4
    vertices, triangles, _ = lathe(centres, tangents, normals, radii[:, ::-1], segments)
    if not driven:
        ch.cloth("skirt", vertices, triangles, BIPED_TRUNK)
        return
    count = ch.pick(SKIRT_CHAIN_COUNTS)
    chains = []
    middle = rows // 2
    for k in range(count // 2 + 1):
        angle = 2.0 * np.pi * k / count
        on_centre = k == 0 or k == count // 2
        suffix = "" if on_centre else LEFT_SUFFIX
        points = centres[[0, middle, rows - 1]] + np.column_stack(
            [radii[[0, middle, rows - 1], 0] * np.sin(angle), -radii[[0, middle, rows - 1], 1] * np.cos(angle),
             np.zeros(3)]
        )
        if on_centre:
            points[:, 0] = 0.0
        names = rig.add_path(chain_names(f"skirt_{k:02d}", 2, suffix), points, "spine")
        chains.append((angle, names))
    rig.symmetrize()
    for angle, names in list(chains):
        if names[0].endswith(LEFT_SUFFIX):
            chains.append((-angle, [mirror_name(n) for n in names]))
    chains.sort(key=lambda item: item[0])
    chain_angles = np.array([a for a, _ in chains])
    vertex_angles = np.arctan2(vertices[:, 0], -(vertices[:, 1] - centre_y))
    # Periodic linear interpolation between the two chains around each vertex.
    wrapped = np.concatenate([chain_angles, [chain_angles[0] + 2 * np.pi]])
    position = np.interp(np.mod(vertex_angles - chain_angles[0], 2 * np.pi) + chain_angles[0], wrapped,
                         np.arange(len(wrapped)))
    lower = np.floor(position).astype(np.int64)
    upper_share = position - lower
    blocks = []
    for k, (_, names) in enumerate(chains):
        share = (np.where(lower % len(chains) == k, 1.0 - upper_share, 0.0)
                 + np.where((lower + 1) % len(chains) == k, upper_share, 0.0))
        polyline = rig.path_points(names)
        along = joint_blend_weights(polyline_arc_lengths(vertices, polyline), cumulative_lengths(polyline), ch.blend,
                                    True, False)
        blocks.append((["spine"] + names, along * share[:, None]))
    names, weights = sum_weight_blocks(blocks)
    ch.add_part(Part("skirt", PART_DRIVEN, False, vertices, triangles, names, weights))


def add_cape(ch, driven: bool):
    """An open cape on a biped, hanging behind the back from the shoulders.

    ``driven``: give it a three-bone chain of its own down its middle;
    otherwise it takes the body's weights at the closest body point.
    """
    rig = ch.rig
    top = rig.head("spine.004")[2]
    bottom = max(rig.head("shin.L")[2] - ch.uniform(0.0, 0.6) * rig.length("shin.L"), 0.05 * top)
    half_width = ch.uniform(0.9, 1.3) * abs(rig.head("upper_arm.L")[0])
    rows = grid_samples(3, top - bottom, ch.spacing)
    columns = 2 * (grid_samples(2, half_width, ch.spacing) // 2) + 1
    x, z = np.meshgrid(np.linspace(-half_width, half_width, columns), np.linspace(top, bottom, rows))
    gap = _garment_gap(ch)
    y = ch.drape(np.stack([x, z], axis=-1), [0, 2], 1, gap, BIPED_TRUNK | {"head"})
    y = np.maximum.accumulate(y, axis=0)  # hang straight down past the buttocks
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    triangles = face_towards(vertices, grid_triangles(rows, columns), Y)
    if not driven:
        ch.cloth("cape", vertices, triangles, BIPED_TRUNK | {"head"})
        return
    centre_column = vertices.reshape(rows, columns, 3)[:, columns // 2]
    joints = centre_column[np.linspace(0, rows - 1, 4).round().astype(int)]
    names = rig.add_path(chain_names("cape", 3), joints, "spine.003")
    weights = joint_blend_weights(polyline_arc_lengths(vertices, joints), cumulative_lengths(joints), ch.blend,
                                  True, False)
    ch.add_part(Part("cape", PART_DRIVEN, False, vertices, triangles, tuple(["spine.003"] + names), weights))
