"""Whether a character's weights sit on the bones their names say, before they are trusted as an artist's.

Rigs with Mixamo's bone names (``mixamorig:LeftHand``) may have been weighted
by Mixamo's automatic rigger rather than by an artist. :func:`check_named_weights`
looks at what an automatic or broken weighting gets wrong:

* **unweighted vertices**: every vertex of an artist's skin carries weight;
* **role bones**: the vertices nearest a bone whose name says hand, foot
  or head (the root-most deform bone with that word, per side) should be
  weighted mostly to that bone, its parent or its descendants (a hand
  vertex on the hand or a finger, not on the spine);
* **crossed sides**: a vertex nearest a left bone weighted mostly to a
  right bone (or the reverse).

Nearest means the closest deform bone segment (``core.geometry.segments``).
The loader runs the check on rigs with Mixamo names
(:func:`has_mixamo_names`) and notes the result
(:attr:`NamedWeightCheck.note`); the data split decides what to do with it.
"""

from __future__ import annotations

import re
from typing import NamedTuple

import numpy as np

from ..geometry.segments import closest_segments
from ..skeleton.hierarchy import children_lists
from ..skeleton.naming import NO_SIDE, bone_side
from ..types import Mesh, Skeleton, Weights
from ..weights import INFLUENCE_EPSILON

#: Bone-name prefix of Mixamo's rigs.
MIXAMO_PREFIX = "mixamorig"
#: Words that name a role bone, checked per side (the head once).
ROLE_WORDS = ("hand", "foot", "head")
#: Smallest share of a role bone's nearest vertices weighted to its neighbourhood for the weights to be trusted.
MIN_ROLE_SHARE = 0.8
#: Largest share of weighted vertices weighted to the other side than their nearest bone's.
MAX_CROSSED_SIDE_SHARE = 0.02
# Joints past the role bone (fingers, tips) or rig controls whose names hold a role word.
_NOT_A_ROLE_BONE = re.compile(r"finger|thumb|index|middle|ring|pinky|toe|top|end|nub|ik|target|pole", re.IGNORECASE)


class NamedWeightCheck(NamedTuple):
    """Result of :func:`check_named_weights`.

    Attributes
    ----------
    vertex_count, unweighted : int
    role_shares : tuple of (bone name, share, vertices)
        For each role bone, the share of the vertices nearest it that are
        weighted mostly to it, its parent or its descendants.
    crossed_side_share : float, share of weighted vertices weighted to the other side
    """

    vertex_count: int
    unweighted: int
    role_shares: tuple
    crossed_side_share: float

    @property
    def trustworthy(self) -> bool:
        """Every vertex weighted, every role share at least :data:`MIN_ROLE_SHARE`,
        crossed sides at most :data:`MAX_CROSSED_SIDE_SHARE`."""
        return (self.unweighted == 0 and all(share >= MIN_ROLE_SHARE for _, share, _ in self.role_shares)
                and self.crossed_side_share <= MAX_CROSSED_SIDE_SHARE)

    @property
    def note(self) -> str:
        roles = ", ".join(f"{name} {share:.0%} of {count}" for name, share, count in self.role_shares) or "none found"
        verdict = "plausible" if self.trustworthy else "NOT trustworthy"
        return (f"weights checked against the bone names: {verdict} ({self.unweighted} of {self.vertex_count} "
                f"vertices unweighted; nearest-bone vertices on their own bone: {roles}; "
                f"{self.crossed_side_share:.1%} weighted to the other side)")


def has_mixamo_names(names) -> bool:
    """Whether a rig uses Mixamo's bone names (``mixamorig:Hips``, ``mixamorig1:Spine``)."""
    return any(str(name).lower().startswith(MIXAMO_PREFIX) for name in names)


def _neighbourhood(parents: np.ndarray, children: list, bone: int) -> set:
    found, stack = {bone}, [bone]
    while stack:
        for child in children[stack.pop()]:
            found.add(child)
            stack.append(child)
    if parents[bone] >= 0:
        found.add(int(parents[bone]))
    return found


def role_bones(names) -> list[int]:
    """The root-most bone per role word and side (head once), in ``names`` order (parents first)."""
    chosen = {}
    for index, name in enumerate(names):
        if _NOT_A_ROLE_BONE.search(name):
            continue
        for word in ROLE_WORDS:
            if word in name.lower():
                key = (word, NO_SIDE if word == "head" else bone_side(name))
                chosen.setdefault(key, index)
                break
    return sorted(chosen.values())


def check_named_weights(mesh: Mesh, skeleton: Skeleton, weights: Weights) -> NamedWeightCheck:
    """Check that weights sit on the bones their names say (see the module docstring).

    Parameters
    ----------
    mesh : Mesh, in the skeleton's space
    skeleton : Skeleton; its deform bones are the weights' columns
    weights : Weights (n, d), columns matched to the deform bones by name

    Returns
    -------
    NamedWeightCheck
    """
    bones = skeleton.deform_subset()
    matrix = weights.select_bones(bones.names).matrix
    weighted = (matrix > INFLUENCE_EPSILON).any(axis=1)
    nearest, _ = closest_segments(mesh.vertices, bones.joints, bones.tails)
    dominant = np.argmax(matrix, axis=1)
    children = children_lists(bones.parents)
    shares = []
    for bone in role_bones(bones.names):
        near = weighted & (nearest == bone)
        if near.any():
            hood = np.array(sorted(_neighbourhood(bones.parents, children, bone)))
            shares.append((bones.names[bone], float(np.isin(dominant[near], hood).mean()), int(near.sum())))
    sides = np.array([bone_side(name) for name in bones.names], dtype=np.int64)
    crossed = weighted & (sides[dominant] * sides[nearest] < 0)
    crossed_share = float(crossed.sum() / max(int(weighted.sum()), 1))
    return NamedWeightCheck(mesh.vertex_count, int((~weighted).sum()), tuple(shares), crossed_share)
