"""The three skinning networks in torch: the training twins of
:mod:`autorig_addon.core.skinning.learned.networks` (read that module's
docstring for what each network does). Module and parameter names match the
prefixes the numpy forward passes read, so a ``state_dict`` saved by
:func:`.export.save_module` runs there unchanged.

Every module takes a :class:`~autorig_addon.core.skinning.learned.features.SkinGraph`
whose fields are tensors (:func:`graph_tensors`) and returns the (n, K)
candidate weights; :meth:`SkinNetwork.candidate_scores` gives the raw scores.
"""

from __future__ import annotations

from dataclasses import fields

import numpy as np
import torch
from torch import nn

from ...skinning.learned.features import (
    BONE_FEATURES, CANDIDATE_BONES, PAIR_FEATURES, PRIOR_FLOOR, VERTEX_FEATURES, SkinGraph,
)
from ...skinning.learned.networks import ACTIVATION
from .aggregation import gather, segment_max, segment_mean
from .convolution import GMEdgeBlock, MultiAggregatorConv
from .layers import MLP


def graph_tensors(graph: SkinGraph, device: str | torch.device = "cpu") -> SkinGraph:
    """The same graph with every field a tensor (float32 features, int64
    indices, bool masks) on ``device``."""
    return SkinGraph(**{field.name: torch.as_tensor(np.asarray(getattr(graph, field.name))).to(device)
                        for field in fields(SkinGraph)})


def _mlp(*channels: int, last: bool = True) -> MLP:
    return MLP(list(channels), activation=ACTIVATION, activate_last=last)


class SkinNetwork(nn.Module):
    """What the three networks share: the prior's learned scale and the
    softmax over each vertex's candidates."""

    def __init__(self):
        super().__init__()
        self.prior_scale = nn.Parameter(torch.tensor(1.0))

    def start_from_prior(self, head: MLP) -> None:
        """Zero the last layer of the score ``head``, so the untrained
        network gives the prior exactly and training learns the correction."""
        nn.init.zeros_(head.linears[-1].weight)
        nn.init.zeros_(head.linears[-1].bias)

    def candidate_scores(self, graph: SkinGraph) -> torch.Tensor:
        """(n, K) raw scores, before the prior is added."""
        raise NotImplementedError

    def forward(self, graph: SkinGraph) -> torch.Tensor:
        logits = self.candidate_scores(graph) + self.prior_scale * torch.log(graph.prior + PRIOR_FLOOR)
        logits = logits.masked_fill(~graph.valid, float("-inf"))
        return torch.softmax(logits, dim=1)


def _pairs(graph: SkinGraph) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    rows = torch.nonzero(graph.valid.reshape(-1)).reshape(-1)
    return rows // graph.valid.shape[1], graph.candidates.reshape(-1)[rows], rows


def _scattered_scores(pair_scores: torch.Tensor, graph: SkinGraph, pair_rows: torch.Tensor) -> torch.Tensor:
    scores = pair_scores.new_zeros(graph.valid.numel())
    scores = scores.index_copy(0, pair_rows, pair_scores[:, 0])
    return scores.reshape(graph.valid.shape)


class RigNetSkin(SkinNetwork):
    """RigNet's skinning network, sized for our data."""

    def __init__(self, width: int = 64):
        super().__init__()
        self.encoder = _mlp(VERTEX_FEATURES + CANDIDATE_BONES * PAIR_FEATURES, 2 * width, width)
        for layer in ("gmedge1", "gmedge2"):
            setattr(self, layer, GMEdgeBlock(width, activation=ACTIVATION))
        self.shape = _mlp(width, width)
        self.scores = _mlp(4 * width, width, CANDIDATE_BONES, last=False)
        self.start_from_prior(self.scores)

    def candidate_scores(self, graph: SkinGraph) -> torch.Tensor:
        n = graph.vertex_features.shape[0]
        x = torch.cat([graph.vertex_features, graph.pair_features.reshape(n, -1)], dim=1)
        x = self.encoder(x)
        levels = [x]
        for block in (self.gmedge1, self.gmedge2):
            x = block(x, graph.mesh_edges, graph.ball_edges)
            levels.append(x)
        shape = self.shape(x).max(dim=0, keepdim=True).values
        joined = torch.cat(levels + [shape.expand(n, -1)], dim=1)
        return self.scores(joined)


class HeterSkinNet(SkinNetwork):
    """HeterSkinNet's heterogeneous graph network, sized for our data."""

    def __init__(self, width: int = 64):
        super().__init__()
        self.vertex_encoder = _mlp(VERTEX_FEATURES, width, width)
        self.bone_encoder = _mlp(BONE_FEATURES, width, width)
        self.pair_encoder = _mlp(PAIR_FEATURES, width, width)
        for layer in ("hetero1", "hetero2"):
            block = nn.Module()
            block.to_bone = _mlp(2 * width, width)
            block.bone_update = _mlp(3 * width, width)
            block.to_vertex = _mlp(2 * width, width)
            block.vertex_update = _mlp(3 * width, width)
            block.pair_update = _mlp(3 * width, width)
            setattr(self, layer, block)
        self.scores = _mlp(width, width, 1, last=False)
        self.start_from_prior(self.scores)

    def candidate_scores(self, graph: SkinGraph) -> torch.Tensor:
        n, k = graph.valid.shape
        bone_count = graph.bone_features.shape[0]
        pair_vertex, pair_bone, pair_rows = _pairs(graph)
        vertex = self.vertex_encoder(graph.vertex_features)
        bone = self.bone_encoder(graph.bone_features)
        pair = self.pair_encoder(graph.pair_features.reshape(n * k, -1)[pair_rows])
        for block in (self.hetero1, self.hetero2):
            to_bone = block.to_bone(torch.cat([gather(vertex, pair_vertex), pair], dim=1))
            pooled = torch.cat([segment_mean(to_bone, pair_bone, bone_count),
                                segment_max(to_bone, pair_bone, bone_count)], dim=1)
            bone = bone + block.bone_update(torch.cat([bone, pooled], dim=1))
            to_vertex = block.to_vertex(torch.cat([gather(bone, pair_bone), pair], dim=1))
            from_bones = segment_max(to_vertex, pair_vertex, n)
            from_mesh = segment_mean(gather(vertex, graph.mesh_edges[0]), graph.mesh_edges[1], n)
            vertex = vertex + block.vertex_update(torch.cat([vertex, from_bones, from_mesh], dim=1))
            pair = pair + block.pair_update(torch.cat([gather(vertex, pair_vertex), gather(bone, pair_bone), pair],
                                                      dim=1))
        return _scattered_scores(self.scores(pair), graph, pair_rows)


class SkinningNet(SkinNetwork):
    """SkinningNet's two-stream network, sized for our data."""

    def __init__(self, width: int = 64):
        super().__init__()
        self.vertex_encoder = _mlp(VERTEX_FEATURES, width, width)
        self.mesh1 = MultiAggregatorConv(width, [width], activation=ACTIVATION)
        self.mesh2 = MultiAggregatorConv(width, [width], activation=ACTIVATION)
        self.bone_encoder = _mlp(BONE_FEATURES, width, width)
        self.skeleton1 = MultiAggregatorConv(width, [width], activation=ACTIVATION)
        self.skeleton2 = MultiAggregatorConv(width, [width], activation=ACTIVATION)
        self.join = _mlp(2 * width + PAIR_FEATURES, width, width, 1, last=False)
        self.start_from_prior(self.join)

    def candidate_scores(self, graph: SkinGraph) -> torch.Tensor:
        n, k = graph.valid.shape
        pair_vertex, pair_bone, pair_rows = _pairs(graph)
        vertex = self.vertex_encoder(graph.vertex_features)
        for layer in (self.mesh1, self.mesh2):
            vertex = vertex + layer(vertex, graph.mesh_edges)
        bone = self.bone_encoder(graph.bone_features)
        for layer in (self.skeleton1, self.skeleton2):
            bone = bone + layer(bone, graph.bone_edges)
        pair = graph.pair_features.reshape(n * k, -1)[pair_rows]
        joined = torch.cat([gather(vertex, pair_vertex), gather(bone, pair_bone), pair], dim=1)
        return _scattered_scores(self.join(joined), graph, pair_rows)


#: The networks by name (the names of
#: :data:`autorig_addon.core.skinning.learned.networks.SCORE_FUNCTIONS`).
NETWORKS = {
    "rignet": RigNetSkin,
    "heterskinnet": HeterSkinNet,
    "skinningnet": SkinningNet,
}
