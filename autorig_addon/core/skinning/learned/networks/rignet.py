"""RigNet's skinning network (Xu et al. 2020), sized for our data.

The candidates' per-(vertex, bone) features concatenated per vertex, RigNet's
trunk (GMEdgeConv layers: EdgeConv over the mesh one-ring and over geodesic
balls, fused; a global max-pooled shape feature), K scores per vertex. It
reads a vertex's candidates side by side, so a skeleton of fewer deform
bones than candidates leaves empty input slots. The 419-character split's
training set holds 20 characters of 2 to 4 deform bones, so it has learned
3 and 4 (a three-bone tube: 0.955 of each bone's middle on that bone, as
good as the other networks), but two bones still defeat it (0.65 of a
two-bone tube's upper band on its bone, the others 0.93 to 1.0): on fewer
than 3 deform bones it sees each bone cut into pieces
(``..predict.split_bones``).
"""

from __future__ import annotations

from ....nn.convolution import gmedge_trunk
from ....nn.layers import mlp
from ....nn.operations import Array, Operations
from ....nn.spec import Dense, GMEdgeTrunk, TrainingSettings
from ..features import CANDIDATE_BONES, PAIR_FEATURES, VERTEX_FEATURES, SkinGraph
from .scoring import TRAINED_FOLDER, SkinNetworkSpec

WIDTH = 64
TRUNK = GMEdgeTrunk(VERTEX_FEATURES + CANDIDATE_BONES * PAIR_FEATURES, WIDTH, ("gmedge1", "gmedge2"), WIDTH)


def rignet_scores(ops: Operations, params: dict, graph: SkinGraph) -> Array:
    """(n, K) candidate scores."""
    n = graph.vertex_features.shape[0]
    x = ops.concat([graph.vertex_features, graph.pair_features.reshape(n, -1)], 1)
    joined = gmedge_trunk(ops, params, x, graph.mesh_edges, graph.ball_edges, TRUNK.blocks, activation=SPEC.activation)
    return mlp(ops, params, joined, "scores.", activation=SPEC.activation, activate_last=False)


SPEC = SkinNetworkSpec(
    name="rignet",
    label="RigNet",
    description="RigNet's network (Xu et al. 2020) trained on artists' rigs: graph convolutions over the mesh "
                "and geodesic balls",
    layers=(TRUNK, Dense("scores", (TRUNK.out_width, WIDTH, CANDIDATE_BONES), zero_last=True)),
    forward=rignet_scores,
    # 20 epochs of 128 family-sampled steps: about 15 minutes on one CPU thread (docs/models.md).
    training=TrainingSettings(epochs=20, learning_rate=2e-3),
    weights_file=TRAINED_FOLDER / "rignet.npz",
    distance="geodesic",
    prior="geometric",
    min_deform_bones=3,
)
