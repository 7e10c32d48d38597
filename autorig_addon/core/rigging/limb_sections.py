"""A biped's elbows, wrists and knees at the middle of their limb.

Artists put a limb's joints on the limb's axis, the middle of its
cross-section. The landmark network, on bodies unlike the training ones,
puts them off it: on Quaternius' big-headed characters it read the elbows
and wrists of arms held out level above the arm's axis (a median 0.047 of
the largest side for the elbows of the animated pack), some outside the
body, drawn up toward the head that hangs over the shoulders. Each joint is
moved, across its limb only, to the middle of the limb's outline in the
plane through it square to the limb (:mod:`..geometry.plane_section`,
exact on low-poly meshes whose long faces leave no vertex near the cut).
"""

from __future__ import annotations

import numpy as np

from ..geometry.plane_section import plane_section
from ..geometry.segments import paired_point_segment_distances
from ..skeleton.key_joints import LEFT, RIGHT
from ..types import Mesh

#: (from, joint, to) of each joint moved: the limb's direction at the joint
#: is the mean of the directions from ``from`` to the joint and from the
#: joint to ``to`` (the bend's bisector), or the first alone without ``to``.
CENTRED_JOINTS = (("shoulder", "elbow", "wrist"), ("elbow", "wrist", None), ("hip", "knee", "ankle"))
#: A joint farther than this share of its parent limb from the middle keeps its place: the cut missed the limb.
#: Set, not tuned: several limb radii, so a joint read on the limb's surface or just off it always moves.
MAX_MOVE = 0.6


def limb_joints_centred(points: dict, surface: Mesh) -> dict:
    """A biped's landmarks (``points``, by role) with the joints of
    :data:`CENTRED_JOINTS` moved across their limb to the middle of its
    outline on ``surface`` (the body's mesh, normalised as ``points``).
    In the order of :data:`CENTRED_JOINTS`: the wrist's cut is square to
    the forearm from the elbow already centred, the better axis (read from
    the elbow as the network put it, two of Quaternius' animated characters
    lost a wrist on validation)."""
    points = dict(points)
    for start, joint, end in CENTRED_JOINTS:
        for side, sign in ((LEFT, 1.0), (RIGHT, -1.0)):
            moved = _centred(points, start + side, joint + side, end and end + side, surface, sign)
            if moved is not None:
                points[joint + side] = moved
    return points


def _centred(points: dict, start: str, joint: str, end: str | None, surface: Mesh, sign: float):
    """Where ``joint`` goes (None to stay): see :func:`limb_joints_centred`;
    ``sign`` the side of x its limb lies on."""
    at = np.asarray(points[joint], dtype=np.float64)
    parent_limb = at - points[start]
    length = float(np.linalg.norm(parent_limb))
    if length <= 1e-9:
        return None
    direction = parent_limb / length
    if end is not None:
        child_limb = points[end] - at
        if np.linalg.norm(child_limb) > 1e-9:
            direction = direction + child_limb / np.linalg.norm(child_limb)
    if np.linalg.norm(direction) <= 1e-9:
        return None
    section = plane_section(surface, at, direction)
    # The limb is the piece of the outline (its loop) nearest the joint among those wholly on the limb's own side:
    # the cut also crosses the other leg, a hand's fingers, and the chest beside a hanging arm, or a skirt round
    # both legs, whose loops run across the middle.
    loop_count = int(section.loops.max()) + 1 if len(section.loops) else 0
    crosses_middle = np.zeros(loop_count, dtype=bool)
    crosses_middle[section.loops[sign * section.midpoints[:, 0] <= 0.0]] = True
    section = section.keep(~crosses_middle[section.loops])
    if not len(section.loops):
        return None
    distances = paired_point_segment_distances(np.broadcast_to(at, section.starts.shape), section.starts,
                                               section.ends)
    limb = section.loops == section.loops[np.argmin(distances)]
    lengths = section.lengths[limb]
    if lengths.sum() <= 0.0:
        return None
    middle = (section.midpoints[limb] * lengths[:, None]).sum(axis=0) / lengths.sum()
    return middle if np.linalg.norm(middle - at) <= MAX_MOVE * length else None
