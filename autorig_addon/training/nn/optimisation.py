"""The optimiser every network's training shares: Adam with a small weight
decay, its learning rate annealed along a cosine to zero over the run's
steps (one scheduler step per optimiser step).

:meth:`CosineAdam.step` does the calls of one step in a fixed order
(``zero_grad``, ``backward``, ``step``, the schedule's ``step``), so a
seeded run reproduces.
"""

from __future__ import annotations

from typing import Iterable

import torch

#: Weight decay of Adam (small networks trained on few characters).
WEIGHT_DECAY = 1e-5


class CosineAdam:
    """Adam whose learning rate falls along a cosine from ``learning_rate``
    to zero over ``steps`` steps.

    Parameters
    ----------
    parameters : iterable of tensors, the model's parameters
    learning_rate : float > 0, the starting learning rate
    steps : int >= 1, the optimiser steps of the whole run (the schedule's
        ``T_max``)
    weight_decay : float >= 0, Adam's weight decay
    """

    def __init__(self, parameters: Iterable[torch.Tensor], learning_rate: float, steps: int, *,
                 weight_decay: float = WEIGHT_DECAY):
        self.optimiser = torch.optim.Adam(parameters, lr=learning_rate, weight_decay=weight_decay)
        self.schedule = torch.optim.lr_scheduler.CosineAnnealingLR(self.optimiser, T_max=steps)

    def step(self, loss: torch.Tensor) -> None:
        """One step down ``loss`` (a scalar tensor), then one along the schedule."""
        self.optimiser.zero_grad()
        loss.backward()
        self.optimiser.step()
        self.schedule.step()
