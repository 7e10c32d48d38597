"""HeterSkinNet's network (Pan et al. 2021), sized for our data.

Vertex nodes and bone nodes of one heterogeneous graph whose vertex-bone
edges carry HollowDist; each layer passes messages vertex -> bone and
bone -> vertex (and along the mesh), so a bone outside the body or a loose
part still exchanges information with the vertices it serves. It scores
each (vertex, bone) pair on its own, so it takes any skeleton.
"""

from __future__ import annotations

from ....nn.layers import mlp
from ....nn.operations import Array, Operations
from ....nn.spec import Dense, TrainingSettings
from ..features import BONE_FEATURES, PAIR_FEATURES, VERTEX_FEATURES, SkinGraph
from .scoring import TRAINED_FOLDER, SkinNetworkSpec, candidate_pairs, scattered_scores

WIDTH = 64
HETERO_LAYERS = ("hetero1", "hetero2")


def heterskinnet_scores(ops: Operations, params: dict, graph: SkinGraph) -> Array:
    """(n, K) candidate scores."""
    activation = SPEC.activation
    n, k = graph.valid.shape
    bone_count = graph.bone_features.shape[0]
    pair_vertex, pair_bone, pair_rows = candidate_pairs(ops, graph)
    vertex = mlp(ops, params, graph.vertex_features, "vertex_encoder.", activation=activation)
    bone = mlp(ops, params, graph.bone_features, "bone_encoder.", activation=activation)
    pair = mlp(ops, params, graph.pair_features.reshape(n * k, -1)[pair_rows], "pair_encoder.",
               activation=activation)
    for layer in HETERO_LAYERS:
        def step(name: str, x: Array) -> Array:
            return mlp(ops, params, x, f"{layer}.{name}.", activation=activation)

        to_bone = step("to_bone", ops.concat([ops.gather(vertex, pair_vertex), pair], 1))
        pooled = ops.concat([ops.segment_mean(to_bone, pair_bone, bone_count),
                             ops.segment_max(to_bone, pair_bone, bone_count)], 1)
        bone = bone + step("bone_update", ops.concat([bone, pooled], 1))
        to_vertex = step("to_vertex", ops.concat([ops.gather(bone, pair_bone), pair], 1))
        from_bones = ops.segment_max(to_vertex, pair_vertex, n)
        from_mesh = ops.segment_mean(ops.gather(vertex, graph.mesh_edges[0]), graph.mesh_edges[1], n)
        vertex = vertex + step("vertex_update", ops.concat([vertex, from_bones, from_mesh], 1))
        pair = pair + step("pair_update",
                           ops.concat([ops.gather(vertex, pair_vertex), ops.gather(bone, pair_bone), pair], 1))
    scores = mlp(ops, params, pair, "scores.", activation=activation, activate_last=False)
    return scattered_scores(ops, scores, graph, pair_rows)


def _hetero_layer(name: str) -> tuple:
    return (Dense(f"{name}.to_bone", (2 * WIDTH, WIDTH)), Dense(f"{name}.bone_update", (3 * WIDTH, WIDTH)),
            Dense(f"{name}.to_vertex", (2 * WIDTH, WIDTH)), Dense(f"{name}.vertex_update", (3 * WIDTH, WIDTH)),
            Dense(f"{name}.pair_update", (3 * WIDTH, WIDTH)))


SPEC = SkinNetworkSpec(
    name="heterskinnet",
    label="HeterSkinNet",
    description="HeterSkinNet (Pan et al. 2021) trained on artists' rigs: messages between vertices and bones "
                "over HollowDist, for bones outside the body and loose parts",
    layers=(
        Dense("vertex_encoder", (VERTEX_FEATURES, WIDTH, WIDTH)),
        Dense("bone_encoder", (BONE_FEATURES, WIDTH, WIDTH)),
        Dense("pair_encoder", (PAIR_FEATURES, WIDTH, WIDTH)),
        *(part for name in HETERO_LAYERS for part in _hetero_layer(name)),
        Dense("scores", (WIDTH, WIDTH, 1), zero_last=True),
    ),
    forward=heterskinnet_scores,
    # At 2e-3 it peaked on the held-out characters at epoch 3 and fell back; at 5e-4 it went lower.
    training=TrainingSettings(epochs=25, learning_rate=5e-4),
    weights_file=TRAINED_FOLDER / "heterskinnet.npz",
    distance="hollow",
    prior="heat",
)
