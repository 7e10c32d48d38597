"""Which way the skeleton prediction takes a character to face, on the cached characters.

Usage: .venv/bin/python scripts/check_facing.py train|validation [SAMPLE_DIR]

Every cached character of the part of ``data_split.json`` named (``train``:
every third by name, as the rules' measurements in docs/rigging.md), as it
stands (facing -Y) and turned half a turn about Z (facing +Y). For each,
``predict_votes`` runs and the frame it predicts in is checked: the
character's own left must come out at +X. Prints a line per character, then
per kind (humanoid, the rest) how many were taken the right way, as they
stand and turned.
"""

import collections
import os
import sys
from pathlib import Path

import numpy as np

from autorig_addon.core.dataset.cache import default_cache_dir
from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split
from autorig_addon.core.errors import InputError
from autorig_addon.core.rigging.predict import predict_votes
from autorig_addon.core.types import Mesh

#: The two ways a character is given: as it stands, and turned half a turn about Z.
WAYS = {"as it stands": np.array([1.0, 1.0, 1.0]), "turned": np.array([-1.0, -1.0, 1.0])}


def names_of(part: str) -> set:
    split = read_data_split(DEFAULT_SPLIT_FILE)
    if part == "validation":
        return {os.path.splitext(path)[0] for path in split.validation}
    return {os.path.splitext(path)[0] for path in sorted(split.train)[::3]}


def left_comes_out_at_plus_x(sample: CharacterSample, flip: np.ndarray) -> bool | None:
    """Whether the prediction's frame puts the character's own left at +X (None: refused)."""
    try:
        votes = predict_votes(Mesh(sample.vertices * flip, sample.triangles))
    except InputError:
        return None
    left = votes.transform[:3, :3] @ (np.array([1.0, 0.0, 0.0]) * flip)
    return bool(left[0] > 0)


def main(part: str, folder: str) -> int:
    names = names_of(part)
    right = collections.defaultdict(lambda: collections.Counter())
    for path in sorted(Path(folder).glob("*.npz")):
        try:
            sample = CharacterSample.load(path)
        except Exception:  # noqa: BLE001 - samples of an older format are skipped
            continue
        if sample.name not in names:
            continue
        kind = "humanoid" if sample.category == "humanoid" else "other kinds"
        outcomes = {way: left_comes_out_at_plus_x(sample, flip) for way, flip in WAYS.items()}
        print(sample.name, sample.category, outcomes, flush=True)
        for way, outcome in outcomes.items():
            right[kind, way]["right" if outcome else "refused" if outcome is None else "wrong"] += 1
    for (kind, way), counts in sorted(right.items()):
        print(f"{kind}, {way}: {counts['right']} right, {counts['wrong']} wrong, {counts['refused']} refused")
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] not in ("train", "validation"):
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else str(default_cache_dir())))
