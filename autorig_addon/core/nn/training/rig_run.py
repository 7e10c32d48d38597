"""One training run of a skeleton network, from cached samples to a shipped
weights file: what ``python -m autorig_addon train rig --model NAME`` does.

1. The training characters of ``data_split.json`` are read from the sample
   cache (no Blender needed); their examples with stretched variants are
   built once or reused (:mod:`autorig_addon.core.rigging.training_set`).
2. Every :data:`.skin_run.HOLDOUT_EVERY`-th training character (sorted by
   name) is held out to pick the epoch; its variants are not trained on.
3. :mod:`.rig_training` trains; the kept weights are written with the
   run's record as metadata.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

import torch

from ...dataset.cache import default_cache_dir, training_samples
from ...errors import InputError
from ...nn.weights_io import save_weights
from ...rigging.predict import DEFAULT_BANDWIDTH, DEFAULT_DENSITY_THRESHOLD, NETWORK_NAMES, trained_weights_path
from ...rigging.training_set import EXAMPLE_FORMAT_VERSION, TRAINING_SETTINGS, build_examples
from .rig_training import train_connectivity_network, train_joint_network
from .skin_run import HOLDOUT_EVERY, TRAINING_THREADS, pick_device, procedural_samples


def default_examples_dir(seed: int) -> Path:
    return default_cache_dir().parent / "rig_examples" / f"v{EXAMPLE_FORMAT_VERSION}" / f"seed{seed}"


def run_rig_training(network: str, *, sample_dir: Path, examples_dir: Optional[Path] = None,
                     epochs: Optional[int] = None, learning_rate: Optional[float] = None, seed: int = 0,
                     device: str = "auto", output: Optional[Path] = None, procedural: int = 0) -> dict:
    """Train ``network`` (``joints``, ``bones`` or ``root``) and write its weights; returns the record.

    ``procedural`` adds the procedural characters of seeds ``0 .. procedural - 1``
    (exact skeletons) as training characters; they are never held out, so
    the epoch is still chosen on artists' rigs.
    """
    if network not in NETWORK_NAMES:
        raise InputError(f"Unknown skeleton network '{network}': use one of {NETWORK_NAMES}.")
    torch.set_num_threads(TRAINING_THREADS)
    shipped_epochs, shipped_rate = TRAINING_SETTINGS[network]
    epochs = epochs or shipped_epochs
    learning_rate = learning_rate or shipped_rate
    samples = training_samples(Path(sample_dir))
    examples = build_examples(samples, Path(examples_dir or default_examples_dir(seed)), seed,
                              log=lambda line: print(line, file=sys.stderr, flush=True))
    names = sorted(examples)
    held_names = set(names[::HOLDOUT_EVERY])
    made = build_examples(procedural_samples(procedural), Path(examples_dir or default_examples_dir(seed)), seed,
                          log=lambda line: print(line, file=sys.stderr, flush=True))
    train = [example for name in names if name not in held_names for example in examples[name]]
    train += [example for name in sorted(made) for example in made[name]]
    # Held-out characters are scored as they are, not on their stretched copies.
    holdout = [examples[name][0] for name in names if name in held_names]
    device = pick_device(device)
    if network == "joints":
        weights, record = train_joint_network(train, holdout, epochs=epochs, learning_rate=learning_rate, seed=seed,
                                              device=device, bandwidth=DEFAULT_BANDWIDTH,
                                              density_threshold=DEFAULT_DENSITY_THRESHOLD)
    else:
        weights, record = train_connectivity_network(network, train, holdout, epochs=epochs,
                                                     learning_rate=learning_rate, seed=seed, device=device)
    record.update(procedural=procedural, torch_version=torch.__version__, python=sys.version.split()[0])
    destination = Path(output) if output else trained_weights_path(network)
    destination.parent.mkdir(parents=True, exist_ok=True)
    save_weights(str(destination), weights, record)
    return record
