"""Rig families: characters that share a skeleton or a body, which a split must keep on one side.

Files made from one rig are near-duplicates for skeleton prediction (the
same joints, often at the same places) and files of one body for skin
weights (the same mesh under another head or texture). The split
(``scripts/make_split.py``, :mod:`.split_drawing`) therefore moves whole
families, never files. Two files are in one family when they share

* a **rig**: the same joint names with the same parents (:func:`rig_keys`:
  all joints of the skins, and separately only the joints that carry
  weight, so an extra prop joint does not part two copies of one rig);
* a **declared skeleton**: the name a file records for the skeleton it was
  made for (the 0 A.D. conversions: ``horse_old:Horse`` for a lion, a
  lioness and a donkey);
* a **body**: listed together by the sources (the same model under another
  texture or with a small extra), or named ``<body>__<variant>`` by the
  converter (:func:`body_of`: the 0 A.D. humans, ``<body>__<head>``);

and families are the connected groups of that relation.
"""

from __future__ import annotations

from pathlib import PurePosixPath
from typing import Iterable, Mapping, Sequence

from ..io.gltf_skins import SkinRig

#: Fewest joints a rig key needs: one- and two-joint rigs (a test cylinder)
#: are too generic to say two files were made from one rig.
MIN_RIG_KEY_JOINTS = 3
#: Separates a body from its variant in a converted file's stem (``m_tunic_long__head_beard``).
BODY_SEPARATOR = "__"


def _hierarchy_key(names: Sequence[str], parents: Sequence[int], keep: Sequence[bool]) -> tuple:
    """Sorted (name, parent name) pairs of the kept joints; a kept joint's
    parent is its nearest kept ancestor ("" at the top)."""
    pairs = set()
    for joint, kept in enumerate(keep):
        if not kept:
            continue
        parent = parents[joint]
        while parent >= 0 and not keep[parent]:
            parent = parents[parent]
        pairs.add((names[joint], names[parent] if parent >= 0 else ""))
    return tuple(sorted(pairs))


def rig_keys(rigs: Sequence[SkinRig], declared_skeleton: str = "") -> tuple[str, ...]:
    """Keys naming the rig a file was made from; files sharing any key share a rig.

    Parameters
    ----------
    rigs : the file's skins (``core.io.gltf_skins.skin_rigs``); several
        skins of one file (one per body part) count as one rig
    declared_skeleton : the skeleton the file says it was made for, or ``""``

    Returns
    -------
    tuple of str: ``"joints:..."`` (every joint with its parent),
    ``"weighted:..."`` (the joints that carry weight, each under its nearest
    weighted ancestor) and ``"declared:..."``; a joint key with fewer than
    :data:`MIN_RIG_KEY_JOINTS` joints is left out.
    """
    every, weighted = set(), set()
    for rig in rigs:
        every.update(_hierarchy_key(rig.names, rig.parents, [True] * len(rig.names)))
        weighted.update(_hierarchy_key(rig.names, rig.parents, rig.weighted))
    keys = [f"{label}:{sorted(pairs)!r}" for label, pairs in (("joints", every), ("weighted", weighted))
            if len(pairs) >= MIN_RIG_KEY_JOINTS]
    if declared_skeleton:
        keys.append(f"declared:{declared_skeleton}")
    return tuple(dict.fromkeys(keys))


def body_of(path: str) -> str:
    """The body a converted file shows: ``folder/<body>`` for a stem
    ``<body>__<variant>``, ``""`` for any other name."""
    posix = PurePosixPath(path)
    body, separator, _ = posix.stem.partition(BODY_SEPARATOR)
    return f"{posix.parent.as_posix()}/{body}" if separator and body else ""


def rig_families(keys: Mapping[str, Iterable[str]], bodies: Iterable[Iterable[str]] = ()) -> list[tuple[str, ...]]:
    """Files gathered into families: connected by a shared rig key, a shared
    :func:`body_of` or a listed body group.

    Parameters
    ----------
    keys : path -> its rig keys (:func:`rig_keys`); every path to group is a key of this mapping
    bodies : groups of paths listed as one body (paths not in ``keys`` are ignored)

    Returns
    -------
    list of tuples of paths: each family sorted, families sorted by their first path.
    """
    paths = sorted(keys)
    parent = {path: path for path in paths}

    def root(path: str) -> str:
        while parent[path] != path:
            parent[path] = parent[parent[path]]
            path = parent[path]
        return path

    def join(first: str, second: str) -> None:
        parent[root(second)] = root(first)

    first_with = {}
    for path in paths:
        for key in list(keys[path]) + ([f"body:{body_of(path)}"] if body_of(path) else []):
            if key in first_with:
                join(first_with[key], path)
            else:
                first_with[key] = path
    for group in bodies:
        members = [path for path in group if path in parent]
        for other in members[1:]:
            join(members[0], other)
    families = {}
    for path in paths:
        families.setdefault(root(path), []).append(path)
    return sorted(tuple(sorted(members)) for members in families.values())
