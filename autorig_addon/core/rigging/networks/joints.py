"""The joint network, after RigNet's joint stage (Xu et al. 2020).

RigNet's trunk (GMEdgeConv layers: EdgeConv over the mesh one-ring and over
geodesic balls, fused, with a residual; a global max-pooled shape feature)
and two heads per vertex: an *offset* that moves the vertex onto the joint
it belongs to, and an *attention* logit that says how much its vote counts
(vertices around a joint vote, those halfway along a limb do not). Its
input is a :class:`..joint_features.JointGraph`; :mod:`..mean_shift`
clusters the moved vertices into joints.
"""

from __future__ import annotations

from ...nn.convolution import gmedge_trunk
from ...nn.layers import mlp
from ...nn.operations import Array, Operations
from ...nn.spec import Dense, GMEdgeTrunk, NetworkSpec, TrainingSettings
from ..joint_features import VERTEX_FEATURES, JointGraph
from .trained import TRAINED_FOLDER

WIDTH = 64
TRUNK = GMEdgeTrunk(VERTEX_FEATURES, WIDTH, ("gmedge1", "gmedge2", "gmedge3"), 2 * WIDTH)


def joint_network(ops: Operations, params: dict, graph: JointGraph) -> tuple[Array, Array]:
    """Per-vertex offsets and attention logits.

    Returns
    -------
    offsets : (n, 3) float array, normalised units
    attention_logits : (n,) float array (the attention is their sigmoid)
    """
    joined = gmedge_trunk(ops, params, graph.vertex_features, graph.mesh_edges, graph.ball_edges, TRUNK.blocks,
                          activation=SPEC.activation)
    offsets = mlp(ops, params, joined, "offset.", activation=SPEC.activation, activate_last=False)
    attention = mlp(ops, params, joined, "attention.", activation=SPEC.activation, activate_last=False)
    return offsets, attention[:, 0]


SPEC = NetworkSpec(
    name="joints",
    label="Joints",
    description="Moves every vertex of the character onto its joint and weighs its vote (RigNet's joint stage)",
    inputs="JointGraph",
    layers=(TRUNK, Dense("offset", (TRUNK.out_width, 2 * WIDTH, WIDTH, 3)),
            Dense("attention", (TRUNK.out_width, WIDTH, 1))),
    forward=joint_network,
    # On the 31-character set 80 epochs fitted the held-out characters better and the validation ones no
    # better; on the 419-character set 30 epochs of about 150 family-sampled steps keep the run within the
    # hour on one CPU thread (docs/models.md).
    training=TrainingSettings(epochs=30, learning_rate=2e-3),
    weights_file=TRAINED_FOLDER / "joints.npz",
)
