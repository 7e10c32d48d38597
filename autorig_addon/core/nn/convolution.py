"""Edge convolution in numpy: the message -> aggregate -> update layer the
networks share.

EdgeConv (Wang et al. 2019, the building block of RigNet's GMEdgeConv):
every edge ``j -> i`` carries the message ``MLP([x_i, x_j - x_i])``, the
receiver aggregates its messages (max by default), and the update keeps the
aggregate as the node's new features. A node that receives no edge gets 0
(see :mod:`.aggregation`). The inference twin of
:class:`autorig_addon.core.nn.training.convolution.EdgeConv`; its weights
are that module's ``state_dict`` under ``prefix`` (the MLP under
``prefix + "mlp."``).

The MLP's first layer is linear, so with its weight split as ``[A, B]``
(columns for ``x_i`` and for ``x_j - x_i``) it equals
``(A - B) x_i + B x_j + bias``: both terms are computed once per node and
gathered per edge, instead of building the (e, 2c) message rows, which
saves most of the layer's time (a mesh has ~10-40 times more edges than
vertices).

RigNet's GMEdgeConv block (:func:`gmedge_block`) runs two EdgeConvs, over
the mesh one-ring and over geodesic balls, and fuses them with a residual;
the skinning and the joint networks both stack it.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from .aggregation import AGGREGATIONS, gather
from .layers import linear, mlp


def edge_messages(x: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(e, 2c) rows ``[x_i, x_j - x_i]`` of every edge ``j -> i``, from
    (n, c) node features and a (2, e) edge index (senders, receivers): the
    EdgeConv MLP's input, written out (:func:`edge_convolution` does not
    build it)."""
    receivers = gather(x, edges[1])
    return np.concatenate([receivers, gather(x, edges[0]) - receivers], axis=1)


def first_layer_per_edge(x: np.ndarray, edges: np.ndarray, weight: np.ndarray,
                         bias: Optional[np.ndarray]) -> np.ndarray:
    """``linear(edge_messages(x, edges), weight, bias)`` computed per node
    then gathered: (n, c), (2, e), (out, 2c), (out,) give (e, out)."""
    channels = x.shape[1]
    receiver_weight, difference_weight = weight[:, :channels], weight[:, channels:]
    at_receiver = linear(x, receiver_weight - difference_weight, bias)
    at_sender = linear(x, difference_weight)
    return gather(at_receiver, edges[1]) + gather(at_sender, edges[0])


def edge_convolution(x: np.ndarray, edges: np.ndarray, weights: dict, prefix: str, *, aggregation: str = "max",
                     activation: str = "relu", norm: Optional[str] = None, activate_last: bool = True) -> np.ndarray:
    """One EdgeConv layer.

    Parameters
    ----------
    x : (n, c) float array, node features
    edges : (2, e) int array, senders then receivers (:mod:`.graph`)
    weights : dict of str -> array, holding the MLP ``prefix + "mlp."``
        whose first layer takes ``2c`` inputs
    prefix : str, the layer's name with its trailing dot (``"conv1."``)
    aggregation : str, a key of :data:`.aggregation.AGGREGATIONS`
    activation, norm, activate_last : the MLP's settings (:func:`.layers.mlp`)

    Returns
    -------
    (n, out) float array, the aggregated messages of each node.
    """
    first = prefix + "mlp.linears.0."
    if first + "weight" not in weights:
        raise KeyError(f"No EdgeConv named {prefix!r} in the weights (no {first}weight).")
    hidden = first_layer_per_edge(x, edges, weights[first + "weight"], weights.get(first + "bias"))
    messages = mlp(hidden, weights, prefix + "mlp.", activation=activation, norm=norm, activate_last=activate_last,
                   first_linear_applied=True)
    return AGGREGATIONS[aggregation](messages, edges[1], len(x))


def gmedge_block(x: np.ndarray, mesh_edges: np.ndarray, ball_edges: np.ndarray, weights: dict, prefix: str, *,
                 activation: str = "relu") -> np.ndarray:
    """RigNet's GMEdgeConv block, residual included: ``x + fuse([one_ring, ball])``.

    Parameters
    ----------
    x : (n, c) float array, node features
    mesh_edges : (2, e) int array, the mesh one-ring (:func:`.graph.mesh_edges`)
    ball_edges : (2, b) int array, the geodesic balls (:func:`.graph.geodesic_ball_edges`)
    weights : dict of str -> array, holding the EdgeConvs ``prefix + "one_ring."``
        and ``prefix + "ball."`` (max-aggregated, ``c`` outputs each) and the MLP
        ``prefix + "fuse."`` (``2c`` inputs, ``c`` outputs): the ``state_dict`` of
        :class:`autorig_addon.core.nn.training.convolution.GMEdgeBlock` under ``prefix``
    prefix : str, the block's name with its trailing dot (``"gmedge1."``)
    activation : str, every layer's activation (:func:`.layers.mlp`)

    Returns
    -------
    (n, c) float array, the block's new node features.
    """
    one_ring = edge_convolution(x, mesh_edges, weights, prefix + "one_ring.", activation=activation)
    ball = edge_convolution(x, ball_edges, weights, prefix + "ball.", activation=activation)
    return x + mlp(np.concatenate([one_ring, ball], axis=1), weights, prefix + "fuse.", activation=activation)


def multi_aggregator_convolution(x: np.ndarray, edges: np.ndarray, weights: dict, prefix: str, *,
                                 aggregations: tuple = ("mean", "max", "min", "std"), activation: str = "relu",
                                 norm: Optional[str] = None) -> np.ndarray:
    """SkinningNet's Multi-Aggregator Graph Convolution: the EdgeConv
    messages of :func:`edge_convolution`, reduced by several aggregators
    whose results are concatenated and summarised by one more MLP.

    Parameters
    ----------
    x : (n, c) float array
    edges : (2, e) int array
    weights : dict of str -> array, holding ``prefix + "mlp."`` (messages,
        first layer ``2c`` inputs) and ``prefix + "summary."`` (its input is
        ``len(aggregations)`` times the message width)
    prefix : str, the layer's name with its trailing dot
    aggregations : tuple of keys of :data:`.aggregation.AGGREGATIONS`
    activation, norm : the MLPs' settings (:func:`.layers.mlp`)

    Returns
    -------
    (n, out) float array.
    """
    first = prefix + "mlp.linears.0."
    if first + "weight" not in weights:
        raise KeyError(f"No convolution named {prefix!r} in the weights (no {first}weight).")
    hidden = first_layer_per_edge(x, edges, weights[first + "weight"], weights.get(first + "bias"))
    messages = mlp(hidden, weights, prefix + "mlp.", activation=activation, norm=norm, first_linear_applied=True)
    pooled = np.concatenate([AGGREGATIONS[name](messages, edges[1], len(x)) for name in aggregations], axis=1)
    return mlp(pooled, weights, prefix + "summary.", activation=activation, norm=norm)
