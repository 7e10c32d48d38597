"""Training a skinning network: what ``python -m autorig_addon train skin
--model NAME`` does.

1. The training characters of ``data_split.json`` are read from the sample
   cache; their examples, with augmented variants, are built or reused
   (:mod:`.training_set`).
2. Every :data:`...runs.HOLDOUT_EVERY`-th training character (sorted by
   name) is held out to pick the epoch; its variants are not trained on.
3. :func:`...nn.fit.fit`: one character per step, at most
   :data:`...runs.CHARACTERS_PER_FAMILY` of each skeleton family per epoch,
   each as itself or one of its variants drawn at random
   (:func:`...runs.epoch_steps`), turned by a random angle
   about the up axis and mirrored left-right with probability one half
   (:func:`...nn.augmentation.turn_and_mirror` on the feature vectors:
   neither changes a distance, so no example has to be rebuilt). The loss
   is the cross-entropy between the artist's weights of each vertex's
   candidates and the predicted ones (RigNet's), over vertices the artist
   weighted. After every epoch the network, as numpy runs it, skins the
   held-out characters; the epoch of lowest mean L1 is kept and written
   with the run's record.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Optional

import numpy as np
import torch

from ....core.dataset.cache import training_samples
from ....core.dataset.split import PURPOSE_SKIN
from ....core.evaluation.skin_metrics import influence_precision_recall, skin_l1
from ....core.skinning.geometric import DEFAULT_MAX_INFLUENCES
from ....core.skinning.learned.features import BONE_VECTORS, PAIR_VECTORS, VERTEX_VECTORS, SkinGraph
from ....core.skinning.learned.networks import skin_network
from ....core.skinning.learned.networks.scoring import SkinNetworkSpec, candidate_weights
from ....core.skinning.learned.predict import dense_weights, network_candidate_weights, pruned_weights
from ...nn.augmentation import turn_and_mirror, turned_columns
from ...nn.fit import FitRecord, Log, fit, log_to_stderr
from ...nn.modules import NetworkModule, as_tensors
from ...nn.torch_kernels import TORCH
from ...runs import (
    character_families,
    epoch_step_count,
    epoch_steps,
    held_out_names,
    procedural_samples,
    start_run,
    write_weights,
)
from .training_set import build_examples, load_example

#: What the kept epoch minimises.
SCORE_NAME = "l1"


def augmented(graph: SkinGraph, matrix: np.ndarray) -> SkinGraph:
    """The graph (of tensors) turned/mirrored by the (3, 3) ``matrix``."""
    turn = torch.as_tensor(matrix, dtype=graph.vertex_features.dtype, device=graph.vertex_features.device)
    return replace(graph, vertex_features=turned_columns(TORCH, graph.vertex_features, VERTEX_VECTORS, turn),
                   pair_features=turned_columns(TORCH, graph.pair_features, PAIR_VECTORS, turn),
                   bone_features=turned_columns(TORCH, graph.bone_features, BONE_VECTORS, turn))


def predicted_weights(module: NetworkModule, graph: SkinGraph) -> torch.Tensor:
    """(n, K) candidate weights of the module on a graph of tensors."""
    return candidate_weights(TORCH, module.params(), graph, module(graph))


def candidate_cross_entropy(predicted: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Mean over weighted vertices of ``-sum target * log predicted``."""
    weighted = target.sum(dim=1) > 0
    log_predicted = torch.log(predicted.clamp_min(1e-8))
    per_vertex = -(target * log_predicted).sum(dim=1)[weighted]
    # A character the artist left unweighted teaches nothing (and the mean
    # of nothing would be NaN).
    return per_vertex.mean() if len(per_vertex) else per_vertex.sum()


def holdout_scores(spec: SkinNetworkSpec, weights: dict, holdout: list) -> dict:
    """Mean L1, precision and recall of the numpy forward pass on the
    held-out examples ``[(graph, reference), ...]``."""
    l1s, precisions, recalls = [], [], []
    for graph, reference in holdout:
        candidate = network_candidate_weights(spec, graph, weights)
        predicted = pruned_weights(dense_weights(graph, candidate), DEFAULT_MAX_INFLUENCES)
        l1s.append(skin_l1(predicted, reference))
        scores = influence_precision_recall(predicted, reference)
        precisions.append(scores["precision"])
        recalls.append(scores["recall"])
    return {"l1": float(np.mean(l1s)), "precision": float(np.mean(precisions)), "recall": float(np.mean(recalls))}


def train_network(spec: SkinNetworkSpec, train: list, holdout: list, record: FitRecord,
                  log: Log = log_to_stderr) -> dict:
    """Train ``spec``'s network from scratch (torch seeded by the caller,
    :func:`...runs.start_run`); returns the kept weights.

    Parameters
    ----------
    spec : SkinNetworkSpec
    train : list of ``(name, graph, target)``: numpy SkinGraph and (n, K)
        targets; ``name`` is ``CHARACTER--VARIANT``
    holdout : list of ``(name, graph, reference)``: scored after each epoch
    record : FitRecord of the run (settings in, results out)
    log : where the progress lines go
    """
    rng = np.random.default_rng(record.seed)
    module = NetworkModule(spec).to(record.device)
    tensors = [(as_tensors(graph, record.device), torch.as_tensor(target, device=record.device))
               for _, graph, target in train]
    held = [(graph, reference) for _, graph, reference in holdout]
    characters = [example_character(name) for name, _, _ in train]
    families = character_families(characters)
    steps = epoch_step_count(characters, families)
    record.details.update(train_examples=len(train), train_characters=len(set(characters)), steps_per_epoch=steps,
                          holdout_examples=[name for name, _, _ in holdout])

    def epoch_losses():
        for index in epoch_steps(characters, families, rng):
            graph, target = tensors[index]
            yield lambda: candidate_cross_entropy(predicted_weights(module, augmented(graph, turn_and_mirror(rng))),
                                                  target)

    return fit(module, epoch_losses, lambda weights: holdout_scores(spec, weights, held), record=record,
               steps_per_epoch=steps, log=log)


def example_character(name: str) -> str:
    """The character an example was made from (its name is ``CHARACTER--VARIANT``)."""
    return name.rsplit("--", 1)[0]


def run_training(network: str, *, sample_dir: Path, examples_dir: Optional[Path] = None, epochs: Optional[int] = None,
                 seed: int = 0, device: str = "auto", output: Optional[Path] = None, augment: bool = True,
                 learning_rate: Optional[float] = None, procedural: int = 0,
                 split_file: Optional[str] = None) -> FitRecord:
    """Train the skinning network ``network`` and write its weights; returns
    the run's record. ``epochs`` and ``learning_rate`` default to the
    network's spec (its shipped weights' run)."""
    spec = skin_network(network)
    record = start_run(spec, seed=seed, device=device, epochs=epochs, learning_rate=learning_rate,
                       score_name=SCORE_NAME)
    samples = training_samples(sample_dir, split_file, PURPOSE_SKIN)
    held_names = held_out_names([sample.name for sample in samples])
    samples = samples + procedural_samples(procedural)  # never held out: the epoch is chosen on artists' rigs
    train, holdout = [], []
    for sample in samples:
        held = sample.name in held_names
        for path in build_examples([sample], spec.distance, prior=spec.prior, augment=augment and not held,
                                   seed=seed, folder=examples_dir):
            graph, target, reference, name = load_example(path)
            (holdout if held else train).append((name, graph, reference if held else target))
    weights = train_network(spec, train, holdout, record)
    record.details.update(distance=spec.distance, prior=spec.prior, augment=augment, procedural=procedural)
    write_weights(spec, weights, record, output)
    return record
