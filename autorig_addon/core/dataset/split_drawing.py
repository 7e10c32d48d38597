"""Drawing the train/validation split: whole families, a validation share per kind, earlier sides kept.

:func:`draw_split` decides the side of every character from its family
(:mod:`.families`), its kind and the sides an earlier split already gave
(characters the shipped networks were trained or validated on keep them):

1. A family holding characters of the earlier split keeps those on their
   sides; its new members go to validation only when every earlier member
   is a validation character, else to training (a new file on a rig the
   networks were trained on would leak into validation).
2. Every other family is new. Per kind, the new families are shuffled with
   one seeded generator (kinds in sorted order, each kind's families
   sorted first, so the draw never depends on file-system order) and
   interleaved across source folders (validation takes one family from each
   folder before a second from the same folder). Going down that order a
   family goes to validation while validation holds fewer than
   ``round(fraction x families)`` of the kind's new families and the family
   fits in ``round(fraction x files)`` of its new files, so a family of 133
   near-identical files never fills validation alone. At least one family
   goes to validation (the smallest, when none fits) and at least one
   trains; a kind with a single new family trains it.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import PurePosixPath
from typing import Mapping, Sequence

import numpy as np

#: Names of the two sides.
TRAIN, VALIDATION = "train", "validation"


def _folder(path: str) -> str:
    return PurePosixPath(path).parent.as_posix()


def interleave_by_folder(families: Sequence[tuple[str, ...]]) -> list[tuple[str, ...]]:
    """Round-robin over source folders (each family's first path's folder),
    keeping each folder's order."""
    by_folder = defaultdict(list)
    for family in families:
        by_folder[_folder(family[0])].append(family)
    queues = [by_folder[folder] for folder in sorted(by_folder)]
    ordered = []
    while any(queues):
        for queue in queues:
            if queue:
                ordered.append(queue.pop(0))
    return ordered


def _validation_families(families: list[tuple[str, ...]], fraction: float) -> set[tuple[str, ...]]:
    """The families of one kind that go to validation, in the given (drawn) order."""
    if len(families) < 2:
        return set()
    wanted = min(max(1, int(round(fraction * len(families)))), len(families) - 1)
    file_cap = max(1, int(round(fraction * sum(map(len, families)))))
    chosen, files = [], 0
    for family in families:
        if len(chosen) < wanted and files + len(family) <= file_cap:
            chosen.append(family)
            files += len(family)
    if not chosen:
        chosen.append(min(families, key=len))
    return set(chosen)


def draw_split(
    families: Sequence[tuple[str, ...]],
    kinds: Mapping[str, str],
    earlier_sides: Mapping[str, str],
    fraction: float,
    seed: int,
) -> dict[str, str]:
    """The side of every character (see the module docstring).

    Parameters
    ----------
    families : tuples of paths (:func:`.families.rig_families`); a family has one kind
    kinds : path -> kind (``"humanoid"``, ``"quadruped"``, ...)
    earlier_sides : path -> :data:`TRAIN` or :data:`VALIDATION` for the characters of an earlier split
    fraction : validation share of each kind's new families and files (0..1)
    seed : seed of the shuffle

    Returns
    -------
    dict path -> :data:`TRAIN` or :data:`VALIDATION`, for every path of ``families``.

    Raises
    ------
    ValueError when a family mixes kinds.
    """
    sides = {}
    new_by_kind = defaultdict(list)
    for family in families:
        family_kinds = sorted({kinds[path] for path in family})
        if len(family_kinds) != 1:
            raise ValueError(f"The family {list(family)} mixes kinds {family_kinds}: give its files one kind.")
        earlier = [earlier_sides[path] for path in family if path in earlier_sides]
        if earlier:
            newcomers = VALIDATION if all(side == VALIDATION for side in earlier) else TRAIN
            sides.update({path: earlier_sides.get(path, newcomers) for path in family})
        else:
            new_by_kind[family_kinds[0]].append(tuple(family))
    rng = np.random.default_rng(seed)
    for kind in sorted(new_by_kind):
        kind_families = sorted(new_by_kind[kind])
        drawn = interleave_by_folder([kind_families[index] for index in rng.permutation(len(kind_families))])
        validation = _validation_families(drawn, fraction)
        for family in kind_families:
            sides.update({path: VALIDATION if family in validation else TRAIN for path in family})
    return sides
