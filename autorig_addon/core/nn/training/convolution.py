"""Edge convolution in torch: the training twin of
:mod:`autorig_addon.core.nn.convolution` (message ``MLP([x_i, x_j - x_i])``
on every edge ``j -> i``, aggregated at the receiver, max by default; the
MLP's first linear layer computed per node and gathered, as there), and
RigNet's GMEdgeConv block built from it (:class:`GMEdgeBlock`).
"""

from __future__ import annotations

from typing import Optional, Sequence

import torch
import torch.nn.functional as F
from torch import nn

from .aggregation import AGGREGATIONS, gather
from .layers import MLP


def edge_messages(x: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
    """(e, 2c) rows ``[x_i, x_j - x_i]`` of every edge ``j -> i``."""
    receivers = gather(x, edges[1])
    return torch.cat([receivers, gather(x, edges[0]) - receivers], dim=1)


def first_layer_per_edge(x: torch.Tensor, edges: torch.Tensor, weight: torch.Tensor,
                         bias: Optional[torch.Tensor]) -> torch.Tensor:
    """``F.linear(edge_messages(x, edges), weight, bias)`` computed per node
    then gathered: (n, c), (2, e), (out, 2c), (out,) give (e, out)."""
    channels = x.shape[1]
    receiver_weight, difference_weight = weight[:, :channels], weight[:, channels:]
    at_receiver = F.linear(x, receiver_weight - difference_weight, bias)
    at_sender = F.linear(x, difference_weight)
    return gather(at_receiver, edges[1]) + gather(at_sender, edges[0])


class EdgeConv(nn.Module):
    """One EdgeConv layer; its ``state_dict`` holds the MLP under ``mlp.``.

    Parameters
    ----------
    in_channels : int, node feature width ``c`` (the MLP takes ``2c``)
    channels : sequence of int, the MLP's widths after its input
    aggregation : str, a key of :data:`.aggregation.AGGREGATIONS`
    activation, norm, activate_last : the MLP's settings (:class:`.layers.MLP`)
    """

    def __init__(self, in_channels: int, channels: Sequence[int], *, aggregation: str = "max",
                 activation: str = "relu", norm: Optional[str] = None, activate_last: bool = True):
        super().__init__()
        self.aggregate = AGGREGATIONS[aggregation]
        self.mlp = MLP([2 * in_channels, *channels], activation=activation, norm=norm, activate_last=activate_last)

    def forward(self, x: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
        """(n, c) features and a (2, e) int64 edge index give (n, out)."""
        first = self.mlp.linears[0]
        hidden = first_layer_per_edge(x, edges, first.weight, first.bias)
        return self.aggregate(self.mlp(hidden, first_linear_applied=True), edges[1], x.shape[0])


class GMEdgeBlock(nn.Module):
    """RigNet's GMEdgeConv block, residual included (twin of
    :func:`autorig_addon.core.nn.convolution.gmedge_block`): max EdgeConvs
    over the mesh one-ring (``one_ring.``) and over geodesic balls
    (``ball.``), concatenated, fused by one linear layer and activation
    (``fuse.``) and added to the input.

    Parameters
    ----------
    channels : int, node feature width ``c`` (in and out)
    activation : str, every layer's activation (:class:`.layers.MLP`)
    """

    def __init__(self, channels: int, *, activation: str = "relu"):
        super().__init__()
        # Built in this order, so a seeded network's initial parameters do not change.
        self.one_ring = EdgeConv(channels, [channels], aggregation="max", activation=activation)
        self.ball = EdgeConv(channels, [channels], aggregation="max", activation=activation)
        self.fuse = MLP([2 * channels, channels], activation=activation)

    def forward(self, x: torch.Tensor, mesh_edges: torch.Tensor, ball_edges: torch.Tensor) -> torch.Tensor:
        """(n, c) features, (2, e) and (2, b) int64 edge indices give (n, c)."""
        one_ring = self.one_ring(x, mesh_edges)
        ball = self.ball(x, ball_edges)
        return x + self.fuse(torch.cat([one_ring, ball], dim=1))


class MultiAggregatorConv(nn.Module):
    """SkinningNet's Multi-Aggregator Graph Convolution (twin of
    :func:`autorig_addon.core.nn.convolution.multi_aggregator_convolution`):
    EdgeConv messages reduced by several aggregators, concatenated and
    summarised by one linear layer and activation (``summary.``)."""

    def __init__(self, in_channels: int, channels: Sequence[int], *,
                 aggregations: tuple = ("mean", "max", "min", "std"), activation: str = "relu",
                 norm: Optional[str] = None):
        super().__init__()
        self.aggregations = tuple(AGGREGATIONS[name] for name in aggregations)
        self.mlp = MLP([2 * in_channels, *channels], activation=activation, norm=norm)
        self.summary = MLP([len(aggregations) * channels[-1], channels[-1]], activation=activation, norm=norm)

    def forward(self, x: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
        first = self.mlp.linears[0]
        messages = self.mlp(first_layer_per_edge(x, edges, first.weight, first.bias), first_linear_applied=True)
        pooled = torch.cat([aggregate(messages, edges[1], x.shape[0]) for aggregate in self.aggregations], dim=1)
        return self.summary(pooled)
