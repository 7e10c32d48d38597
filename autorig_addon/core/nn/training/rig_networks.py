"""The skeleton networks in torch: the training twins of
:mod:`autorig_addon.core.rigging.joint_network` and
:mod:`autorig_addon.core.rigging.connectivity` (read their docstrings).
Module and parameter names match the prefixes the numpy forward passes
read, so a ``state_dict`` saved by :func:`.export.save_module` runs there
unchanged.
"""

from __future__ import annotations

import torch
from torch import nn

from ...rigging.connectivity import PAIR_FEATURES, ROOT_FEATURES, STD_FLOOR
from ...rigging.joint_features import VERTEX_FEATURES
from ...rigging.joint_network import ACTIVATION
from .convolution import GMEdgeBlock
from .layers import MLP


def _mlp(*channels: int, last: bool = True) -> MLP:
    return MLP(list(channels), activation=ACTIVATION, activate_last=last)


class JointNetwork(nn.Module):
    """Offsets and attention per vertex (:func:`...rigging.joint_network.joint_outputs`)."""

    def __init__(self, width: int = 64):
        super().__init__()
        self.encoder = _mlp(VERTEX_FEATURES, 2 * width, width)
        for layer in ("gmedge1", "gmedge2", "gmedge3"):
            setattr(self, layer, GMEdgeBlock(width, activation=ACTIVATION))
        self.shape = _mlp(width, 2 * width)
        self.offset = _mlp(6 * width, 2 * width, width, 3, last=False)
        self.attention = _mlp(6 * width, width, 1, last=False)

    def forward(self, features: torch.Tensor, mesh_edges: torch.Tensor, ball_edges: torch.Tensor):
        """(n, 3) offsets and (n,) attention logits (the sigmoid comes in the loss)."""
        n = features.shape[0]
        x = self.encoder(features)
        levels = [x]
        for block in (self.gmedge1, self.gmedge2, self.gmedge3):
            x = block(x, mesh_edges, ball_edges)
            levels.append(x)
        shape = self.shape(x).max(dim=0, keepdim=True).values
        joined = torch.cat(levels + [shape.expand(n, -1)], dim=1)
        return self.offset(joined), self.attention(joined)[:, 0]


class _StandardisedMLP(nn.Module):
    """An MLP on features standardised by the training data's mean and
    spread (buffers ``input_mean``, ``input_std``: the features mix lengths
    of a few hundredths with ranks and shares near one)."""

    def __init__(self, features: int, width: int):
        super().__init__()
        self.register_buffer("input_mean", torch.zeros(features))
        self.register_buffer("input_std", torch.ones(features))
        self.mlp = _mlp(features, width, width, 1, last=False)

    def standardise_from(self, features: torch.Tensor) -> None:
        self.input_mean.copy_(features.mean(dim=0))
        self.input_std.copy_(features.std(dim=0).clamp_min(STD_FLOOR))

    def forward(self, features: torch.Tensor) -> torch.Tensor:
        return self.mlp((features - self.input_mean) / self.input_std)[:, 0]


class BoneNetwork(_StandardisedMLP):
    """Probability logit that a candidate joint pair is a bone
    (:func:`...rigging.connectivity.bone_probabilities`)."""

    def __init__(self, width: int = 64):
        super().__init__(PAIR_FEATURES, width)


class RootNetwork(_StandardisedMLP):
    """Root score per joint (:func:`...rigging.connectivity.root_scores`)."""

    def __init__(self, width: int = 32):
        super().__init__(ROOT_FEATURES, width)


NETWORKS = {"joints": JointNetwork, "bones": BoneNetwork, "root": RootNetwork}
