"""SkinningNet's two-stream network (Mosella-Montoro and Ruiz-Hidalgo
2022), sized for our data.

A mesh stream and a skeleton stream of Multi-Aggregator Graph Convolutions
(mean, max, min and std pooled together), joined per (vertex, bone) pair.
It scores each pair on its own, so it takes any skeleton.
"""

from __future__ import annotations

from ....nn.convolution import multi_aggregator_convolution
from ....nn.layers import mlp
from ....nn.operations import Array, Operations
from ....nn.spec import Dense, MultiAggregator, TrainingSettings
from ..features import BONE_FEATURES, PAIR_FEATURES, VERTEX_FEATURES, SkinGraph
from .scoring import TRAINED_FOLDER, SkinNetworkSpec, candidate_pairs, scattered_scores

WIDTH = 64
MESH_LAYERS = ("mesh1", "mesh2")
SKELETON_LAYERS = ("skeleton1", "skeleton2")


def skinningnet_scores(ops: Operations, params: dict, graph: SkinGraph) -> Array:
    """(n, K) candidate scores."""
    activation = SPEC.activation
    n, k = graph.valid.shape
    pair_vertex, pair_bone, pair_rows = candidate_pairs(ops, graph)
    vertex = mlp(ops, params, graph.vertex_features, "vertex_encoder.", activation=activation)
    for layer in MESH_LAYERS:
        vertex = vertex + multi_aggregator_convolution(ops, params, vertex, graph.mesh_edges, layer + ".",
                                                       activation=activation)
    bone = mlp(ops, params, graph.bone_features, "bone_encoder.", activation=activation)
    for layer in SKELETON_LAYERS:
        bone = bone + multi_aggregator_convolution(ops, params, bone, graph.bone_edges, layer + ".",
                                                   activation=activation)
    pair = graph.pair_features.reshape(n * k, -1)[pair_rows]
    joined = ops.concat([ops.gather(vertex, pair_vertex), ops.gather(bone, pair_bone), pair], 1)
    scores = mlp(ops, params, joined, "join.", activation=activation, activate_last=False)
    return scattered_scores(ops, scores, graph, pair_rows)


SPEC = SkinNetworkSpec(
    name="skinningnet",
    label="SkinningNet",
    description="SkinningNet (Mosella-Montoro and Ruiz-Hidalgo 2022) trained on artists' rigs: mesh and "
                "skeleton streams of multi-aggregator graph convolutions",
    layers=(
        Dense("vertex_encoder", (VERTEX_FEATURES, WIDTH, WIDTH)),
        *(MultiAggregator(layer, WIDTH, (WIDTH,)) for layer in MESH_LAYERS),
        Dense("bone_encoder", (BONE_FEATURES, WIDTH, WIDTH)),
        *(MultiAggregator(layer, WIDTH, (WIDTH,)) for layer in SKELETON_LAYERS),
        Dense("join", (2 * WIDTH + PAIR_FEATURES, WIDTH, WIDTH, 1), zero_last=True),
    ),
    forward=skinningnet_scores,
    # 20 epochs of 128 family-sampled steps, as RigNet's (docs/models.md).
    training=TrainingSettings(epochs=20, learning_rate=2e-3),
    weights_file=TRAINED_FOLDER / "skinningnet.npz",
    distance="geodesic",
    prior="geometric",
)
