"""Bone naming conventions: side suffixes, numbered chains, and the side any name says.

A bone on the left ends in ``.L`` and its mirror twin on the right in
``.R``; Blender's "flip name" swaps the two. A chain of bones repeats one
base name with a three-digit counter (``tail``, ``tail.001``, ``tail.002``),
the side suffix, if any, coming last (``finger.001.L``). Other rigs say
the side in other ways (``LeftArm``, ``l_thigh``, ``bip01 l hand``);
:func:`bone_side` reads them all.
"""

from __future__ import annotations

import re

#: Suffixes of bones on the character's left and right side.
LEFT_SUFFIX = ".L"
RIGHT_SUFFIX = ".R"
#: What :func:`bone_side` returns for a bone on the left, on the right and on neither side.
LEFT_SIDE, RIGHT_SIDE, NO_SIDE = 1, -1, 0
# Side markers: a separated single letter at the end (".L", "_l", "-R", " r"),
# at the start ("L_", "r.") or between separators ("bip01 l hand",
# "thigh.L.01"), or the words left/right anywhere ("LeftArm", "arm_right",
# "mixamorig:RightHand").
_SUFFIX_SIDE = re.compile(r"[._\-\s]([LlRr])$")
_PREFIX_SIDE = re.compile(r"^([LlRr])[._\-\s]")
_MIDDLE_SIDE = re.compile(r"[._\-\s]([LlRr])[._\-\s]")
_LEFT_WORD = re.compile(r"left", re.IGNORECASE)
_RIGHT_WORD = re.compile(r"right", re.IGNORECASE)


def mirror_name(name: str) -> str:
    """The name of the mirror twin: ``.L`` and ``.R`` suffixes swapped.

    Parameters
    ----------
    name : str

    Returns
    -------
    str
        ``name`` itself when it has neither suffix (a bone on the midline).

    Examples
    --------
    >>> mirror_name("upper_arm.L"), mirror_name("hand.R"), mirror_name("spine")
    ('upper_arm.R', 'hand.L', 'spine')
    """
    if name.endswith(LEFT_SUFFIX):
        return name[: -len(LEFT_SUFFIX)] + RIGHT_SUFFIX
    if name.endswith(RIGHT_SUFFIX):
        return name[: -len(RIGHT_SUFFIX)] + LEFT_SUFFIX
    return name


def chain_names(base: str, count: int, suffix: str = "") -> list:
    """Names of a chain of ``count`` bones: ``base``, ``base.001``, ...,
    each followed by the side ``suffix`` (``".L"``, or ``""`` for none).

    Examples
    --------
    >>> chain_names("wing", 3, ".L")
    ['wing.L', 'wing.001.L', 'wing.002.L']
    """
    return [base + suffix] + [f"{base}.{i:03d}{suffix}" for i in range(1, count)]


def bone_side(name: str) -> int:
    """Which side of the body a bone name says it is on.

    Recognises ``.L``/``.R`` and ``_l``/``_r``-style suffixes, ``L_``/``r.``
    prefixes, a lone letter between separators (``bip01 l hand``,
    ``thigh.L.01``) and the words ``Left``/``Right`` anywhere (any case);
    a word outranks a letter (``left_r_leg`` is left).

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
    # A word outranks a lone letter: in "left_r_leg" (0 A.D.'s giraffe) the r is "rear".
    for pattern in () if left or right else (_SUFFIX_SIDE, _PREFIX_SIDE, _MIDDLE_SIDE):
        match = pattern.search(name)
        if match:
            letter = match.group(1).lower()
            left |= letter == "l"
            right |= letter == "r"
    if left == right:
        return NO_SIDE
    return LEFT_SIDE if left else RIGHT_SIDE
