"""One training run of a skinning network, from cached samples to a shipped
weights file: what ``python -m autorig_addon train skin`` does.

1. The training characters of ``data_split.json`` are read from the sample
   cache (``.npz``, :mod:`autorig_addon.core.dataset`); no Blender needed.
2. Their examples, with augmented variants, are built or reused
   (:mod:`autorig_addon.core.skinning.learned.training_set`).
3. Every :data:`HOLDOUT_EVERY`-th training character (sorted by name) is
   held out to pick the epoch; its variants are not trained on.
4. :func:`.skin_training.train_network`, then the kept weights are written
   with the run's record as metadata.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import torch

from ...dataset.cache import training_samples
from ...dataset.sample import CharacterSample
from ...errors import InputError
from ...nn.weights_io import save_weights
from ...skinning.learned.predict import NETWORK_PRIORS, network_distance, trained_weights_path
from ...skinning.learned.training_set import (
    TRAINING_SETTINGS, build_examples, load_example,
)
from .skin_training import train_network

#: Every this-many-th training character (by sorted name) is held out to
#: choose the epoch: 7 of the 38.
HOLDOUT_EVERY = 6
#: CPU threads torch trains with.
TRAINING_THREADS = 1


def procedural_samples(count: int) -> list[CharacterSample]:
    """The procedural characters of seeds ``0 .. count - 1`` as samples
    (weights from how each piece was built, :mod:`...procedural`)."""
    from ...procedural import generate_character

    samples = []
    for seed in range(count):
        character = generate_character(seed)
        samples.append(CharacterSample.from_character(f"procedural/{character.kind}_{seed}", character.kind,
                                                      character.mesh, character.skeleton, character.weights))
    return samples


def pick_device(requested: str) -> str:
    if requested == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    if requested == "cuda" and not torch.cuda.is_available():
        raise InputError("--device cuda was asked for but torch sees no GPU.")
    return requested


def run_training(network: str, *, sample_dir: Path, examples_dir: Optional[Path] = None, epochs: Optional[int] = None,
                 seed: int = 0, device: str = "auto", output: Optional[Path] = None, augment: bool = True,
                 learning_rate: Optional[float] = None, procedural: int = 0,
                 split_file: Optional[str] = None) -> dict:
    """Train ``network`` and write its weights; returns the run's record.
    ``epochs`` and ``learning_rate`` default to the network's
    :data:`...skinning.learned.training_set.TRAINING_SETTINGS`."""
    distance = network_distance(network)
    default_epochs, default_rate = TRAINING_SETTINGS[network]
    epochs = default_epochs if epochs is None else epochs
    learning_rate = default_rate if learning_rate is None else learning_rate
    # The graphs are small (about 3,000 vertices): one thread is as fast as
    # two on this machine and never fights other work for the cores.
    torch.set_num_threads(TRAINING_THREADS)
    samples = training_samples(sample_dir, split_file)
    holdout_names = {sample.name for sample in samples[::HOLDOUT_EVERY]}
    samples = samples + procedural_samples(procedural)  # never held out: the epoch is chosen on artists' rigs
    train, holdout = [], []
    for sample in samples:
        held = sample.name in holdout_names
        for path in build_examples([sample], distance, prior=NETWORK_PRIORS[network], augment=augment and not held,
                                   seed=seed, folder=examples_dir):
            graph, target, reference, name = load_example(path)
            if held:
                holdout.append((name, graph, reference))
            else:
                train.append((name, graph, target))
    weights, record = train_network(network, train, holdout, epochs=epochs, seed=seed, device=pick_device(device),
                                    learning_rate=learning_rate)
    record.train_examples = len(record.train_examples)
    metadata = record.metadata()
    metadata.update(distance=distance, augment=augment, procedural=procedural, torch_version=torch.__version__,
                    python=sys.version.split()[0])
    destination = Path(output) if output else trained_weights_path(network)
    destination.parent.mkdir(parents=True, exist_ok=True)
    save_weights(str(destination), weights, metadata)
    return metadata
