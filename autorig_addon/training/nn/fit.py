"""The one training loop every network shares.

An epoch takes the optimiser steps the network's task hands out (one per
training character, or one full batch), then the network, as numpy will
run it inside Blender, is scored on the held-out training characters
(never the validation ones, which only ``eval`` sees); the epoch with the
lowest score is kept, the untrained network (epoch 0) included. Fixed
seeds and a fixed order of random draws make a run reproduce on the same
device: ``torch.manual_seed`` before the module is built, then the
task's draws from one ``numpy`` generator.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import asdict, dataclass, field
from typing import Callable, Iterable

import numpy as np
import torch

from .modules import NetworkModule, module_weights, parameter_count
from .optimisation import CosineAdam

#: A step's loss: called once, in order, with the module in training mode.
Loss = Callable[[], torch.Tensor]
Log = Callable[[str], None]


def log_to_stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


@dataclass
class FitRecord:
    """What a run did; saved as the weights file's metadata.

    Attributes
    ----------
    network, seed, epochs, learning_rate, device : the run's settings
    score_name : str, what the held-out score measures (lower is better)
    parameters : int, learned numbers
    history : list of dict, per logged epoch: loss and held-out scores
    best_epoch : int, the kept epoch (0: the untrained network)
    best_score : float, its held-out score
    seconds : float, the training's wall time
    details : dict, what the task adds (examples, held-out names, accuracy)
    """

    network: str
    seed: int
    epochs: int
    learning_rate: float
    device: str
    score_name: str
    parameters: int = 0
    history: list = field(default_factory=list)
    best_epoch: int = -1
    best_score: float = math.inf
    seconds: float = 0.0
    details: dict = field(default_factory=dict)

    def metadata(self) -> dict:
        record = asdict(self)
        details = record.pop("details")
        return {**record, **details}


def fit(module: NetworkModule, epoch_losses: Callable[[], Iterable[Loss]], holdout_scores: Callable[[dict], dict], *,
        record: FitRecord, steps_per_epoch: int, log: Log = log_to_stderr, log_every: int = 1) -> dict:
    """Train ``module`` and return the kept epoch's weights (numpy, by
    ``state_dict`` name); ``record`` is filled in as it goes.

    Parameters
    ----------
    module : NetworkModule, freshly built (seeded)
    epoch_losses : callable giving one epoch's step losses in order (it
        draws the epoch's shuffle and augmentation as it goes)
    holdout_scores : callable ``weights -> {name: value}`` holding
        ``record.score_name``, lower is better (the numpy forward on the
        held-out characters)
    record : FitRecord, the run's settings; its results are written here
    steps_per_epoch : int, steps :func:`epoch_losses` gives (the cosine
        schedule spans ``epochs * steps_per_epoch`` steps)
    log, log_every : where progress goes, and every how many epochs
        (the history keeps those epochs too)
    """
    record.parameters = parameter_count(module)
    optimiser = CosineAdam(module.parameters(), record.learning_rate, record.epochs * steps_per_epoch)
    best = module_weights(module)
    scores = holdout_scores(best)
    record.history.append({"epoch": 0, "loss": None, **scores})
    record.best_epoch, record.best_score = 0, scores[record.score_name]
    log(f"{record.network}: {record.parameters} parameters, untrained {record.score_name} {record.best_score:.4f}")
    started = time.perf_counter()
    for epoch in range(1, record.epochs + 1):
        module.train()
        losses = []
        for loss_of in epoch_losses():
            loss = loss_of()
            optimiser.step(loss)
            losses.append(loss.item())
        module.eval()
        weights = module_weights(module)
        with torch.no_grad():
            scores = holdout_scores(weights)
        kept = scores[record.score_name] < record.best_score
        if kept:
            best, record.best_epoch, record.best_score = weights, epoch, scores[record.score_name]
        if epoch % log_every == 0 or epoch == record.epochs:
            elapsed = time.perf_counter() - started
            record.history.append({"epoch": epoch, "loss": float(np.mean(losses)), **scores})
            shown = " ".join(f"{name} {value:.4f}" for name, value in scores.items())
            log(f"{record.network} [{'#' * int(20 * epoch / record.epochs):<20}] epoch {epoch}/{record.epochs} "
                f"loss {np.mean(losses):.4f} held out: {shown}{' (kept)' if kept else ''} {elapsed:.0f} s, "
                f"~{elapsed / epoch * (record.epochs - epoch):.0f} s left")
    record.seconds = time.perf_counter() - started
    return best
