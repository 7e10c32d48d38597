"""Write data_split.json: the fixed train / validation split of the rigged characters.

The rule (deterministic; rerunning gives the same file):

1. Every character file under the data root (``.glb``, and ``.gltf`` whose
   ``.bin`` and textures lie beside it) is one character. Its category comes
   from its pack folder (``CATEGORY_BY_FOLDER``) or, for the mixed folders,
   from its name (``CATEGORY_BY_FILE``).
2. Near-duplicates (the same model with another texture or a small extra,
   ``NEAR_DUPLICATES``) form one group and land on the same side, so
   validation never sees a model it was trained on under another name.
3. Within each category, groups are shuffled with a fixed seed and then
   interleaved across pack folders (so validation draws from different packs
   before it takes a second one from the same pack). Going down that order,
   groups go to validation while they fit in a quota of
   ``round(VALIDATION_FRACTION * characters)`` (at least one; a category
   with two or more characters keeps at least one for training); the rest
   train. A category of one character (the two-bone test cylinder) is
   validation only.

Usage (from the repository root)::

    .venv/bin/python scripts/make_split.py            # writes data_split.json
    .venv/bin/python scripts/make_split.py --check    # fails if the file is stale

Paths in the file are relative to the data root, ``../shared/data/characters``
seen from the repository root.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections import defaultdict

import numpy as np

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: Data root relative to the repository root.
DATA_ROOT = "../shared/data/characters"
OUTPUT = os.path.join(REPOSITORY, "data_split.json")
#: Seed of the shuffle; change it only to make a new split on purpose.
SPLIT_SEED = 20250301
#: Share of each category's characters held out for validation.
VALIDATION_FRACTION = 0.28
#: File types that hold a character (a .gltf brings its .bin and textures).
CHARACTER_SUFFIXES = (".glb", ".gltf")

CATEGORY_BY_FOLDER = {
    "quaternius_glb/animals_pack": "animal",
    "quaternius_glb/dinosaurs_pack": "dinosaur",
    "quaternius_glb/easy_enemies_pack": "creature",
    "quaternius_glb/fish_pack": "fish",
    "quaternius_glb/mech_pack": "mech",
    "quaternius_glb/modular_men": "human",
    "quaternius_glb/modular_women": "human",
    "quaternius_glb/single_knight_pack": "human",
    "kaykit": "human",
    "assimp_bsd": "human",
}
#: Files whose folder mixes categories.
CATEGORY_BY_FILE = {
    "khronos/CesiumMan.glb": "human",
    "khronos/RiggedFigure.glb": "human",
    "khronos/RiggedSimple.glb": "primitive",  # a two-bone cylinder test rig
}
#: Same model under two names: kept together.
NEAR_DUPLICATES = (
    ("quaternius_glb/animals_pack/Horse.glb", "quaternius_glb/animals_pack/Horse_White.glb"),
    ("quaternius_glb/easy_enemies_pack/Snake.glb", "quaternius_glb/easy_enemies_pack/Snake_angry.glb"),
    ("kaykit/Rogue.glb", "kaykit/Rogue_Hooded.glb"),
)


def find_characters(root: str) -> list:
    """Sorted paths (relative to ``root``, '/' separated) of character files."""
    found = []
    for folder, _, files in os.walk(root):
        for name in files:
            if name.endswith(CHARACTER_SUFFIXES):
                found.append(os.path.relpath(os.path.join(folder, name), root).replace(os.sep, "/"))
    return sorted(found)


def category_of(path: str) -> str:
    if path in CATEGORY_BY_FILE:
        return CATEGORY_BY_FILE[path]
    folder = path.rsplit("/", 1)[0]
    if folder not in CATEGORY_BY_FOLDER:
        raise SystemExit(f"No category for {path}: add its folder to CATEGORY_BY_FOLDER or the file to "
                         "CATEGORY_BY_FILE.")
    return CATEGORY_BY_FOLDER[folder]


def companion_files(root: str, path: str) -> list:
    """Buffers and images a .gltf refers to (they travel with it)."""
    if not path.endswith(".gltf"):
        return []
    with open(os.path.join(root, path), encoding="utf-8") as handle:
        document = json.load(handle)
    folder = path.rsplit("/", 1)[0]
    uris = [item.get("uri") for key in ("buffers", "images") for item in document.get(key, [])]
    return sorted(f"{folder}/{uri}" for uri in uris if uri and not uri.startswith("data:"))


def groups_of(paths: list) -> list:
    """Paths gathered into near-duplicate groups (singletons otherwise)."""
    present = set(paths)
    grouped, groups = set(), []
    for members in NEAR_DUPLICATES:
        members = [m for m in members if m in present]
        if members:
            groups.append(sorted(members))
            grouped.update(members)
    groups.extend([p] for p in paths if p not in grouped)
    return sorted(groups)


def interleave_by_folder(groups: list) -> list:
    """Round-robin over pack folders, keeping each folder's (shuffled) order."""
    by_folder = defaultdict(list)
    for group in groups:
        by_folder[group[0].rsplit("/", 1)[0]].append(group)
    queues = [by_folder[folder] for folder in sorted(by_folder)]
    ordered = []
    while any(queues):
        for queue in queues:
            if queue:
                ordered.append(queue.pop(0))
    return ordered


def make_split(root: str) -> dict:
    paths = find_characters(root)
    if not paths:
        raise SystemExit(f"No characters found under {root}.")
    categories = defaultdict(list)
    for path in paths:
        categories[category_of(path)].append(path)
    rng = np.random.default_rng(SPLIT_SEED)
    train, validation = [], []
    for category in sorted(categories):
        members = sorted(categories[category])
        groups = groups_of(members)
        order = rng.permutation(len(groups))
        ordered = interleave_by_folder([groups[k] for k in order])
        wanted = max(1, int(round(VALIDATION_FRACTION * len(members))))
        if len(members) >= 2:
            wanted = min(wanted, len(members) - 1)
        chosen = []
        for group in ordered:
            if sum(map(len, chosen)) + len(group) <= wanted:
                chosen.append(group)
        if not chosen:  # every group is larger than the quota: take the smallest
            chosen.append(min(ordered, key=len))
        for group in ordered:
            (validation if group in chosen else train).extend(group)
    companions = {p: companion_files(root, p) for p in paths if companion_files(root, p)}
    return {
        "description": "Fixed split of the rigged characters by character; validation characters are never trained on. "
                       "Regenerate with scripts/make_split.py (see its docstring for the rule).",
        "root": DATA_ROOT,
        "seed": SPLIT_SEED,
        "validation_fraction": VALIDATION_FRACTION,
        "train": sorted(train),
        "validation": sorted(validation),
        "categories": {c: sorted(categories[c]) for c in sorted(categories)},
        "near_duplicates": [list(g) for g in NEAR_DUPLICATES],
        "companion_files": companions,
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=os.path.join(REPOSITORY, DATA_ROOT), help="folder holding the characters")
    parser.add_argument("--output", default=OUTPUT)
    parser.add_argument("--check", action="store_true", help="compare with the existing file instead of writing")
    args = parser.parse_args(argv)
    split = make_split(os.path.normpath(args.root))
    text = json.dumps(split, indent=2) + "\n"
    if args.check:
        with open(args.output, encoding="utf-8") as handle:
            if handle.read() != text:
                print(f"{args.output} differs from what {__file__} makes now.", file=sys.stderr)
                return 1
        print(f"{args.output} is up to date.")
        return 0
    with open(args.output, "w", encoding="utf-8") as handle:
        handle.write(text)
    counts = {c: (sum(p in split["validation"] for p in m), len(m)) for c, m in split["categories"].items()}
    print(f"wrote {args.output}: {len(split['train'])} train, {len(split['validation'])} validation; "
          f"per category (validation, total): {counts}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
