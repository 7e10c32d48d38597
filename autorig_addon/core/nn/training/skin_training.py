"""Training a skinning network from its examples (torch; never in Blender).

One run: fixed seed, Adam with a cosine learning-rate schedule
(:class:`.optimisation.CosineAdam`), one character per step. Each step turns the character by a random angle about
the up axis and mirrors it left-right with probability one half
(:func:`.augmentation.turn_and_mirror`), applied to the feature vectors
(:data:`~autorig_addon.core.skinning.learned.features.VERTEX_VECTORS` and
friends): neither changes a distance, so no example has to be rebuilt. The
loss is the cross-entropy between the artist's weights of each vertex's
candidates and the predicted ones (RigNet's), over vertices the artist
weighted.

After every epoch the network, as numpy runs it, skins the held-out
training characters (never the validation ones, which only ``eval``
sees) and the epoch with the lowest mean L1 is kept.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np
import torch

from ...evaluation.skin_metrics import influence_precision_recall, skin_l1
from ...skinning.geometric import DEFAULT_MAX_INFLUENCES
from ...skinning.learned.training_set import DEFAULT_LEARNING_RATE
from ...skinning.learned.features import BONE_VECTORS, PAIR_VECTORS, VERTEX_VECTORS, SkinGraph
from ...skinning.learned.networks import SCORE_FUNCTIONS, candidate_weights
from ...skinning.learned.predict import dense_weights, finished_weights
from .augmentation import turn_and_mirror, turned_columns
from .export import module_weights
from .optimisation import CosineAdam
from .skin_networks import NETWORKS, graph_tensors


@dataclass
class TrainingRecord:
    """What a run did: settings, per-epoch scores and the kept epoch."""

    network: str
    seed: int
    epochs: int
    learning_rate: float
    device: str
    train_examples: list
    holdout_examples: list
    parameters: int = 0
    history: list = field(default_factory=list)
    best_epoch: int = -1
    best_l1: float = math.inf
    seconds: float = 0.0

    def metadata(self) -> dict:
        return {key: value for key, value in self.__dict__.items()}


def augmented(graph: SkinGraph, matrix: np.ndarray) -> SkinGraph:
    """The graph (of tensors) turned/mirrored by the (3, 3) ``matrix``."""
    turn = torch.as_tensor(matrix, dtype=graph.vertex_features.dtype, device=graph.vertex_features.device)
    return replace(graph, vertex_features=turned_columns(graph.vertex_features, VERTEX_VECTORS, turn),
                   pair_features=turned_columns(graph.pair_features, PAIR_VECTORS, turn),
                   bone_features=turned_columns(graph.bone_features, BONE_VECTORS, turn))


def candidate_cross_entropy(predicted: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Mean over weighted vertices of ``-sum target * log predicted``."""
    weighted = target.sum(dim=1) > 0
    log_predicted = torch.log(predicted.clamp_min(1e-8))
    per_vertex = -(target * log_predicted).sum(dim=1)[weighted]
    # A character the artist left unweighted teaches nothing (and the mean
    # of nothing would be NaN).
    return per_vertex.mean() if len(per_vertex) else per_vertex.sum()


def holdout_scores(network: str, weights: dict, holdout: list) -> dict:
    """Mean L1, precision and recall of the numpy forward pass on the
    held-out examples ``[(graph, reference), ...]``."""
    l1s, precisions, recalls = [], [], []
    for graph, reference in holdout:
        candidate = candidate_weights(SCORE_FUNCTIONS[network](weights, graph), graph, float(weights["prior_scale"]))
        predicted = finished_weights(dense_weights(graph, candidate), DEFAULT_MAX_INFLUENCES)
        l1s.append(skin_l1(predicted, reference))
        scores = influence_precision_recall(predicted, reference)
        precisions.append(scores["precision"])
        recalls.append(scores["recall"])
    return {"l1": float(np.mean(l1s)), "precision": float(np.mean(precisions)), "recall": float(np.mean(recalls))}


def train_network(network: str, train: list, holdout: list, *, epochs: int, seed: int = 0,
                  learning_rate: float = DEFAULT_LEARNING_RATE, device: str = "cpu", width: int = 64,
                  log: Callable[[str], None] = lambda line: print(line, file=sys.stderr, flush=True),
                  ) -> tuple[dict, TrainingRecord]:
    """Train ``network`` from scratch.

    Parameters
    ----------
    network : a key of :data:`.skin_networks.NETWORKS`
    train : list of ``(name, graph, target)``: numpy SkinGraph and (n, K) targets
    holdout : list of ``(name, graph, reference)``: scored after each epoch
    epochs, seed, learning_rate, device, width : the run's settings
    log : where the progress lines go

    Returns
    -------
    weights : dict of numpy arrays, the kept epoch's ``state_dict``
    record : TrainingRecord
    """
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    model = NETWORKS[network](width=width).to(device)
    record = TrainingRecord(network, seed, epochs, learning_rate, device, [name for name, _, _ in train],
                            [name for name, _, _ in holdout],
                            parameters=sum(parameter.numel() for parameter in model.parameters()))
    tensors = [(graph_tensors(graph, device), torch.as_tensor(target, device=device)) for _, graph, target in train]
    held = [(graph, reference) for _, graph, reference in holdout]
    optimiser = CosineAdam(model.parameters(), learning_rate, epochs * len(tensors))
    best = module_weights(model)
    record.history.append({"epoch": 0, "loss": None, **holdout_scores(network, best, held)})
    record.best_epoch, record.best_l1 = 0, record.history[0]["l1"]
    log(f"{network}: {record.parameters} parameters, {len(tensors)} examples, untrained (the prior): "
        f"holdout L1 {record.best_l1:.4f}")
    started = time.perf_counter()
    for epoch in range(1, epochs + 1):
        model.train()
        losses = []
        for index in rng.permutation(len(tensors)):
            graph, target = tensors[index]
            loss = candidate_cross_entropy(model(augmented(graph, turn_and_mirror(rng))), target)
            optimiser.step(loss)
            losses.append(loss.item())
        model.eval()
        weights = module_weights(model)
        scores = holdout_scores(network, weights, held)
        record.history.append({"epoch": epoch, "loss": float(np.mean(losses)), **scores})
        kept = scores["l1"] < record.best_l1
        if kept:
            best, record.best_epoch, record.best_l1 = weights, epoch, scores["l1"]
        elapsed = time.perf_counter() - started
        bar = "#" * int(20 * epoch / epochs)
        log(f"{network} [{bar:<20}] epoch {epoch}/{epochs} loss {np.mean(losses):.4f} holdout L1 {scores['l1']:.4f} "
            f"precision {scores['precision']:.3f} recall {scores['recall']:.3f}{' (kept)' if kept else ''} "
            f"{elapsed:.0f} s, ~{elapsed / epoch * (epochs - epoch):.0f} s left")
    record.seconds = time.perf_counter() - started
    return best, record
