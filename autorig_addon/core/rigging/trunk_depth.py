"""A biped's trunk joints between its front and its back.

Artists put the hips, the hip joints, the shoulders, the neck and the head
near the middle of the body front to back. Measured on the training
humanoids' own rigs (177, 2026-12-07) in the frame and solid the
prediction reads them in, on the line through each joint parallel to y, in
the run of the solid that holds it (1,123 of 1,227 joints; the others lie
outside it, as inside a dress whose solid is its shell): 90 % lie between 0.42 and 0.66 of the way from
front to back (5th to 95th percentiles: hips 0.41 to 0.55, shoulders 0.44 to
0.58, hip joints 0.43 to 0.58, necks 0.45 to 0.69, heads 0.38 to 0.69). On
bodies unlike the training ones the landmark network reads them far off
that: on Quaternius' monsters the shoulders at a median 0.16 of the way back
and the hip joints at 0.29 (the artists': 0.47 and 0.63; on their meshes'
own crossings), some in front of the chest. Each such joint is moved along y only, into :data:`DEPTH_RANGE`
of its run.
"""

from __future__ import annotations

import numpy as np

from .joint_features import SolidDepth

#: The landmarks moved (:func:`trunk_joints_in_depth`). Elbows, wrists,
#: knees and ankles are centred in their limb by :mod:`.limb_sections`.
DEPTH_ROLES = ("hips", "neck", "head", "shoulder.L", "shoulder.R", "hip.L", "hip.R")
#: Where between front (0) and back (1) of its run a joint may lie: a band
#: about the middle, set from the training humanoids' rigs (the module
#: docstring), not tuned. Clamped into it, their own joints move more than
#: 0.02 of the largest side on 17 of 1,227 and more than 0.05 on 5 (the
#: posed Nexuiz `lurk`'s and `nexus`'s shoulders and `lurk`'s hip joint, at
#: 0.8 of the way back; the hips of Quaternius' mech `George`, in front of its
#: body), 0.081 at most.
DEPTH_RANGE = (0.4, 0.6)


def trunk_joints_in_depth(points: dict, solid: SolidDepth) -> dict:
    """A biped's landmarks (``points``, by role, normalised frame: facing
    -y) with each joint of :data:`DEPTH_ROLES` moved along y into
    :data:`DEPTH_RANGE` of the run of ``solid`` it lies in. A joint in
    front of the body or behind it takes the nearest run; one in a gap
    between runs keeps its place: it may lie inside a hollow garment (a
    dress or a robe open at the hem leaves its solid a shell) or a trunk
    whose solid leaked."""
    points = dict(points)
    low, high = DEPTH_RANGE
    for role in DEPTH_ROLES:
        if role not in points:
            continue
        at = np.asarray(points[role], dtype=np.float64)
        run = _enclosing_run(solid_runs_along_y(solid, at), float(at[1]))
        if run is None:
            continue
        front, back = run
        moved = at.copy()
        moved[1] = np.clip(at[1], front + low * (back - front), front + high * (back - front))
        points[role] = moved
    return points


def solid_runs_along_y(solid: SolidDepth, point: np.ndarray) -> list:
    """The (front, back) y intervals, front to back, where the line through
    ``point`` parallel to y runs inside ``solid`` (at least half a cell
    deep: inside, not in the interpolated fringe), to half a cell."""
    count = solid.depth.shape[1]
    along = solid.origin[1] + (np.arange(count) + 0.5) * solid.cell_size
    line = np.column_stack([np.full(count, point[0]), along, np.full(count, point[2])])
    inside = np.concatenate([[False], solid.at(line) >= 0.5 * solid.cell_size, [False]])
    edges = np.flatnonzero(np.diff(inside.astype(np.int8)))
    half = 0.5 * solid.cell_size
    return [(float(along[start] - half), float(along[end - 1] + half)) for start, end in zip(edges[::2], edges[1::2])]


def _enclosing_run(runs: list, y: float):
    """The run of ``runs`` holding ``y``, the first when ``y`` is in front
    of them all, the last when behind; None in a gap between runs or
    without runs."""
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
