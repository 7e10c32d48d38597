"""A biped's trunk joints between its front and its back.

Artists put the hips, the hip joints, the shoulders, the neck and the head
near the middle of the body front to back. Measured on the training
humanoids' own rigs (177, 2026-12-07) in the frame and solid the
prediction reads them in, on the line through each joint parallel to y, in
the run of the solid that holds it (1,121 of 1,227 joints; the others lie
outside it, as inside a dress whose solid is its shell): 90 % lie between
0.41 and 0.67 of the way from front to back (5th to 95th percentiles: hips
0.40 to 0.55, shoulders 0.43 to 0.59, hip joints 0.43 to 0.59, necks 0.44
to 0.71, heads 0.36 to 0.69). On bodies unlike the training ones the
landmark network reads them far off that: on Quaternius' monsters the
shoulders at a median 0.16 of the way back and the hip joints at 0.29 (the
artists': 0.47 and 0.63; on their meshes' own crossings), some in front of
the chest. Each such landmark is moved along y only, into
:data:`DEPTH_RANGE` of its run (:func:`.standard_skeleton.standard_skeleton`
does it first, and again for the shoulders once they are put on the arms'
axes, which may lie in front of the trunk's middle).
"""

from __future__ import annotations

import numpy as np

from .joint_features import SolidDepth

#: The landmarks moved (:func:`trunk_joints_in_depth`). Elbows, wrists,
#: knees and ankles are centred in their limb by :mod:`.limb_sections`.
DEPTH_ROLES = ("hips", "neck", "head", "shoulder.L", "shoulder.R", "hip.L", "hip.R")
#: Where between front (0) and back (1) of its run a joint may lie: a round
#: band about the middle, not tuned, and narrower than the training rigs'
#: spread for necks and heads (the module docstring); what justifies it is
#: how little it moves those rigs' own joints: more than 0.02 of the largest
#: side on 15 of 1,227 and more than 0.05 on 5 (the posed Nexuiz `lurk`'s
#: and `nexus`'s shoulders and `lurk`'s hip joint, 0.8 of the way back; the
#: hips of Quaternius' mech `George`, in front of its body), 0.082 at most.
DEPTH_RANGE = (0.4, 0.6)


def trunk_joints_in_depth(points: dict, solid: SolidDepth, roles: tuple = DEPTH_ROLES) -> dict:
    """A biped's landmarks (``points``, by role, normalised frame: facing
    -y) with each joint of ``roles`` (of :data:`DEPTH_ROLES`) moved along y into
    :data:`DEPTH_RANGE` of the run of ``solid`` it lies in. A joint in
    front of the body or behind it takes the nearest run; one in a gap
    between runs keeps its place: it may lie inside a hollow garment (a
    dress or a robe open at the hem leaves its solid a shell) or a trunk
    whose solid leaked."""
    points = dict(points)
    low, high = DEPTH_RANGE
    for role in roles:
        if role not in points:
            continue
        at = np.asarray(points[role], dtype=np.float64)
        run = _run_to_move_into(solid_runs_along_y(solid, at), float(at[1]))
        if run is None:
            continue
        front, back = run
        moved = at.copy()
        moved[1] = np.clip(at[1], front + low * (back - front), front + high * (back - front))
        points[role] = moved
    return points


def solid_runs_along_y(solid: SolidDepth, point: np.ndarray) -> list:
    """The (front, back) y intervals, front to back, where the line through
    ``point`` parallel to y runs inside ``solid`` (:attr:`.SolidDepth.inside_depth`
    deep): from the centre of the first cell inside to the centre of the last. The solid marks every cell the
    surface touches, so its outer faces lie up to a cell beyond the surface;
    the centres lie within half a cell of it. Empty beside the body or off
    the solid's grid."""
    count = solid.depth.shape[1]
    along = solid.origin[1] + (np.arange(count) + 0.5) * solid.cell_size
    line = np.column_stack([np.full(count, point[0]), along, np.full(count, point[2])])
    inside = np.concatenate([[False], solid.at(line) >= solid.inside_depth, [False]])
    edges = np.flatnonzero(np.diff(inside.astype(np.int8)))
    return [(float(along[start]), float(along[end - 1])) for start, end in zip(edges[::2], edges[1::2])]


def _run_to_move_into(runs: list, y: float):
    """The run of ``runs`` (front to back) holding ``y``, the first when
    ``y`` is in front of them all, the last when behind; None in a gap
    between runs or without runs."""
    if not runs:
        return None
    for run in runs:
        if run[0] <= y <= run[1]:
            return run
    if y < runs[0][0]:
        return runs[0]
    if y > runs[-1][1]:
        return runs[-1]
    return None
