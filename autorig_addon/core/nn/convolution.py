"""Edge convolution, the message -> aggregate -> update layer the networks
share, written once against an operations table (:mod:`.operations`).

EdgeConv (Wang et al. 2019, the building block of RigNet's GMEdgeConv):
every edge ``j -> i`` carries the message ``MLP([x_i, x_j - x_i])``, the
receiver aggregates its messages (max by default), and the update keeps the
aggregate as the node's new features. A node that receives no edge gets 0.
The MLP's weights are ``prefix + "mlp."`` (:func:`.layers.mlp`).

The MLP's first layer is linear, so with its weight split as ``[A, B]``
(columns for ``x_i`` and for ``x_j - x_i``) it equals
``(A - B) x_i + B x_j + bias``: both terms are computed once per node and
gathered per edge, instead of building the (e, 2c) message rows, which
saves most of the layer's time (a mesh has ~10-40 times more edges than
vertices).

RigNet's GMEdgeConv block (:func:`gmedge_block`) runs two EdgeConvs, over
the mesh one-ring and over geodesic balls, and fuses them with a residual;
RigNet's trunk (:func:`gmedge_trunk`: an encoder, stacked blocks and a
max-pooled shape code) carries both its skinning and its joint network. SkinningNet's
multi-aggregator convolution (:func:`multi_aggregator_convolution`) pools
the same messages several ways. Their parameter layouts are
:class:`.spec.GMEdge` and :class:`.spec.MultiAggregator`.
"""

from __future__ import annotations

from .aggregation import aggregate
from .layers import layer_count, mlp
from .operations import Array, Operations

#: The aggregators of SkinningNet's convolution.
MULTI_AGGREGATIONS = ("mean", "max", "min", "std")


def edge_messages(ops: Operations, x: Array, edges: Array) -> Array:
    """(e, 2c) rows ``[x_i, x_j - x_i]`` of every edge ``j -> i``, from
    (n, c) node features and a (2, e) edge index (senders, receivers): the
    EdgeConv MLP's input, written out (:func:`edge_convolution` does not
    build it; tests compare the two)."""
    receivers = ops.gather(x, edges[1])
    return ops.concat([receivers, ops.gather(x, edges[0]) - receivers], 1)


def _first_layer_per_node(ops: Operations, x: Array, weight: Array, bias) -> tuple:
    """The first layer's two per-node terms, ``(A - B) x + bias`` and ``B x``
    (see the module docstring): (n, c), (out, 2c), (out,) give two (n, out)."""
    channels = x.shape[1]
    receiver_weight, difference_weight = weight[:, :channels], weight[:, channels:]
    return ops.linear(x, receiver_weight - difference_weight, bias), ops.linear(x, difference_weight, None)


def first_layer_per_edge(ops: Operations, x: Array, edges: Array, weight: Array, bias) -> Array:
    """``linear(edge_messages(x, edges), weight, bias)`` computed per node
    then gathered: (n, c), (2, e), (out, 2c), (out,) give (e, out)."""
    at_receiver, at_sender = _first_layer_per_node(ops, x, weight, bias)
    return ops.gather(at_receiver, edges[1]) + ops.gather(at_sender, edges[0])


def _largest_one_layer_message(ops: Operations, params: dict, x: Array, edges: Array, prefix: str, *,
                               activation: str, activate_last: bool) -> Array:
    """(n, out): the max-aggregated messages of a one-layer EdgeConv MLP,
    without a row per edge. A message is ``f(a_i + b_j)`` with ``a_i`` the
    receiver's term, ``b_j`` the sender's and ``f`` an activation that never
    decreases (all of ``ops.activations`` do), and adding ``a_i`` never
    reorders two numbers, rounding included, so the largest message is
    ``f(a_i + max_j b_j)``, to the last bit: one activation per node instead
    of one per edge. A node that receives no edge gets 0, as the segment
    max gives it."""
    first = prefix + "mlp.linears.0."
    at_receiver, at_sender = _first_layer_per_node(ops, x, params[first + "weight"], params.get(first + "bias"))
    senders, receivers, count = edges[0], edges[1], x.shape[0]
    largest = ops.segment_max(ops.gather(at_sender, senders), receivers, count)
    received = ops.segment_max(ops.gather(at_sender[:, :1] * 0 + 1, senders), receivers, count) > 0
    activate = ops.activations[activation] if activate_last else ops.activations["none"]
    return ops.where(received, activate(at_receiver + largest), 0.0)


def edge_messages_mlp(ops: Operations, params: dict, x: Array, edges: Array, prefix: str, *,
                      activation: str, activate_last: bool = True) -> Array:
    """(e, out): the MLP ``prefix + "mlp."`` of every edge's message."""
    first = prefix + "mlp.linears.0."
    if first + "weight" not in params:
        raise KeyError(f"No convolution named {prefix!r} in the weights (no {first}weight).")
    hidden = first_layer_per_edge(ops, x, edges, params[first + "weight"], params.get(first + "bias"))
    return mlp(ops, params, hidden, prefix + "mlp.", activation=activation, activate_last=activate_last,
               first_linear_applied=True)


def edge_convolution(ops: Operations, params: dict, x: Array, edges: Array, prefix: str, *, activation: str,
                     aggregation: str = "max", activate_last: bool = True) -> Array:
    """One EdgeConv layer.

    Parameters
    ----------
    ops : Operations
    params : dict of str -> array, holding the MLP ``prefix + "mlp."``
        whose first layer takes ``2c`` inputs
    x : (n, c) float array, node features
    edges : (2, e) int array, senders then receivers (:mod:`.graph`)
    prefix : str, the layer's name with its trailing dot (``"conv1."``)
    activation, activate_last : the MLP's settings (:func:`.layers.mlp`)
    aggregation : str, one of :data:`.aggregation.AGGREGATION_NAMES`

    Returns
    -------
    (n, out) float array, the aggregated messages of each node.
    """
    if aggregation == "max" and ops.name == "numpy" and layer_count(params, prefix + "mlp.") == 1:
        # Inference only: training keeps the per-edge rows, so its gradients (a tie is split the same way)
        # and its recorded runs stay as they were; the torch twins check the two agree.
        return _largest_one_layer_message(ops, params, x, edges, prefix, activation=activation,
                                          activate_last=activate_last)
    messages = edge_messages_mlp(ops, params, x, edges, prefix, activation=activation, activate_last=activate_last)
    return aggregate(ops, aggregation, messages, edges[1], x.shape[0])


def gmedge_block(ops: Operations, params: dict, x: Array, mesh_edges: Array, ball_edges: Array, prefix: str, *,
                 activation: str) -> Array:
    """RigNet's GMEdgeConv block, residual included: ``x + fuse([one_ring, ball])``.

    Parameters
    ----------
    ops : Operations
    params : dict of str -> array, holding the EdgeConvs ``prefix + "one_ring."``
        and ``prefix + "ball."`` (max-aggregated, ``c`` outputs each) and the MLP
        ``prefix + "fuse."`` (``2c`` inputs, ``c`` outputs): :class:`.spec.GMEdge`
    x : (n, c) float array, node features
    mesh_edges : (2, e) int array, the mesh one-ring (:func:`.graph.mesh_edges`)
    ball_edges : (2, b) int array, the geodesic balls (:func:`.graph.geodesic_ball_edges`)
    prefix : str, the block's name with its trailing dot (``"gmedge1."``)
    activation : str, every layer's activation

    Returns
    -------
    (n, c) float array, the block's new node features.
    """
    one_ring = edge_convolution(ops, params, x, mesh_edges, prefix + "one_ring.", activation=activation)
    ball = edge_convolution(ops, params, x, ball_edges, prefix + "ball.", activation=activation)
    return x + mlp(ops, params, ops.concat([one_ring, ball], 1), prefix + "fuse.", activation=activation)


def gmedge_trunk(ops: Operations, params: dict, x: Array, mesh_edges: Array, ball_edges: Array, blocks: tuple, *,
                 activation: str) -> Array:
    """RigNet's trunk: the MLP ``"encoder."``, the GMEdgeConv ``blocks`` in
    turn, and a shape code (the MLP ``"shape."`` of the last features,
    max-pooled over every node); its layout is :class:`.spec.GMEdgeTrunk`.

    Parameters
    ----------
    x : (n, in) float array, node features
    mesh_edges, ball_edges : (2, e), (2, b) int arrays, as :func:`gmedge_block`
    blocks : tuple of str, the blocks' names (``("gmedge1", "gmedge2")``)

    Returns
    -------
    (n, (len(blocks) + 1) * c + s) float array: the encoder's and every
    block's features side by side, then the shape code on every row.
    """
    x = mlp(ops, params, x, "encoder.", activation=activation)
    levels = [x]
    for block in blocks:
        x = gmedge_block(ops, params, x, mesh_edges, ball_edges, block + ".", activation=activation)
        levels.append(x)
    shape = ops.column_max(mlp(ops, params, x, "shape.", activation=activation))
    return ops.concat(levels + [ops.repeat_rows(shape, x.shape[0])], 1)


def multi_aggregator_convolution(ops: Operations, params: dict, x: Array, edges: Array, prefix: str, *,
                                 activation: str, aggregations: tuple = MULTI_AGGREGATIONS) -> Array:
    """SkinningNet's Multi-Aggregator Graph Convolution: the EdgeConv
    messages, reduced by several aggregators whose results are concatenated
    and summarised by one more MLP.

    Parameters
    ----------
    ops : Operations
    params : dict of str -> array, holding ``prefix + "mlp."`` (messages,
        first layer ``2c`` inputs) and ``prefix + "summary."`` (its input is
        ``len(aggregations)`` times the message width): :class:`.spec.MultiAggregator`
    x : (n, c) float array
    edges : (2, e) int array
    prefix : str, the layer's name with its trailing dot
    activation : str, the MLPs' activation
    aggregations : tuple of names of :data:`.aggregation.AGGREGATION_NAMES`

    Returns
    -------
    (n, out) float array.
    """
    messages = edge_messages_mlp(ops, params, x, edges, prefix, activation=activation)
    pooled = ops.concat([aggregate(ops, name, messages, edges[1], x.shape[0]) for name in aggregations], 1)
    return mlp(ops, params, pooled, prefix + "summary.", activation=activation)
