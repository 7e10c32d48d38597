"""Whether a predicted skeleton is sound, checked as an animator would before success is reported.

:func:`skeleton_problems` looks at a skeleton beside the character's voxel
solid (normalised frame, largest side 1) and names what an animator would
reject at first sight:

* more than one tree (a part that would not follow the rest);
* a bone longer than the body;
* bones lying mostly outside the body (more than :data:`MAX_OUTSIDE_SHARE`
  of the points from a joint to a child joint where the solid has no depth,
  the surface (its triangles, not only its corners: a low-poly animal's
  vertices lie 0.1 of its length apart) is farther than
  :data:`FAR_FROM_SURFACE` and, when the caller
  can tell, the surface does not enclose them: an open mesh's solid is only
  its shell; a leaf's tail, only an estimate, is not checked);
* for a body named as a biped or quadruped (Rigify's role names, or an
  engine preset's): the legs' chains not meeting at the hips, the arms' (or
  front legs') not meeting on the spine above the hips, the head not above
  the hips (biped).

Artists' own rigs pass it: on the development set's 416 characters,
``scripts/check_skeleton_quality.py`` counts what it flags on the artists'
skeletons (its answer is in docs/bad_input.md).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..geometry.closest_point import TriangleMeshQuery
from ..geometry.winding import winding_numbers
from ..skeleton.hierarchy import ancestors
from ..skeleton.name_presets import DEFAULT_PRESET, preset_names
from ..types import Mesh, Skeleton

#: A bone lies mostly outside the body when more than this share of the
#: points along it are outside the solid.
MAX_OUTSIDE_SHARE = 0.5
#: A point outside the solid this far from the surface (share of the largest
#: side) is outside the body.
FAR_FROM_SURFACE = 0.1
#: Points sampled along each bone, ends excluded (a joint on the surface is fine).
BONE_SAMPLES = 9
#: A bone is longer than the body when it is longer than this share of the
#: largest side.
MAX_BONE_SHARE = 1.0
#: Bones named in a problem before the rest are only counted.
MAX_NAMED = 4


def _listed(names: list) -> str:
    shown = ", ".join(names[:MAX_NAMED])
    return shown + (f" and {len(names) - MAX_NAMED} more" if len(names) > MAX_NAMED else "")


def _meeting_joint(parents: np.ndarray, first: int, second: int):
    """The nearest joint both chains hang from (their lowest common ancestor), or None."""
    above_first = [first] + ancestors(parents, first)
    above_second = set([second] + ancestors(parents, second))
    return next((joint for joint in above_first if joint in above_second), None)


def _surface_distances(surface: Mesh, points: np.ndarray) -> np.ndarray:
    """(k,) distance of each point to ``surface``: to its triangles, or to its vertices when it has none."""
    if len(surface.triangles):
        return TriangleMeshQuery(surface.vertices, surface.triangles).closest(points).distances
    return cKDTree(surface.vertices).query(points)[0]


def skeleton_problems(skeleton: Skeleton, depth_at, surface: Mesh, enclosed=None) -> tuple:
    """What is wrong with ``skeleton`` (normalised frame), as sentences; empty when nothing is.

    Parameters
    ----------
    skeleton : Skeleton in the normalised frame (largest side 1)
    depth_at : callable, ``(k, 3) points -> (k,) depth`` of the character's
        solid (``SolidDepth.at``); 0 outside the body
    surface : Mesh, the character's surface (its proxy): a point outside the
        solid counts as outside the body only when it is also farther than
        :data:`FAR_FROM_SURFACE` from it, since an open shell (a dress, a
        cape, a helmet) has a solid one cell deep. Without triangles, its
        vertices stand for it
    enclosed : callable or None, ``(k, 3) points -> (k,) bool``: whether the
        character's surface encloses each point (``enclosed_by``): a point it
        encloses is inside the body whatever the solid says (an open mesh,
        whose solid leaked to its shell). None: the solid alone tells
    """
    problems = []
    parents = np.asarray(skeleton.parents)
    roots = int(np.count_nonzero(parents < 0))
    if roots != 1:
        problems.append(f"the skeleton is {roots} separate trees, not one")
    lengths = np.linalg.norm(skeleton.tails - skeleton.joints, axis=1)
    too_long = [name for name, length in zip(skeleton.names, lengths) if length > MAX_BONE_SHARE]
    if too_long:
        problems.append(f"{_listed(too_long)} {'is' if len(too_long) == 1 else 'are'} longer than the body")
    # Between each joint and its children's: a leaf's tail is only an estimate of where the part ends.
    children = parents[parents >= 0]
    steps = np.linspace(0.0, 1.0, BONE_SAMPLES + 2)[1:-1]
    starts, ends = skeleton.joints[parents[parents >= 0]], skeleton.joints[parents >= 0]
    along = starts[:, None, :] + steps[None, :, None] * (ends - starts)[:, None, :]
    points = along.reshape(-1, 3)
    away = np.asarray(depth_at(points)) <= 0.0
    if away.any():
        away[away] = _surface_distances(surface, points[away]) > FAR_FROM_SURFACE
    if enclosed is not None and away.any():
        away[away] = ~np.asarray(enclosed(points[away]), dtype=bool)
    outside = away.reshape(len(starts), BONE_SAMPLES).mean(axis=1)
    stray = list(dict.fromkeys(skeleton.names[parent] for parent, share in zip(children, outside)
                               if share > MAX_OUTSIDE_SHARE))
    if stray:
        problems.append(f"{_listed(stray)} {'lies' if len(stray) == 1 else 'lie'} mostly outside the body")
    problems += _body_problems(skeleton)
    return tuple(problems)


#: A point is enclosed by a surface whose winding number there is at least this (1 inside a closed surface,
#: 0 outside; an open box's centre 0.83).
ENCLOSED_WINDING = 0.5


def enclosed_by(surface: Mesh):
    """``(k, 3) points -> (k,) bool``: whether ``surface`` (outward wound) encloses each point, by its
    generalised winding number (``core.geometry.winding``), which an open mesh's holes do not fool."""
    def enclosed(points: np.ndarray) -> np.ndarray:
        return winding_numbers(points, surface.vertices, surface.triangles) >= ENCLOSED_WINDING
    return enclosed


def _body_problems(skeleton: Skeleton) -> list:
    """A biped's or quadruped's limbs that do not hang where they should (by Rigify's role names)."""
    names = preset_names(skeleton.names, DEFAULT_PRESET)[0]
    index = {name: k for k, name in enumerate(names)}
    parents = np.asarray(skeleton.parents)
    hips = index.get("spine")
    if hips is None:
        return []
    problems = []
    legs = ("thigh.L", "thigh.R")
    if all(leg in index for leg in legs):
        meeting = _meeting_joint(parents, index[legs[0]], index[legs[1]])
        # From the hips or a root below them; from the chest or from a foot, no.
        if meeting is None or hips in ancestors(parents, meeting):
            problems.append("the legs do not hang from the hips")
    for arms in (("upper_arm.L", "upper_arm.R"), ("front_thigh.L", "front_thigh.R")):
        if all(arm in index for arm in arms):
            meeting = _meeting_joint(parents, index[arms[0]], index[arms[1]])
            if meeting is None or meeting == hips or hips not in ancestors(parents, meeting):
                problems.append(f"the {'arms' if arms[0].startswith('upper') else 'front legs'} do not hang from "
                                "the spine above the hips")
    if "upper_arm.L" in index and "head" in index and skeleton.joints[index["head"], 2] <= skeleton.joints[hips, 2]:
        problems.append("the head is not above the hips")
    return problems
