"""The three skinning networks' forward passes in numpy (inference inside
Blender). Their torch twins, which train them, are
:mod:`autorig_addon.core.nn.training.skin_networks`: same layers, same
parameter names (``weights`` is the torch ``state_dict``), and a test checks
both give the same weights.

Each network scores every vertex's :data:`.features.CANDIDATE_BONES`
candidate bones; the scores are *added to* ``prior_scale * log(prior)``, the
logarithm of a prior's weight (our geometric method's, or bone heat as
Blender computes it: :data:`.predict.NETWORK_PRIORS`), so an untrained network
reproduces the prior and training learns the correction (predicting a
residual on a geometric prior is what lets these generalise from a few
dozen characters). A softmax over each vertex's candidates gives weights.

* :func:`rignet_scores`, after RigNet (Xu et al. 2020): the candidates'
  per-(vertex, bone) features concatenated per vertex, GMEdgeConv layers
  (EdgeConv over the mesh one-ring and over geodesic balls, fused), a
  global max-pooled shape feature, K scores per vertex.
* :func:`heterskinnet_scores`, after HeterSkinNet (Pan et al. 2021): vertex
  nodes and bone nodes of one heterogeneous graph whose vertex-bone edges
  carry HollowDist; each layer passes messages vertex -> bone and
  bone -> vertex (and along the mesh), so a bone outside the body or a
  loose part still exchanges information with the vertices it serves.
* :func:`skinningnet_scores`, after SkinningNet (Mosella-Montoro and
  Ruiz-Hidalgo 2022): a mesh stream and a skeleton stream of
  Multi-Aggregator Graph Convolutions (mean, max, min and std pooled
  together), joined per (vertex, bone) pair.
"""

from __future__ import annotations

import numpy as np

from ...nn.aggregation import gather, segment_max, segment_mean
from ...nn.convolution import gmedge_block, multi_aggregator_convolution
from ...nn.layers import mlp
from .features import PRIOR_FLOOR, SkinGraph

#: Activation of every hidden layer.
ACTIVATION = "leaky_relu"


def candidate_weights(scores: np.ndarray, graph: SkinGraph, prior_scale: float) -> np.ndarray:
    """(n, K) weights: softmax over each vertex's valid candidates of the
    network ``scores`` plus ``prior_scale * log(prior)``."""
    logits = scores + prior_scale * np.log(graph.prior + PRIOR_FLOOR)
    logits = np.where(graph.valid, logits, -np.inf)
    logits = logits - logits.max(axis=1, keepdims=True)
    exponentials = np.exp(logits)
    return exponentials / exponentials.sum(axis=1, keepdims=True)


def rignet_scores(weights: dict, graph: SkinGraph) -> np.ndarray:
    """(n, K) candidate scores of the RigNet-style network."""
    n = graph.vertex_count
    x = np.concatenate([graph.vertex_features, graph.pair_features.reshape(n, -1)], axis=1)
    x = mlp(x, weights, "encoder.", activation=ACTIVATION)
    levels = [x]
    for layer in ("gmedge1.", "gmedge2."):
        x = gmedge_block(x, graph.mesh_edges, graph.ball_edges, weights, layer, activation=ACTIVATION)
        levels.append(x)
    shape = mlp(x, weights, "shape.", activation=ACTIVATION).max(axis=0, keepdims=True)
    joined = np.concatenate(levels + [np.repeat(shape, n, axis=0)], axis=1)
    return mlp(joined, weights, "scores.", activation=ACTIVATION, activate_last=False)


def heterskinnet_scores(weights: dict, graph: SkinGraph) -> np.ndarray:
    """(n, K) candidate scores of the HeterSkinNet-style network."""
    n, k = graph.valid.shape
    pair_vertex, pair_bone, pair_rows = _pairs(graph)
    vertex = mlp(graph.vertex_features, weights, "vertex_encoder.", activation=ACTIVATION)
    bone = mlp(graph.bone_features, weights, "bone_encoder.", activation=ACTIVATION)
    pair = mlp(graph.pair_features.reshape(n * k, -1)[pair_rows], weights, "pair_encoder.", activation=ACTIVATION)
    for layer in ("hetero1.", "hetero2."):
        to_bone = mlp(np.concatenate([gather(vertex, pair_vertex), pair], axis=1), weights, layer + "to_bone.",
                      activation=ACTIVATION)
        pooled = np.concatenate([segment_mean(to_bone, pair_bone, graph.bone_count),
                                 segment_max(to_bone, pair_bone, graph.bone_count)], axis=1)
        bone = bone + mlp(np.concatenate([bone, pooled], axis=1), weights, layer + "bone_update.",
                          activation=ACTIVATION)
        to_vertex = mlp(np.concatenate([gather(bone, pair_bone), pair], axis=1), weights, layer + "to_vertex.",
                        activation=ACTIVATION)
        from_bones = segment_max(to_vertex, pair_vertex, n)
        from_mesh = segment_mean(gather(vertex, graph.mesh_edges[0]), graph.mesh_edges[1], n)
        vertex = vertex + mlp(np.concatenate([vertex, from_bones, from_mesh], axis=1), weights,
                              layer + "vertex_update.", activation=ACTIVATION)
        pair = pair + mlp(np.concatenate([gather(vertex, pair_vertex), gather(bone, pair_bone), pair], axis=1),
                          weights, layer + "pair_update.", activation=ACTIVATION)
    return _scattered_scores(mlp(pair, weights, "scores.", activation=ACTIVATION, activate_last=False), graph,
                             pair_rows)


def skinningnet_scores(weights: dict, graph: SkinGraph) -> np.ndarray:
    """(n, K) candidate scores of the SkinningNet-style network."""
    n, k = graph.valid.shape
    pair_vertex, pair_bone, pair_rows = _pairs(graph)
    vertex = mlp(graph.vertex_features, weights, "vertex_encoder.", activation=ACTIVATION)
    for layer in ("mesh1.", "mesh2."):
        vertex = vertex + multi_aggregator_convolution(vertex, graph.mesh_edges, weights, layer,
                                                       activation=ACTIVATION)
    bone = mlp(graph.bone_features, weights, "bone_encoder.", activation=ACTIVATION)
    for layer in ("skeleton1.", "skeleton2."):
        bone = bone + multi_aggregator_convolution(bone, graph.bone_edges, weights, layer, activation=ACTIVATION)
    pair = graph.pair_features.reshape(n * k, -1)[pair_rows]
    joined = np.concatenate([gather(vertex, pair_vertex), gather(bone, pair_bone), pair], axis=1)
    return _scattered_scores(mlp(joined, weights, "join.", activation=ACTIVATION, activate_last=False), graph,
                             pair_rows)


#: The networks by name: ``scores(weights, graph) -> (n, K)``.
SCORE_FUNCTIONS = {
    "rignet": rignet_scores,
    "heterskinnet": heterskinnet_scores,
    "skinningnet": skinningnet_scores,
}


def _pairs(graph: SkinGraph) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The valid (vertex, bone) candidate pairs: vertex and bone of each,
    and each pair's row in the flattened (n * K) candidate table."""
    rows = np.flatnonzero(graph.valid.reshape(-1))
    return rows // graph.valid.shape[1], graph.candidates.reshape(-1)[rows], rows


def _scattered_scores(pair_scores: np.ndarray, graph: SkinGraph, pair_rows: np.ndarray) -> np.ndarray:
    """(n, K) table of per-pair scores (p, 1); 0 in the invalid slots."""
    scores = np.zeros(graph.valid.size, dtype=pair_scores.dtype)
    scores[pair_rows] = pair_scores[:, 0]
    return scores.reshape(graph.valid.shape)
