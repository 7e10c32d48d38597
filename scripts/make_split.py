"""Write data_split.json: the fixed train / validation split of the rigged characters.

The rule (deterministic; rerunning gives the same file):

1. Every character file under the data root (``.glb``, and ``.gltf`` whose
   ``.bin`` and textures lie beside it) is one character, but for the files
   of ``EXCLUDED``, which are left out with their reason. Its **kind**
   (humanoid, quadruped, bird, fish, other) comes from the longest entry of
   ``KINDS`` its path starts with (a folder, or a file or file-name prefix).
2. Characters are gathered into **families** (``core.dataset.families``):
   files sharing a rig (joint names and parents, read from the glTF skins),
   a declared skeleton (``asset.extras.skeleton``) or a body (``BODIES``,
   and ``<body>__<head>`` file names) are one family, and a family is
   never split.
3. The 53 characters of the first split keep their sides
   (``FIRST_SPLIT_FOLDERS``, ``FIRST_SPLIT_VALIDATION``): the shipped
   networks were trained on its training characters and measured on its
   validation characters. New files of a family that holds first-split
   characters join them (training, unless all of them are validation).
4. Per kind, the new families are shuffled with ``SPLIT_SEED``, interleaved
   across source folders, and go to validation while validation holds fewer
   than ``round(VALIDATION_FRACTION x families)`` of the kind's new families
   and the family fits in ``round(VALIDATION_FRACTION x files)`` of its new
   files (``core.dataset.split_drawing``).
5. ``SKELETON_ONLY`` characters stay in the split (skeleton training and
   evaluation use them) with the reason their weights are not trusted;
   skin training and skin evaluation leave them out
   (``core.dataset.split.DataSplit.usable_for``).
6. ``SIDES_NAMED_FROM_THE_VIEWER`` characters' bones named left lie on
   their right (their faces tell): their references are read with the
   sides swapped.

Usage (from the repository root)::

    .venv/bin/python scripts/make_split.py            # writes data_split.json
    .venv/bin/python scripts/make_split.py --check    # fails if the file is stale

Paths in the file are relative to the data root, ``../shared/data/characters``
seen from the repository root. The tests never run this script (it needs
the data); the rule's parts are tested on generated lists.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections import Counter

from autorig_addon.core.dataset.families import rig_families, rig_keys
from autorig_addon.core.dataset.split import BIRD, FISH, HUMANOID, OTHER, PURPOSE_SKIN, QUADRUPED
from autorig_addon.core.dataset.split_drawing import TRAIN, VALIDATION, draw_split
from autorig_addon.core.io.gltf_skins import declared_skeleton, read_gltf, skin_rigs

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: Data root relative to the repository root.
DATA_ROOT = "../shared/data/characters"
OUTPUT = os.path.join(REPOSITORY, "data_split.json")
#: Seed of the shuffle; change it only to make a new split on purpose.
SPLIT_SEED = 20250301
#: Share of each kind's new families (and at most of its new files) held out for validation: the first split's.
VALIDATION_FRACTION = 0.28
#: File types that hold a character (a .gltf brings its .bin and textures).
CHARACTER_SUFFIXES = (".glb", ".gltf")

#: Kind of every character: the longest entry its path starts with wins (a
#: folder ends with "/"; a file-name prefix such as ".../standing_" names several files).
KINDS = {
    # The first split's folders (its categories human, animal, dinosaur, fish, creature, mech, primitive).
    "assimp_bsd/": HUMANOID,
    "kaykit/": HUMANOID,
    "khronos/": HUMANOID,
    "khronos/RiggedSimple.glb": OTHER,  # a two-bone test cylinder
    "quaternius_glb/animals_pack/": QUADRUPED,
    "quaternius_glb/dinosaurs_pack/": QUADRUPED,
    "quaternius_glb/dinosaurs_pack/Trex.glb": OTHER,  # bipedal with a long tail
    "quaternius_glb/dinosaurs_pack/Velociraptor.glb": OTHER,
    "quaternius_glb/easy_enemies_pack/": OTHER,  # snakes and a wasp
    "quaternius_glb/easy_enemies_pack/Rat.glb": QUADRUPED,
    "quaternius_glb/fish_pack/": FISH,
    "quaternius_glb/mech_pack/": HUMANOID,
    "quaternius_glb/mech_pack/Leela.glb": OTHER,  # a two-legged walker without arms
    "quaternius_glb/modular_men/": HUMANOID,
    "quaternius_glb/modular_women/": HUMANOID,
    "quaternius_glb/single_knight_pack/": HUMANOID,
    # Converted from open-source games.
    "zeroad_humans/": HUMANOID,
    "zeroad_animals/": QUADRUPED,
    "zeroad_animals/chicken.glb": BIRD,
    "zeroad_animals/crow.glb": BIRD,
    "zeroad_animals/hawk.glb": BIRD,
    "zeroad_animals/seagull.glb": BIRD,
    "zeroad_animals/animal_tuna.glb": FISH,
    "zeroad_animals/fish_single.glb": FISH,
    "zeroad_animals/shark.glb": FISH,
    "zeroad_animals/whale_fin.glb": FISH,  # a whale: a swimmer's body and rig
    "nexuiz/": HUMANOID,
    "redeclipse/": HUMANOID,
    "openclonk/": HUMANOID,  # the Clonk in four outfits
    "openclonk/oc_chippie.glb": OTHER,  # an insect-like creature
    "openclonk/oc_fish.glb": FISH,
    "openclonk/oc_piranha.glb": FISH,
    "openclonk/oc_shark.glb": FISH,
    "openclonk/oc_wipf.glb": QUADRUPED,
    "stk/": HUMANOID,
    "stk/stk_redCrab_a.glb": OTHER,
    # From public repositories redistributing open packs.
    "gh_gdquest_mannequiny/": HUMANOID,
    "gh_godot_demo_platformer/platformer_player.glb": HUMANOID,
    "gh_godot_demo_platformer/platformer_enemy.glb": OTHER,  # a four-legged robot beetle
    "gh_kaykit_adventurers2_via_viber3d/": HUMANOID,
    "gh_kenney_mini_characters_1/": HUMANOID,
    "gh_quaternius_cute_fish_pack/": FISH,
    "gh_quaternius_cyberpunk_pack/": OTHER,  # robots on legs, flying drones
    "gh_quaternius_cyberpunk_pack/Character.glb": HUMANOID,
    "gh_quaternius_toon_shooter_via_pvp/": HUMANOID,
    "gh_quaternius_ultimate_animated_character_pack/": HUMANOID,
    "gh_quaternius_ultimate_monsters/": OTHER,  # blob_ (a four-joint blob rig) and flying_ monsters
    "gh_quaternius_ultimate_monsters/standing_": HUMANOID,  # two-legged monsters on the soldier's rig
    "gh_quaternius_ultimate_space_pack/": OTHER,  # enemies and walker mechs
    "gh_quaternius_ultimate_space_pack/Astronaut_": HUMANOID,
    "gh_quaternius_ultimate_space_pack/Enemy_Large.glb": HUMANOID,  # on the astronauts' rig
    "gh_quaternius_via_imagine_dungeons/": OTHER,  # limbless blob monsters, a dragon, Cthulhu
    "gh_quaternius_via_imagine_dungeons/Bat.glb": BIRD,
    "gh_redeclipse_actors/": OTHER,  # a wheeled robot
}
#: Files of one body (another texture, a small extra, another outfit), listed by the sources.
BODIES = (
    ("quaternius_glb/animals_pack/Horse.glb", "quaternius_glb/animals_pack/Horse_White.glb"),
    ("quaternius_glb/easy_enemies_pack/Snake.glb", "quaternius_glb/easy_enemies_pack/Snake_angry.glb"),
    ("kaykit/Rogue.glb", "kaykit/Rogue_Hooded.glb"),
    ("openclonk/oc_clonk.glb", "openclonk/oc_clonk_alchemist.glb", "openclonk/oc_clonk_farmer.glb",
     "openclonk/oc_clonk_steampunk.glb"),
    ("gh_quaternius_ultimate_monsters/standing_Orc.glb", "gh_quaternius_ultimate_monsters/standing_Orc_Skull.glb"),
    ("gh_quaternius_ultimate_animated_character_pack/Kimono_Female.glb",
     "gh_quaternius_ultimate_animated_character_pack/Zombie_Female.glb"),
    ("gh_quaternius_cyberpunk_pack/Enemy_Flying.glb", "gh_quaternius_cyberpunk_pack/Enemy_Flying_Gun.glb"),
)
#: The first split (53 characters): these folders, and of them these validation characters.
FIRST_SPLIT_FOLDERS = ("assimp_bsd/", "kaykit/", "khronos/", "quaternius_glb/")
FIRST_SPLIT_VALIDATION = (
    "assimp_bsd/X_BCN_Epileptic.glb", "kaykit/Rogue.glb", "kaykit/Rogue_Hooded.glb", "khronos/RiggedFigure.glb",
    "khronos/RiggedSimple.glb", "quaternius_glb/animals_pack/Cow.glb", "quaternius_glb/animals_pack/Donkey.glb",
    "quaternius_glb/animals_pack/Wolf.glb", "quaternius_glb/dinosaurs_pack/Stegosaurus.glb",
    "quaternius_glb/easy_enemies_pack/Wasp.glb", "quaternius_glb/fish_pack/Fish3.glb",
    "quaternius_glb/mech_pack/Leela.glb", "quaternius_glb/modular_men/Casual.glb",
    "quaternius_glb/modular_women/Casual.glb", "quaternius_glb/single_knight_pack/KnightCharacter.glb",
)
#: Characters whose skin weights are not trusted (path prefix -> reason): skeletons only.
SKELETON_ONLY = {
    "nexuiz/": "rigid weights (every vertex on one bone) and a rest pose that is the first idle frame (arms "
               "forward), converted from Nexuiz's .zym: not an artist's skinning",
}
#: Characters whose artist named the sides from the viewer, with the evidence: the bones named left lie on the
#: character's right. Their references are read with the sides swapped (``core.dataset.normalise.facing_decision``).
SIDES_NAMED_FROM_THE_VIEWER = {
    "gh_godot_demo_platformer/platformer_player.glb":
        "its face (eyes and mouth on the head's front) looks toward -Y as imported, its feet point there too, and its "
        "l- bones (l-arm, l-thigh...) lie at -X: on its right (docs/rigging.md, Key joints)",
}
#: Files left out of the split, with the reason.
_BROKEN_MIXAMO_MESH = (
    "a second mesh part (head piece or hair) stored at 100 times the body's scale lies 25 to 36 times the "
    "skeleton's size away from the body, so neither the normalised shape nor the skin is sound; the body's own "
    "weights pass the Mixamo-name check (every vertex weighted, hand and foot vertices on their bones)"
)
EXCLUDED = {
    "gh_quaternius_via_imagine_dungeons/cleric.glb": _BROKEN_MIXAMO_MESH,
    "gh_quaternius_via_imagine_dungeons/ranger.glb": _BROKEN_MIXAMO_MESH,
    "gh_quaternius_via_imagine_dungeons/rogue.glb": _BROKEN_MIXAMO_MESH,
}


def find_characters(root: str) -> list:
    """Sorted paths (relative to ``root``, '/' separated) of character files."""
    found = []
    for folder, _, files in os.walk(root):
        for name in files:
            if name.endswith(CHARACTER_SUFFIXES):
                found.append(os.path.relpath(os.path.join(folder, name), root).replace(os.sep, "/"))
    return sorted(found)


def longest_prefix_value(path: str, table: dict):
    """The value of the longest key of ``table`` that ``path`` starts with, or None."""
    matches = [key for key in table if path.startswith(key)]
    return table[max(matches, key=len)] if matches else None


def kind_of(path: str) -> str:
    kind = longest_prefix_value(path, KINDS)
    if kind is None:
        raise SystemExit(f"No kind for {path}: add its folder or its file to KINDS.")
    return kind


def companion_files(root: str, path: str) -> list:
    """Buffers and images a .gltf refers to (they travel with it)."""
    if not path.endswith(".gltf"):
        return []
    with open(os.path.join(root, path), encoding="utf-8") as handle:
        document = json.load(handle)
    folder = path.rsplit("/", 1)[0]
    uris = [item.get("uri") for key in ("buffers", "images") for item in document.get(key, [])]
    return sorted(f"{folder}/{uri}" for uri in uris if uri and not uri.startswith("data:"))


def file_rig_keys(root: str, path: str) -> tuple:
    document, buffers = read_gltf(os.path.join(root, path))
    return rig_keys(skin_rigs(document, buffers), declared_skeleton(document))


def make_split(root: str) -> dict:
    found = find_characters(root)
    if not found:
        raise SystemExit(f"No characters found under {root}.")
    paths = [path for path in found if path not in EXCLUDED]
    kinds = {path: kind_of(path) for path in paths}
    families = rig_families({path: file_rig_keys(root, path) for path in paths}, BODIES)
    earlier = {path: VALIDATION if path in FIRST_SPLIT_VALIDATION else TRAIN
               for path in paths if path.startswith(FIRST_SPLIT_FOLDERS)}
    sides = draw_split(families, kinds, earlier, VALIDATION_FRACTION, SPLIT_SEED)
    skeleton_only = {path: longest_prefix_value(path, SKELETON_ONLY) for path in paths
                     if longest_prefix_value(path, SKELETON_ONLY)}
    companions = {p: companion_files(root, p) for p in paths if companion_files(root, p)}
    by_kind = {kind: sorted(p for p in paths if kinds[p] == kind) for kind in sorted(set(kinds.values()))}
    return {
        "description": "Fixed split of the rigged characters by rig family and body; validation characters are "
                       "never trained on. Regenerate with scripts/make_split.py (see its docstring for the rule).",
        "root": DATA_ROOT,
        "seed": SPLIT_SEED,
        "validation_fraction": VALIDATION_FRACTION,
        "train": sorted(p for p in paths if sides[p] == TRAIN),
        "validation": sorted(p for p in paths if sides[p] == VALIDATION),
        "categories": by_kind,
        "families": [{"kind": kinds[family[0]],
                      "side": sides[family[0]] if len({sides[p] for p in family}) == 1 else "both",
                      "members": list(family)} for family in families],
        "near_duplicates": [list(group) for group in BODIES],
        "skeleton_only": skeleton_only,
        "excluded": {path: EXCLUDED[path] for path in found if path in EXCLUDED},
        "sides_named_from_the_viewer": {path: reason for path, reason in SIDES_NAMED_FROM_THE_VIEWER.items()
                                        if path in kinds},
        "companion_files": companions,
    }


def summary(split: dict) -> str:
    """Counts per kind and side (characters, families, usable for skin weights), one line each."""
    side_of = {path: side for side in (TRAIN, VALIDATION) for path in split[side]}
    lines = []
    for kind, members in split["categories"].items():
        counts = Counter(side_of[path] for path in members)
        families = Counter(family["side"] for family in split["families"] if family["kind"] == kind)
        skin = Counter(side_of[path] for path in members if path not in split["skeleton_only"])
        lines.append(f"{kind}: train {counts[TRAIN]} ({families[TRAIN]} families), validation {counts[VALIDATION]} "
                     f"({families[VALIDATION]} families), straddling families {families['both']}; "
                     f"for {PURPOSE_SKIN}: {skin[TRAIN]} / {skin[VALIDATION]}")
    return "\n".join(lines)


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
    print(f"wrote {args.output}: {len(split['train'])} train, {len(split['validation'])} validation, "
          f"{len(split['families'])} families, {len(split['excluded'])} left out\n{summary(split)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
