"""What every training run shares, from cached samples to a shipped weights
file: the device and threads, which training characters are held out to
pick the epoch, the procedural characters a run may add, and writing the
kept weights with the run's record.

Training reads the characters of ``data_split.json`` from the sample cache
(``.npz``, :mod:`autorig_addon.core.dataset`) alone: no Blender, so it also
runs on a machine without ``bpy`` (the GPU machine).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Optional, Sequence

import numpy as np
import torch

from ..core.dataset.sample import CharacterSample
from ..core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split
from ..core.errors import InputError
from ..core.nn.spec import NetworkSpec, forget_shipped_weights
from ..core.nn.weights_io import save_weights
from .nn.fit import FitRecord

#: Every this-many-th training character (by sorted name) is held out to
#: choose the epoch; its variants are not trained on.
HOLDOUT_EVERY = 6
#: CPU threads torch trains with: the graphs are small (about 3,000
#: vertices), and one thread is as fast as two on this machine and never
#: fights other work for the cores.
TRAINING_THREADS = 1
#: Most characters of one skeleton family an epoch trains on, each with one
#: of its variants drawn at random. Without it the 133 0 A.D. humans (14
#: bodies with many heads on one skeleton) would be two steps in five and
#: the 33 fish of one pack the next most; with it an epoch is about 150
#: steps, so training on the 419-character set stays within the hour.
CHARACTERS_PER_FAMILY = 8


def pick_device(requested: str) -> str:
    """``cpu`` or ``cuda`` for a requested device (``auto``: the GPU when torch sees one)."""
    if requested == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    if requested == "cuda" and not torch.cuda.is_available():
        raise InputError("--device cuda was asked for but torch sees no GPU.")
    return requested


def start_run(spec: NetworkSpec, *, seed: int, device: str, epochs: Optional[int], learning_rate: Optional[float],
              score_name: str) -> FitRecord:
    """Seed torch, set its threads and make the run's record: ``epochs`` and
    ``learning_rate`` default to the spec's training settings."""
    torch.set_num_threads(TRAINING_THREADS)
    torch.manual_seed(seed)
    return FitRecord(spec.name, seed, epochs or spec.training.epochs,
                     learning_rate or spec.training.learning_rate, pick_device(device), score_name)


def held_out_names(names: list[str]) -> set[str]:
    """The training characters held out to choose the epoch: every
    :data:`HOLDOUT_EVERY`-th by sorted name."""
    return set(sorted(names)[::HOLDOUT_EVERY])


def character_families(names: Sequence[str], split_file: Optional[str] = None) -> dict[str, int]:
    """Family of each character name (its path without extension) by
    ``data_split.json``'s ``families``; a name the split does not list (a
    procedural character, a test's) is a family of its own."""
    split = read_data_split(split_file or DEFAULT_SPLIT_FILE)
    listed = {os.path.splitext(path)[0]: family for path, family in split.families.items()}
    next_own = max(listed.values(), default=-1) + 1
    families = {}
    for name in names:
        if name in families:
            continue
        if name in listed:
            families[name] = listed[name]
        else:
            families[name], next_own = next_own, next_own + 1
    return families


def epoch_steps(example_characters: Sequence[str], families: dict[str, int], rng: np.random.Generator,
                per_family: int = CHARACTERS_PER_FAMILY) -> list[int]:
    """One epoch's training examples, as indices into ``example_characters``
    (the character each example was made from), shuffled: at most
    ``per_family`` characters of each family, drawn anew every epoch, each
    with one of its examples (the character or a variant) drawn at random.
    The count is the same every epoch (:func:`epoch_step_count`)."""
    by_character: dict[str, list[int]] = {}
    for index, character in enumerate(example_characters):
        by_character.setdefault(character, []).append(index)
    by_family: dict[int, list[str]] = {}
    for character in by_character:
        by_family.setdefault(families[character], []).append(character)
    steps = []
    for family in sorted(by_family):
        members = by_family[family]
        for pick in rng.permutation(len(members))[:per_family]:
            examples = by_character[members[pick]]
            steps.append(examples[rng.integers(len(examples))])
    return [steps[index] for index in rng.permutation(len(steps))]


def epoch_step_count(example_characters: Sequence[str], families: dict[str, int],
                     per_family: int = CHARACTERS_PER_FAMILY) -> int:
    """How many steps :func:`epoch_steps` gives per epoch."""
    sizes: dict[int, int] = {}
    for character in set(example_characters):
        sizes[families[character]] = sizes.get(families[character], 0) + 1
    return sum(min(size, per_family) for size in sizes.values())


def family_sample(names: Sequence[str], families: dict[str, int], per_family: int) -> list[str]:
    """At most ``per_family`` of ``names`` from each family, the first by
    sorted name: the same every call."""
    taken: dict[int, int] = {}
    kept = []
    for name in sorted(names):
        family = families[name]
        if taken.get(family, 0) < per_family:
            taken[family] = taken.get(family, 0) + 1
            kept.append(name)
    return kept


def procedural_samples(count: int) -> list[CharacterSample]:
    """The procedural characters of seeds ``0 .. count - 1`` as samples
    (weights from how each piece was built, :mod:`autorig_addon.core.procedural`);
    a run trains on them but never holds them out, so the epoch is still
    chosen on artists' rigs."""
    from ..core.procedural import generate_character

    samples = []
    for seed in range(count):
        character = generate_character(seed)
        samples.append(CharacterSample.from_character(f"procedural/{character.kind}_{seed}", character.kind,
                                                      character.mesh, character.skeleton, character.weights))
    return samples


def write_weights(spec: NetworkSpec, weights: dict, record: FitRecord, output: Optional[Path]) -> Path:
    """Save the kept weights at half precision with the run's record (and the
    software that made them) where the extension reads them, or to ``output``."""
    spec.check_weights(weights, f"the trained {spec.name} network")
    destination = Path(output) if output else spec.weights_file
    destination.parent.mkdir(parents=True, exist_ok=True)
    metadata = {**record.metadata(), "torch_version": torch.__version__, "python": sys.version.split()[0]}
    save_weights(str(destination), weights, metadata, half_precision=True)
    forget_shipped_weights()
    return destination
