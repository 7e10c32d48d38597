"""The joint network's forward pass in numpy (inference inside Blender).

After RigNet's joint stage (Xu et al. 2020): GMEdgeConv layers (EdgeConv over
the mesh one-ring and over geodesic balls, fused, with a residual), a global
max-pooled shape feature, and two heads per vertex: an *offset* that moves
the vertex onto the joint it belongs to, and an *attention* in (0, 1) that
says how much its vote counts (vertices around a joint vote, those halfway
along a limb do not). :mod:`.mean_shift` clusters the moved vertices into
joints. The torch twin that trains it is
:class:`autorig_addon.core.nn.training.rig_networks.JointNetwork` (same
parameter names; a test checks both agree).
"""

from __future__ import annotations

import numpy as np

from ..nn.convolution import gmedge_block
from ..nn.layers import mlp, sigmoid
from .joint_features import JointGraph

#: Activation of every hidden layer.
ACTIVATION = "leaky_relu"
#: The GMEdgeConv layers, by parameter prefix.
JOINT_LAYERS = ("gmedge1.", "gmedge2.", "gmedge3.")


def joint_outputs(weights: dict, graph: JointGraph) -> tuple[np.ndarray, np.ndarray]:
    """Per-vertex offsets and attention of the joint network.

    Returns
    -------
    offsets : (n, 3) float array, normalised units
    attention : (n,) float array in (0, 1)
    """
    n = graph.vertex_count
    x = mlp(graph.vertex_features, weights, "encoder.", activation=ACTIVATION)
    levels = [x]
    for layer in JOINT_LAYERS:
        x = gmedge_block(x, graph.mesh_edges, graph.ball_edges, weights, layer, activation=ACTIVATION)
        levels.append(x)
    shape = mlp(x, weights, "shape.", activation=ACTIVATION).max(axis=0, keepdims=True)
    joined = np.concatenate(levels + [np.repeat(shape, n, axis=0)], axis=1)
    offsets = mlp(joined, weights, "offset.", activation=ACTIVATION, activate_last=False)
    attention = sigmoid(mlp(joined, weights, "attention.", activation=ACTIVATION, activate_last=False)[:, 0])
    return offsets, attention
