"""The pieces a generated character is assembled from.

A character's surface is the concatenation of parts (a torso shell, an arm,
an eye, a skirt); each part carries its own weights over the few bones that
move it. :data:`PART_TYPES` says how a part was built, and so how its
weights came about.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..skeleton.naming import mirror_name
from .frames import MIRROR_X

#: Part types (``ProceduralCharacter.part_types``).
PART_BODY = "body"  # shell grown around bones; weights blend along the bones
PART_RIGID = "rigid"  # closed accessory moved by exactly one bone
PART_CLOTH = "cloth"  # open shell offset from the body; body weights at the closest body point
PART_DRIVEN = "driven"  # surface moved by its own bones, placed outside the body
PART_TYPES = (PART_BODY, PART_RIGID, PART_CLOTH, PART_DRIVEN)


@dataclass
class Part:
    """One piece of a character under construction.

    Attributes
    ----------
    name : str
        ``"arm.L"``, ``"helmet"``...
    part_type : str
        One of :data:`PART_TYPES`.
    closed : bool
        Whether every edge lies in two triangles.
    vertices : (n, 3) float64 array
    triangles : (t, 3) int64 array
        Indices into this part's ``vertices``.
    bone_names : tuple of k str
        The bones that move the part, one per weight column.
    weights : (n, k) float64 array
        Rows non-negative and summing to one.
    """

    name: str
    part_type: str
    closed: bool
    vertices: np.ndarray
    triangles: np.ndarray
    bone_names: tuple
    weights: np.ndarray


def mirrored_part(part: Part) -> Part:
    """The mirror twin of ``part`` across x = 0: ``.L`` and ``.R`` names
    swapped, triangles reversed so the twin still faces outward."""
    return Part(
        mirror_name(part.name), part.part_type, part.closed, part.vertices * MIRROR_X,
        np.ascontiguousarray(part.triangles[:, ::-1]), tuple(mirror_name(b) for b in part.bone_names),
        part.weights.copy(),
    )
