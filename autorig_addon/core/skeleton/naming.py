"""Blender's bone naming conventions: side suffixes and numbered chains.

A bone on the left ends in ``.L`` and its mirror twin on the right in
``.R``; Blender's "flip name" swaps the two. A chain of bones repeats one
base name with a three-digit counter (``tail``, ``tail.001``, ``tail.002``),
the side suffix, if any, coming last (``finger.001.L``).
"""

from __future__ import annotations

#: Suffixes of bones on the character's left and right side.
LEFT_SUFFIX = ".L"
RIGHT_SUFFIX = ".R"


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
