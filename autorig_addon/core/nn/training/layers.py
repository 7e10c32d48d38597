"""Dense layers in torch: the training twins of
:mod:`autorig_addon.core.nn.layers`, and the ``MLP`` module whose
``state_dict`` the numpy :func:`~autorig_addon.core.nn.layers.mlp` reads
(``linears.K.*``, ``norms.K.*``). The constants (leaky slope, ELU alpha,
norm epsilon) are the numpy module's, declared there once.
"""

from __future__ import annotations

from typing import Optional, Sequence

import torch
import torch.nn.functional as F
from torch import nn

from ..layers import ELU_ALPHA, LEAKY_RELU_SLOPE, NORM_EPSILON, NORM_KINDS


def linear(x: torch.Tensor, weight: torch.Tensor, bias: Optional[torch.Tensor] = None) -> torch.Tensor:
    """``x @ weight.T + bias``, as the numpy twin."""
    return F.linear(x, weight, bias)


def relu(x: torch.Tensor) -> torch.Tensor:
    return F.relu(x)


def leaky_relu(x: torch.Tensor, slope: float = LEAKY_RELU_SLOPE) -> torch.Tensor:
    return F.leaky_relu(x, slope)


def elu(x: torch.Tensor, alpha: float = ELU_ALPHA) -> torch.Tensor:
    return F.elu(x, alpha)


def identity(x: torch.Tensor) -> torch.Tensor:
    return x


#: Activations by name, as in the numpy twin.
ACTIVATIONS = {
    "relu": relu,
    "leaky_relu": leaky_relu,
    "elu": elu,
    "none": identity,
}


def layer_norm(x: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor,
               epsilon: float = NORM_EPSILON) -> torch.Tensor:
    return F.layer_norm(x, x.shape[-1:], weight, bias, epsilon)


def batch_norm(x: torch.Tensor, running_mean: torch.Tensor, running_var: torch.Tensor, weight: torch.Tensor,
               bias: torch.Tensor, epsilon: float = NORM_EPSILON) -> torch.Tensor:
    """Batch normalisation with stored statistics (inference form)."""
    return F.batch_norm(x, running_mean, running_var, weight, bias, training=False, eps=epsilon)


class MLP(nn.Module):
    """A multi-layer perceptron, each layer linear -> norm -> activation.

    Parameters
    ----------
    channels : sequence of int
        Feature widths ``[in, hidden..., out]``; ``len(channels) - 1`` layers.
    activation : str, a key of :data:`ACTIVATIONS`
    norm : None, "layer" or "batch"
        Batch norm uses batch statistics in ``train()`` mode and the running
        ones in ``eval()`` mode, which the numpy twin reproduces.
    activate_last : bool
        Whether the last layer also gets the norm and activation.
    """

    def __init__(self, channels: Sequence[int], *, activation: str = "relu", norm: Optional[str] = None,
                 activate_last: bool = True):
        super().__init__()
        if len(channels) < 2:
            raise ValueError(f"An MLP needs at least input and output widths, got {list(channels)}.")
        if norm not in NORM_KINDS:
            raise ValueError(f"Unknown norm {norm!r}; choose from {NORM_KINDS}.")
        self.activation = ACTIVATIONS[activation]
        layer_count = len(channels) - 1
        self.linears = nn.ModuleList(nn.Linear(a, b) for a, b in zip(channels[:-1], channels[1:]))
        normalised = [channels[k + 1] for k in range(layer_count) if k < layer_count - 1 or activate_last]
        if norm == "layer":
            self.norms = nn.ModuleList(nn.LayerNorm(width, eps=NORM_EPSILON) for width in normalised)
        elif norm == "batch":
            self.norms = nn.ModuleList(nn.BatchNorm1d(width, eps=NORM_EPSILON) for width in normalised)
        else:
            self.norms = None
        self.activated_layers = len(normalised)

    def forward(self, x: torch.Tensor, first_linear_applied: bool = False) -> torch.Tensor:
        """(r, in) gives (r, out); with ``first_linear_applied``, ``x`` already
        holds layer 0's linear output (as the numpy twin)."""
        for layer, linear_layer in enumerate(self.linears):
            if layer > 0 or not first_linear_applied:
                x = linear_layer(x)
            if layer < self.activated_layers:
                if self.norms is not None:
                    x = self.norms[layer](x)
                x = self.activation(x)
        return x
