"""RigNet-style normalisation of a rigged character into a common frame.

RigNet's (``normalize_obj`` in its ``quick_start.py``), written for
Blender's axes (z up, characters facing -Y, their left side at +X):

1. the bounding box of the mesh is centred on x and y and its lowest point
   (the feet) put at z = 0;
2. the character is turned about the vertical axis by quarter turns so that
   it faces -Y (:func:`facing_decision`): its left-side bones (see
   :func:`bone_side`) go to +X of its right-side ones
   (:func:`facing_quarter_turns`; a character facing +Y turns 180 degrees,
   one facing +X or -X 90 degrees), unless its head and tail say otherwise:
   when a joint named head lies well ahead of one named tail on the ground
   (:func:`head_tail_quarter_turns`), the head goes to -Y, since side names
   can be mirrored (the 0 A.D. cattle's left bones lie on their right) and
   fins named left and right need not lie left and right. When neither
   tells, the character is kept as the file has it (importers already map
   each format's own front axis to Blender's -Y) and the result records
   ``facing = "unknown"``;
3. everything is scaled uniformly so that the largest side of the bounding
   box is 1. For an upright biped this is its height; RigNet scales by the
   largest side too, so long animals (snakes, fish) are not blown up.

The up axis is the importer's: glTF is y-up by specification and FBX files
declare theirs; both are converted to Blender's z-up on import. What was
decided is written out as notes (:attr:`Normalised.notes`): the scale
and the facing, with the cue that decided it.
"""

from __future__ import annotations

import re
from typing import NamedTuple, Optional, Sequence

import numpy as np

from ..errors import InputError
from ..skeleton.hierarchy import subset_parents
from ..skeleton.naming import LEFT_SIDE, NO_SIDE, RIGHT_SIDE, bone_side
from ..types import Mesh, Skeleton

#: ``facing`` values of a sample: already facing -Y as loaded (by its bone
#: names, or its head and tail), turned to face -Y, or kept as loaded because
#: nothing tells where its front is.
FACING_AS_NAMED = "named"
FACING_TURNED = "turned"
FACING_UNKNOWN = "unknown"
#: The head-to-tail facing cue counts when the head lies at least this share
#: of the largest side of the joints' bounding box ahead of the tail on the
#: ground (a horse: about 0.9; a biped whose tail hangs below its head: little).
HEAD_TAIL_MIN_FRACTION = 0.3
#: A facing snapped from side names is noted as off axis beyond this many
#: degrees (the Nexuiz idle stances stand turned by 23 to 43 degrees).
OFF_AXIS_NOTE_DEGREES = 15.0

_HEAD_WORD = re.compile(r"head", re.IGNORECASE)
_TAIL_WORD = re.compile(r"tail", re.IGNORECASE)


def _turns_towards(direction: np.ndarray, target_degrees: float) -> Optional[int]:
    """Counter-clockwise quarter turns bringing a ground direction nearest to the axis at ``target_degrees``."""
    if not np.any(np.abs(direction) > 0.0):
        return None
    angle = np.degrees(np.arctan2(direction[1], direction[0]))
    return int(np.round((target_degrees - angle) / 90.0)) % 4


def _deform_first(skeleton: Skeleton) -> tuple[np.ndarray, tuple, np.ndarray]:
    """Joints, names and parents (re-linked) of the deform bones when there are any, else of all bones.

    Joints without weight (prop points, IK targets) may sit anywhere: the
    side and head cues read the bones that move the mesh.
    """
    deform = np.asarray(skeleton.deform, dtype=bool)
    if deform.any() and not deform.all():
        names = tuple(name for name, kept in zip(skeleton.names, deform) if kept)
        return skeleton.joints[deform], names, subset_parents(skeleton.parents, deform)
    return skeleton.joints, tuple(skeleton.names), skeleton.parents


def named_left_direction(skeleton: Skeleton) -> Optional[np.ndarray]:
    """The character's left on the ground as its bone names tell it.

    The direction from the mean of the right-side joints near the body to
    the mean of the left-side ones. Near the body: the first two joints of
    each chain of joints whose names say a side (:func:`bone_side`), the
    chain starting under a parent that says none (clavicle and upper arm,
    thigh and shin, a giraffe's pelvis and leg top), so hands held across
    the body in a stance, or a thumb named for the other side, do not pull
    the line. The deform bones are read when they name both sides, else all
    bones.

    Returns
    -------
    (2,) float64 array (x, y), or None when the names give no left and right joints.
    """
    whole = (skeleton.joints, tuple(skeleton.names), skeleton.parents)
    for joints, names, parents in (_deform_first(skeleton), whole):
        sides = np.array([bone_side(name) for name in names], dtype=np.int64)
        has_parent = parents >= 0
        parent_sides = np.where(has_parent, sides[np.maximum(parents, 0)], NO_SIDE)
        chain_roots = (sides != NO_SIDE) & (parent_sides == NO_SIDE)
        under_root = has_parent & chain_roots[np.maximum(parents, 0)] & (parent_sides == sides)
        near_body = chain_roots | under_root
        left, right = (sides == LEFT_SIDE) & near_body, (sides == RIGHT_SIDE) & near_body
        if left.any() and right.any():
            return joints[left, :2].mean(axis=0) - joints[right, :2].mean(axis=0)
    return None


def facing_quarter_turns(skeleton: Skeleton) -> Optional[int]:
    """Quarter turns about +Z that bring the character's left side to +X.

    The left of :func:`named_left_direction` is snapped to the nearest axis,
    so a slightly asymmetric pose does not tilt the bounding box.

    Parameters
    ----------
    skeleton : Skeleton

    Returns
    -------
    int in 0..3 or None
        Counter-clockwise quarter turns (seen from above); 2 turns a
        character facing +Y around. None when the names give no left and
        right joints, or both sides lie at the same place on the ground.
    """
    direction = named_left_direction(skeleton)
    return None if direction is None else _turns_towards(direction, 0.0)


def _root_most(names: Sequence[str], depths: np.ndarray, word: re.Pattern) -> Optional[int]:
    matches = [index for index, name in enumerate(names) if word.search(name)]
    return min(matches, key=lambda index: (depths[index], index)) if matches else None


def head_tail_quarter_turns(skeleton: Skeleton) -> Optional[int]:
    """Quarter turns about +Z that bring the head ahead of the tail, to -Y.

    The root-most deform joints whose names hold ``head`` and ``tail`` give
    the body's length on the ground; it counts when the head lies at least
    :data:`HEAD_TAIL_MIN_FRACTION` of the largest side of the joints'
    bounding box ahead of the tail (quadrupeds, fish, birds; not a biped
    whose tail hangs below its head).

    Returns
    -------
    int in 0..3 or None
        Counter-clockwise quarter turns, or None without a head and a tail
        far enough apart on the ground.
    """
    joints, names, parents = _deform_first(skeleton)
    depths = np.zeros(len(names), dtype=np.int64)
    for joint, parent in enumerate(parents):
        depths[joint] = depths[parent] + 1 if parent >= 0 else 0
    head, tail = _root_most(names, depths, _HEAD_WORD), _root_most(names, depths, _TAIL_WORD)
    if head is None or tail is None:
        return None
    ahead = joints[head, :2] - joints[tail, :2]
    extent = float(np.ptp(joints, axis=0).max())
    if extent <= 0.0 or np.linalg.norm(ahead) < HEAD_TAIL_MIN_FRACTION * extent:
        return None
    return _turns_towards(ahead, -90.0)


class FacingDecision(NamedTuple):
    """How :func:`facing_decision` turns a character to face -Y.

    Attributes
    ----------
    quarter_turns : int, counter-clockwise quarter turns about +Z (0..3)
    facing : str, :data:`FACING_AS_NAMED`, :data:`FACING_TURNED` or :data:`FACING_UNKNOWN`
    note : str, what decided it, for the sample's notes
    """

    quarter_turns: int
    facing: str
    note: str


def _degrees_off_axis(direction: np.ndarray) -> float:
    """Angle (degrees, 0..45) between a ground direction and the nearest axis."""
    angle = np.degrees(np.arctan2(direction[1], direction[0])) % 90.0
    return float(min(angle, 90.0 - angle))


_TURN_WORDS = {1: "a quarter turn counter-clockwise", 2: "half a turn", 3: "a quarter turn clockwise"}


def facing_decision(skeleton: Skeleton, sides_named_from_the_viewer: bool = False) -> FacingDecision:
    """The quarter turns that make a character face -Y, and why (see the module docstring).

    ``sides_named_from_the_viewer``: its artist named the sides from the
    viewer (``data_split.json`` says so, its face the evidence), so its
    side names put its own left where they say right.

    Notes read ``"faces -Y as loaded (side names: left joints at +X)"``,
    ``"turned half a turn to face -Y (head ahead of tail; its side names would
    have turned it not at all, so they are mirrored or not lateral)"`` or
    ``"facing kept as loaded: no side names, no head ahead of a tail"``.
    """
    named, head_tail = facing_quarter_turns(skeleton), head_tail_quarter_turns(skeleton)
    if named is not None and sides_named_from_the_viewer:
        named = (named + 2) % 4
    if head_tail is not None and named is not None and head_tail != named:
        turns, cue = head_tail, (f"head ahead of tail; its side names would have turned it "
                                 f"{_TURN_WORDS.get(named, 'not at all')}, so they are mirrored or not lateral")
    elif named is not None:
        turns, cue = named, ("side names, given from the viewer: right joints at +X" if sides_named_from_the_viewer
                             else "side names: left joints at +X")
        off_axis = _degrees_off_axis(named_left_direction(skeleton))
        if off_axis > OFF_AXIS_NOTE_DEGREES:
            cue += f"; the left-right line is {off_axis:.0f} degrees off that axis"
    elif head_tail is not None:
        turns, cue = head_tail, "head ahead of tail; no side names"
    else:
        return FacingDecision(0, FACING_UNKNOWN, "facing kept as loaded: no side names, no head ahead of a tail")
    if turns:
        return FacingDecision(turns, FACING_TURNED, f"turned {_TURN_WORDS[turns]} to face -Y ({cue})")
    return FacingDecision(0, FACING_AS_NAMED, f"faces -Y as loaded ({cue})")


class Normalised(NamedTuple):
    """Result of :func:`normalise`.

    Attributes
    ----------
    mesh : Mesh, the moved copy
    skeleton : Skeleton, the moved copy
    transform : (4, 4) float64 array
        Maps original positions ``p`` to normalised ones:
        ``transform[:3, :3] @ p + transform[:3, 3]``.
    facing : str
        :data:`FACING_AS_NAMED`, :data:`FACING_TURNED` or :data:`FACING_UNKNOWN`.
    notes : tuple of str
        What was done and why: the scale (the largest side in the file's
        units) and the facing (:attr:`FacingDecision.note`).
    """

    mesh: Mesh
    skeleton: Skeleton
    transform: np.ndarray
    facing: str
    notes: tuple = ()


def normalisation_transform(vertices: np.ndarray, quarter_turns: int = 0) -> np.ndarray:
    """The similarity transform of :func:`normalise` for given vertices.

    Parameters
    ----------
    vertices : (n, 3) float64 array
    quarter_turns : int
        Counter-clockwise quarter turns (seen from above) about the vertical
        axis through the box centre.

    Returns
    -------
    transform : (4, 4) float64 array
        ``scale * R @ (p - pivot)`` as an affine matrix, with ``pivot`` the
        box centre in x, y and the box bottom in z.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    if not len(vertices):
        raise InputError("The mesh has no vertices, so it cannot be normalised.")
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    largest_side = float((high - low).max())
    if largest_side <= 0.0:
        raise InputError("All vertices lie at one point, so the mesh cannot be normalised.")
    pivot = np.array([(low[0] + high[0]) / 2.0, (low[1] + high[1]) / 2.0, low[2]])
    cosine, sine = [(1, 0), (0, 1), (-1, 0), (0, -1)][int(quarter_turns) % 4]
    rotation = np.array([[cosine, -sine, 0.0], [sine, cosine, 0.0], [0.0, 0.0, 1.0]])
    linear = rotation / largest_side
    transform = np.eye(4)
    transform[:3, :3] = linear
    transform[:3, 3] = -linear @ pivot
    return transform


def apply_transform(points: np.ndarray, transform: np.ndarray) -> np.ndarray:
    """(n, 3) float64 ``points`` mapped by the (4, 4) affine ``transform``."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return points @ transform[:3, :3].T + transform[:3, 3]


def normalise(mesh: Mesh, skeleton: Skeleton, sides_named_from_the_viewer: bool = False) -> Normalised:
    """Move a character into the common frame (see the module docstring).

    Parameters
    ----------
    mesh : Mesh
    skeleton : Skeleton
        In the mesh's space.
    sides_named_from_the_viewer : bool
        Its side names put its own left where they say right
        (:func:`facing_decision`).

    Returns
    -------
    Normalised
        Copies of both and the transform; triangles, names, parents and
        deform flags are unchanged (a rotation and a positive scale keep the
        triangles' orientation).
    """
    decision = facing_decision(skeleton, sides_named_from_the_viewer)
    transform = normalisation_transform(mesh.vertices, decision.quarter_turns)
    moved_mesh = Mesh(
        apply_transform(mesh.vertices, transform), mesh.triangles, mesh.triangle_polygons,
        mesh.object_offsets, mesh.object_names,
    )
    moved_skeleton = Skeleton(
        apply_transform(skeleton.joints, transform), skeleton.parents, skeleton.names,
        apply_transform(skeleton.tails, transform), skeleton.deform,
    )
    return Normalised(moved_mesh, moved_skeleton, transform, decision.facing,
                      (scale_note(mesh.vertices), decision.note))


def scale_note(vertices: np.ndarray) -> str:
    """What the scaling to a unit largest side did, in the file's units: ``"scaled by 1/70.3: ..."``."""
    sides = np.ptp(np.asarray(vertices, dtype=np.float64).reshape(-1, 3), axis=0)
    largest = int(np.argmax(sides))
    return (f"scaled by 1/{sides[largest]:.4g}: the largest side is {'xyz'[largest]}, {sides[largest]:.4g} file "
            f"units (height {sides[2]:.4g})")
