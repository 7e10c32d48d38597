"""Body shells around bone chains: generalised cylinders with rounded caps.

A tube follows the path through a chain of bones with elliptical rings of
varying radius, spaced about one edge length apart, and closes each end with
a rounded cap. Where the chain bends sharply the tube is cut into shells that
overlap at the joint, so rings never fold through each other. Each ring takes
the bone it lies on, blended with its neighbour near a joint
(:func:`.part_weights.joint_blend_weights`).
"""

from __future__ import annotations

import numpy as np

from .frames import normalized, projected_normals
from .part_weights import joint_blend_weights, stack_weight_blocks
from .parts import Part
from .polylines import cumulative_lengths, segment_lengths
from .shapes import lathe, ring_segments

#: Rings in each rounded end cap of a tube, besides the pole.
CAP_RINGS = 2
#: Length of a rounded end cap as a fraction of the end ring's smaller radius.
CAP_LENGTH_FACTOR = 0.9
#: A chain bending more than this (degrees) at a joint becomes two
#: overlapping shells there, so rings do not fold through each other.
TUBE_SPLIT_ANGLE_DEG = 55.0


def scaled_radii(radii, scale) -> np.ndarray:
    """(k + 1, 2) ring semi-axes: a table of template radii times ``scale``."""
    return np.asarray(radii, dtype=np.float64) * scale


def round_radii(fractions, radius: float) -> np.ndarray:
    """(k + 1, 2) equal semi-axes (round rings): ``radius`` times each fraction."""
    return np.asarray(fractions, dtype=np.float64)[:, None] * np.array([radius, radius])


def tapered_radii(bone_count: int, ends, scale: float) -> np.ndarray:
    """(bone_count + 1, 2) round rings whose radius goes linearly from
    ``ends[0]`` to ``ends[1]`` (times ``scale``) along a chain."""
    return round_radii(np.linspace(ends[0], ends[1], bone_count + 1), scale)


def _radius_function(points, radii, bulge):
    """Ring semi-axes as a function of arc length along the path ``points``
    (k + 1, 3).

    ``radii`` is either (k + 1, 2) semi-axes at the joints (linear in
    between) or a callable mapping (r,) fractions of the path length to
    (r, 2); ``bulge`` (k,) adds a fraction of the radius at each bone's middle.
    """
    lengths = segment_lengths(points)
    joint_arc = cumulative_lengths(points)
    profile = radii if callable(radii) else None
    radii = None if profile else np.asarray(radii, dtype=np.float64)

    def radius_at(arc):
        bone = np.clip(np.searchsorted(joint_arc, arc, side="right") - 1, 0, len(lengths) - 1)
        fraction = np.clip((arc - joint_arc[bone]) / np.maximum(lengths[bone], 1e-12), 0.0, 1.0)
        if profile is not None:
            base = profile(np.clip(arc / joint_arc[-1], 0.0, 1.0))
        else:
            base = np.column_stack([np.interp(arc, joint_arc, radii[:, 0]), np.interp(arc, joint_arc, radii[:, 1])])
        return base * (1.0 + bulge[bone] * np.sin(np.pi * fraction))[:, None]

    return radius_at


def _bend_cuts(points) -> list:
    """Path joints where the tube is cut (its ends included): the joints
    bending more than :data:`TUBE_SPLIT_ANGLE_DEG`."""
    directions = normalized(np.diff(points, axis=0))
    bends = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", directions[:-1], directions[1:]), -1.0, 1.0)))
    return [0] + [k + 1 for k in np.flatnonzero(bends > TUBE_SPLIT_ANGLE_DEG)] + [len(points) - 1]


def tube_shell(points, arc_offset, radius_at, up, spacing):
    """One closed tube along a polyline, with rounded caps.

    Parameters
    ----------
    points : (k + 1, 3) float64 array
        The path.
    arc_offset : float
        Arc length of ``points[0]`` along the whole path ``radius_at`` knows.
    radius_at : callable
        (r,) arc lengths -> (r, 2) ring semi-axes (along the ring normal, across).
    up : (3,) float64 array
        Direction the first semi-axis points to, made perpendicular to the path.
    spacing : float
        Wanted edge length.

    Returns
    -------
    vertices : (n, 3) float64 array
    triangles : (t, 3) int64 array
    arc : (n,) float64 array
        Arc length along the whole path of each vertex's ring.
    """
    lengths = segment_lengths(points)
    per_bone = np.maximum(1, np.ceil(lengths / spacing).astype(np.int64))
    bone = np.repeat(np.arange(len(lengths)), per_bone)
    fraction = ((np.arange(per_bone.sum()) - np.repeat(np.cumsum(per_bone) - per_bone, per_bone))
                / np.repeat(per_bone, per_bone))
    bone = np.append(bone, len(lengths) - 1)
    fraction = np.append(fraction, 1.0)
    centres = points[bone] + fraction[:, None] * (points[bone + 1] - points[bone])
    arc = arc_offset + cumulative_lengths(points)[bone] + fraction * lengths[bone]
    forward = normalized(np.diff(centres, axis=0))
    tangents = np.vstack([forward[:1], normalized(forward[:-1] + forward[1:]), forward[-1:]])
    radii = radius_at(arc)
    normals = projected_normals(tangents, up)
    theta = 0.5 * np.pi * np.arange(1, CAP_RINGS + 1) / (CAP_RINGS + 1)
    start_length = CAP_LENGTH_FACTOR * radii[0].min()
    end_length = CAP_LENGTH_FACTOR * radii[-1].min()
    start_caps = centres[0] - np.outer(start_length * np.sin(theta[::-1]), tangents[0])
    end_caps = centres[-1] + np.outer(end_length * np.sin(theta), tangents[-1])
    all_centres = np.vstack([start_caps, centres, end_caps])
    all_radii = np.vstack([np.outer(np.cos(theta[::-1]), radii[0]), radii, np.outer(np.cos(theta), radii[-1])])
    all_tangents = np.vstack([np.repeat(tangents[:1], CAP_RINGS, 0), tangents, np.repeat(tangents[-1:], CAP_RINGS, 0)])
    all_normals = np.vstack([np.repeat(normals[:1], CAP_RINGS, 0), normals, np.repeat(normals[-1:], CAP_RINGS, 0)])
    all_arc = np.concatenate([np.full(CAP_RINGS, arc[0]), arc, np.full(CAP_RINGS, arc[-1])])
    segments = ring_segments(float(radii.max()), spacing)
    vertices, triangles, ring = lathe(
        all_centres, all_tangents, all_normals, all_radii, segments,
        centres[0] - start_length * tangents[0], centres[-1] + end_length * tangents[-1],
    )
    return vertices, triangles, all_arc[ring]


def tube_part(name, points, bones, radii, up, spacing, blend, part_type, parent=None, child=None, bulge=None) -> Part:
    """A closed shell around the path of ``bones``, weighted along them.

    Parameters
    ----------
    name : str
    points : (k + 1, 3) float64 array
        Joints of the path through the k ``bones``.
    bones : sequence of k str
    radii : (k + 1, 2) float64 array, or callable
        Ring semi-axes at each joint of the path: along ``up`` made
        perpendicular to the path, and across; linear in between.
        A callable maps (r,) fractions of the path length to (r, 2).
    up : (3,) float64 array
    spacing : float
        Wanted edge length.
    blend : float
        Half-width of a joint region as a fraction of the shorter bone.
    part_type : str
    parent : str or None
        Bone the first bone blends into at the path start.
    child : str or None
        Bone the last bone blends into at the path end.
    bulge : (k,) float64 array or None
        Extra fractional radius at the middle of each bone (muscle).

    Returns
    -------
    Part
        One shell, or several overlapping ones where the path bends sharply.
    """
    bulge = np.zeros(len(bones)) if bulge is None else np.asarray(bulge, dtype=np.float64)
    joint_arc = cumulative_lengths(points)
    radius_at = _radius_function(points, radii, bulge)
    cuts = _bend_cuts(points)
    vertex_blocks, triangle_blocks, weight_blocks, offset = [], [], [], 0
    for start, stop in zip(cuts[:-1], cuts[1:]):
        vertices, triangles, arc = tube_shell(points[start:stop + 1], joint_arc[start], radius_at, up, spacing)
        before = bones[start - 1] if start > 0 else parent
        after = bones[stop] if stop < len(bones) else child
        weights = joint_blend_weights(
            arc - joint_arc[start], joint_arc[start:stop + 1] - joint_arc[start], blend, before is not None,
            after is not None
        )
        names = (([before] if before is not None else []) + list(bones[start:stop])
                 + ([after] if after is not None else []))
        vertex_blocks.append(vertices)
        triangle_blocks.append(triangles + offset)
        weight_blocks.append((names, weights))
        offset += len(vertices)
    names, weights = stack_weight_blocks(weight_blocks)
    return Part(name, part_type, True, np.concatenate(vertex_blocks), np.concatenate(triangle_blocks), names, weights)
