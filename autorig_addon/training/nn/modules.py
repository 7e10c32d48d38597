"""A network's spec as a torch module: its parameters laid out as the spec
declares them, its forward the spec's own, run on the torch operations
table; and the module to and from the flat weights dict the numpy forward
reads (names = the module's ``state_dict`` keys).
"""

from __future__ import annotations

from dataclasses import fields, is_dataclass, replace
from typing import Optional

import numpy as np
import torch
from torch import nn

from ...core.nn.spec import Dense, NetworkSpec, Scalar, Standardiser
from ...core.nn.weights_io import save_weights
from .torch_kernels import TORCH

#: Least spread a feature is divided by when a :class:`Standardiser` is set
#: from training data (a constant feature stays finite).
STD_FLOOR = 1e-4


class _DenseLayers(nn.Module):
    """The parameters of one :class:`Dense` MLP: ``linears.K``."""

    def __init__(self, widths: tuple, zero_last: bool):
        super().__init__()
        if len(widths) < 2:
            raise ValueError(f"An MLP needs at least input and output widths, got {list(widths)}.")
        self.linears = nn.ModuleList(nn.Linear(a, b) for a, b in zip(widths[:-1], widths[1:]))
        if zero_last:
            nn.init.zeros_(self.linears[-1].weight)
            nn.init.zeros_(self.linears[-1].bias)


class NetworkModule(nn.Module):
    """The trainable form of a :class:`~autorig_addon.core.nn.spec.NetworkSpec`.

    Its ``state_dict`` has exactly the spec's parameter names and shapes
    (:meth:`NetworkSpec.parameter_shapes`), created in the spec's order (so
    a seeded run starts from the same numbers); ``forward(inputs)`` is
    ``spec.forward(TORCH, params, inputs)``.
    """

    def __init__(self, spec: NetworkSpec):
        super().__init__()
        self.spec = spec
        for part in spec.parts():
            if isinstance(part, Dense):
                self._attach(part.prefix, _DenseLayers(part.widths, part.zero_last))
            elif isinstance(part, Scalar):
                self.register_parameter(part.name, nn.Parameter(torch.tensor(float(part.value))))
            elif isinstance(part, Standardiser):
                self.register_buffer("input_mean", torch.zeros(part.features))
                self.register_buffer("input_std", torch.ones(part.features))
            else:
                raise TypeError(f"{spec.name}: unknown layer {part!r}.")

    def _attach(self, dotted: str, module: nn.Module) -> None:
        """Put ``module`` at the dotted path, making empty containers on the way."""
        *parents, last = dotted.split(".")
        holder = self
        for name in parents:
            if not hasattr(holder, name):
                holder.add_module(name, nn.Module())
            holder = getattr(holder, name)
        holder.add_module(last, module)

    def params(self) -> dict:
        """Every parameter and buffer by ``state_dict`` name (tensors that
        keep their gradients), as the forward reads them."""
        return {**dict(self.named_parameters()), **dict(self.named_buffers())}

    def forward(self, inputs):
        return self.spec.forward(TORCH, self.params(), inputs)

    def standardise_from(self, features: torch.Tensor) -> None:
        """Set the :class:`Standardiser` from training features (r, features)."""
        self.input_mean.copy_(features.mean(dim=0))
        self.input_std.copy_(features.std(dim=0).clamp_min(STD_FLOOR))


def as_tensors(inputs, device: str | torch.device = "cpu"):
    """A network's inputs as tensors on ``device``: an array, or a dataclass
    (a ``SkinGraph``, a ``JointGraph``) with every field a tensor (dtypes kept:
    float32 features, int64 indices, bool masks)."""
    if is_dataclass(inputs):
        return replace(inputs, **{field.name: as_tensors(getattr(inputs, field.name), device)
                                  for field in fields(inputs)})
    return torch.as_tensor(np.asarray(inputs)).to(device)


def parameter_count(module: nn.Module) -> int:
    return sum(parameter.numel() for parameter in module.parameters())


def module_weights(module: nn.Module) -> dict:
    """``module``'s ``state_dict`` as numpy arrays (copies on the CPU, dtypes kept)."""
    return {name: tensor.detach().cpu().numpy().copy() for name, tensor in module.state_dict().items()}


def load_module_weights(module: nn.Module, weights: dict) -> None:
    """Put ``weights`` (every name of the module's ``state_dict``, no other)
    into ``module``; raises torch's error on a missing or extra name."""
    module.load_state_dict({name: torch.from_numpy(np.array(value)) for name, value in weights.items()}, strict=True)


def save_module(module: nn.Module, path: str, metadata: Optional[dict] = None) -> None:
    """Write ``module``'s weights (and ``metadata``) as a weights file."""
    save_weights(path, module_weights(module), metadata)
