"""RigNet-style normalisation of a rigged character into a common frame.

RigNet's (``normalize_obj`` in its ``quick_start.py``), written for
Blender's axes (z up, characters facing -Y, their left side at +X):

1. the bounding box of the mesh is centred on x and y and its lowest point
   (the feet) put at z = 0;
2. the character is turned about the vertical axis by quarter turns so that
   its left-side bones (see :func:`bone_side`) lie at +X of its right-side
   ones (:func:`facing_quarter_turns`): a character facing +Y turns 180
   degrees, one facing +X or -X 90 degrees. When no bone name tells left
   from right the character is kept as the file has it (importers already
   map each format's own front axis to Blender's -Y) and the result records
   ``facing = "unknown"``;
3. everything is scaled uniformly so that the largest side of the bounding
   box is 1. For an upright biped this is its height; RigNet scales by the
   largest side too, so long animals (snakes, fish) are not blown up.

The up axis is the importer's: glTF is y-up by specification and FBX files
declare theirs; both are converted to Blender's z-up on import.
"""

from __future__ import annotations

import re
from typing import NamedTuple, Optional

import numpy as np

from ..errors import InputError
from ..types import Mesh, Skeleton

#: ``facing`` values of a sample: already facing -Y by its bone names, turned
#: to face -Y, or kept as loaded because no bone name tells left from right.
FACING_AS_NAMED = "named"
FACING_TURNED = "turned"
FACING_UNKNOWN = "unknown"

_LEFT, _RIGHT, _NO_SIDE = 1, -1, 0
# Side markers: a separated single letter at the end (".L", "_l", "-R", " r")
# or start ("L_", "r."), or the words left/right anywhere ("LeftArm",
# "arm_right", "mixamorig:RightHand").
_SUFFIX_SIDE = re.compile(r"[._\-\s]([LlRr])$")
_PREFIX_SIDE = re.compile(r"^([LlRr])[._\-\s]")
_LEFT_WORD = re.compile(r"left", re.IGNORECASE)
_RIGHT_WORD = re.compile(r"right", re.IGNORECASE)


def bone_side(name: str) -> int:
    """Which side of the body a bone name says it is on.

    Recognises ``.L``/``.R`` and ``_l``/``_r``-style suffixes, ``L_``/``r.``
    prefixes and the words ``Left``/``Right`` anywhere (any case).

    Parameters
    ----------
    name : str

    Returns
    -------
    side : int
        1 for left, -1 for right, 0 when the name does not say (or says both).
    """
    left = bool(_LEFT_WORD.search(name))
    right = bool(_RIGHT_WORD.search(name))
    for pattern in (_SUFFIX_SIDE, _PREFIX_SIDE):
        match = pattern.search(name)
        if match:
            letter = match.group(1).lower()
            left |= letter == "l"
            right |= letter == "r"
    if left == right:
        return _NO_SIDE
    return _LEFT if left else _RIGHT


def facing_quarter_turns(skeleton: Skeleton) -> Optional[int]:
    """Quarter turns about +Z that bring the character's left side to +X.

    The direction from the mean of the joints whose names say right to the
    mean of those that say left (:func:`bone_side`; all bones count, deform
    or not), projected on the ground, is the character's left. It is snapped
    to the nearest axis, so a slightly asymmetric pose does not tilt the
    bounding box.

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
    sides = np.array([bone_side(name) for name in skeleton.names], dtype=np.int64)
    left, right = sides == _LEFT, sides == _RIGHT
    if not left.any() or not right.any():
        return None
    direction = skeleton.joints[left, :2].mean(axis=0) - skeleton.joints[right, :2].mean(axis=0)
    if not np.any(np.abs(direction) > 0.0):
        return None
    angle = np.degrees(np.arctan2(direction[1], direction[0]))
    return int(np.round(-angle / 90.0)) % 4


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
    """

    mesh: Mesh
    skeleton: Skeleton
    transform: np.ndarray
    facing: str


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


def normalise(mesh: Mesh, skeleton: Skeleton) -> Normalised:
    """Move a character into the common frame (see the module docstring).

    Parameters
    ----------
    mesh : Mesh
    skeleton : Skeleton
        In the mesh's space.

    Returns
    -------
    Normalised
        Copies of both and the transform; triangles, names, parents and
        deform flags are unchanged (a rotation and a positive scale keep the
        triangles' orientation).
    """
    turns = facing_quarter_turns(skeleton)
    transform = normalisation_transform(mesh.vertices, turns or 0)
    moved_mesh = Mesh(
        apply_transform(mesh.vertices, transform), mesh.triangles, mesh.triangle_polygons,
        mesh.object_offsets, mesh.object_names,
    )
    moved_skeleton = Skeleton(
        apply_transform(skeleton.joints, transform), skeleton.parents, skeleton.names,
        apply_transform(skeleton.tails, transform), skeleton.deform,
    )
    facing = FACING_UNKNOWN if turns is None else (FACING_TURNED if turns else FACING_AS_NAMED)
    return Normalised(moved_mesh, moved_skeleton, transform, facing)
