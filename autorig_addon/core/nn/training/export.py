"""A trained torch module to and from the flat weights dict that
:mod:`autorig_addon.core.nn.weights_io` saves and the numpy forward pass
reads (names = the module's ``state_dict`` keys).
"""

from __future__ import annotations

from typing import Optional

import numpy as np
import torch

from ..weights_io import save_weights


def module_weights(module: torch.nn.Module) -> dict:
    """``module``'s ``state_dict`` as numpy arrays (copies on the CPU, dtypes
    kept: float parameters and buffers, batch norm's int64 batch counter)."""
    return {name: tensor.detach().cpu().numpy().copy() for name, tensor in module.state_dict().items()}


def load_module_weights(module: torch.nn.Module, weights: dict) -> None:
    """Put ``weights`` (every name of the module's ``state_dict``, no other)
    into ``module``; raises torch's error on a missing or extra name."""
    module.load_state_dict({name: torch.from_numpy(np.array(value)) for name, value in weights.items()}, strict=True)


def save_module(module: torch.nn.Module, path: str, metadata: Optional[dict] = None) -> None:
    """Write ``module``'s weights (and ``metadata``) as a weights file."""
    save_weights(path, module_weights(module), metadata)
