"""Numpy kernels of the graph networks (core/nn/numpy_kernels) and the layers
written once on them (aggregation, layers, convolution) against answers
worked out by hand."""

import dataclasses

import numpy as np
import pytest

from autorig_addon.core.nn.aggregation import AGGREGATION_NAMES, STD_VARIANCE_FLOOR, aggregate, segment_std
from autorig_addon.core.nn.convolution import edge_convolution, edge_messages, multi_aggregator_convolution
from autorig_addon.core.nn.layers import mlp, standardised
from autorig_addon.core.nn.numpy_kernels import (
    NUMPY,
    column_softmax,
    gather,
    leaky_relu,
    linear,
    masked_row_softmax,
    relu,
    scatter,
    segment_counts,
    sigmoid,
)

# 4 nodes, 5 edges (not sorted by receiver); node 3 receives nothing.
#   edge:     0        1        2        3       4
#   receiver: 2        0        2        0       1
#   value:   (4, 1)  (1, -2)  (-2, 3)  (3, 2)  (5, 0)
RECEIVERS = np.array([2, 0, 2, 0, 1])
VALUES = np.array([[4.0, 1.0], [1.0, -2.0], [-2.0, 3.0], [3.0, 2.0], [5.0, 0.0]])
# Node 0 gets (1,-2), (3,2); node 1 gets (5,0); node 2 gets (4,1), (-2,3).
EXPECTED = {
    "sum": [[4, 0], [5, 0], [2, 4], [0, 0]],
    "mean": [[2, 0], [5, 0], [1, 2], [0, 0]],
    "max": [[3, 2], [5, 0], [4, 3], [0, 0]],
    "min": [[1, -2], [5, 0], [-2, 1], [0, 0]],
    # node 0: E[x^2] - E[x]^2 = 5 - 4 and 4 - 0; node 2: 10 - 1 and 5 - 4.
    "std": [[1, 2], [0, 0], [3, 1], [0, 0]],
}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_segment_reductions_on_a_hand_worked_graph(name):
    result = aggregate(NUMPY, name, VALUES, RECEIVERS, 4)
    assert result.shape == (4, 2)
    np.testing.assert_allclose(result, EXPECTED[name], atol=1e-12)
    # Sorted receivers (the edge builders' order) give the same answer.
    order = np.argsort(RECEIVERS, kind="stable")
    np.testing.assert_allclose(aggregate(NUMPY, name, VALUES[order], RECEIVERS[order], 4), EXPECTED[name],
                               atol=1e-12)


def test_reductions_of_no_edges_and_float32_keep_shape_and_dtype():
    assert sorted(AGGREGATION_NAMES) == sorted(EXPECTED)
    for name in AGGREGATION_NAMES:
        empty = aggregate(NUMPY, name, np.zeros((0, 3), np.float32), np.zeros(0, np.int64), 2)
        assert empty.shape == (2, 3) and empty.dtype == np.float32 and not empty.any(), name
        assert aggregate(NUMPY, name, VALUES.astype(np.float32), RECEIVERS, 4).dtype == np.float32, name
    assert segment_counts(RECEIVERS, 4).tolist() == [2, 1, 2, 0]
    with pytest.raises(ValueError, match=r"outside 0\.\.1"):
        aggregate(NUMPY, "sum", VALUES, RECEIVERS, 2)
    with pytest.raises(ValueError, match="Unknown aggregation 'median'"):
        aggregate(NUMPY, "median", VALUES, RECEIVERS, 4)


def test_segment_std_is_zero_at_or_below_the_variance_floor():
    spread = np.sqrt(STD_VARIANCE_FLOOR)  # values +-spread have variance exactly the floor
    values = np.array([[7.0], [7.0], [1.0 - spread], [1.0 + 2 * spread]])
    result = segment_std(NUMPY, values, np.array([0, 0, 1, 1]), 2)
    assert result[0, 0] == 0.0
    np.testing.assert_allclose(result[1, 0], 1.5 * spread, rtol=1e-6)


def test_masked_row_softmax_scatter_and_sigmoid_by_hand():
    # exp(logits) = 1, 3 and an invalid entry: 0.25, 0.75, 0. A shift of 1000 changes nothing.
    logits = np.log([[1.0, 3.0, 5.0], [7.0, 1.0, 1.0]]) + 1000.0
    valid = np.array([[True, True, False], [True, False, False]])
    np.testing.assert_allclose(masked_row_softmax(logits, valid), [[0.25, 0.75, 0], [1, 0, 0]], rtol=1e-12)
    assert scatter(np.array([4.0, 5.0]), np.array([3, 0]), 4).tolist() == [5, 0, 0, 4]
    np.testing.assert_allclose(sigmoid(np.array([0.0, np.log(3.0), -800.0])), [0.5, 0.75, 0.0], atol=1e-15)


def test_column_softmax_by_hand():
    # Each column over its rows: exp = 1 and 3 give 0.25 and 0.75; a shift of 1000 changes nothing.
    logits = np.log([[1.0, 2.0], [3.0, 2.0]]) + np.array([1000.0, -5.0])
    np.testing.assert_allclose(column_softmax(logits), [[0.25, 0.5], [0.75, 0.5]], rtol=1e-12)


def test_gather_and_edge_messages():
    x = np.array([[0.0, 1.0], [1.0, 3.0], [3.0, 9.0]])
    assert gather(x, np.array([2, 2, 0])).tolist() == [[3, 9], [3, 9], [0, 1]]
    # Edge 1 -> 0 carries [x_0, x_1 - x_0].
    assert edge_messages(NUMPY, x, np.array([[1], [0]])).tolist() == [[0, 1, 1, 2]]


def test_activations_and_linear():
    x = np.array([-2.0, -0.5, 0.0, 1.5])
    assert relu(x).tolist() == [0, 0, 0, 1.5]
    assert leaky_relu(x).tolist() == [-0.02, -0.005, 0, 1.5]
    # The larger of x and slope * x is the same, bit for bit, as x where positive: infinities, NaN, -0 and
    # subnormals too, in either precision.
    special = [np.nan, -0.0, 0.0, np.inf, -np.inf, -1e-45, 1e-45]
    for dtype, bits in ((np.float32, np.uint32), (np.float64, np.uint64)):
        many = np.concatenate([np.random.default_rng(0).normal(size=1000), special]).astype(dtype)
        for slope in (0.01, 0.2):
            expected = np.where(many > 0, many, many * dtype(slope))
            result = leaky_relu(many, slope)
            assert result.dtype == dtype and np.array_equal(result.view(bits), expected.view(bits))
    assert leaky_relu(np.array(-2.0)) == -0.02
    for slope in (0.0, 1.0, 1.5):
        with pytest.raises(ValueError, match="slope in"):
            leaky_relu(x, slope)
    weight = np.array([[1.0, 2.0], [0.0, -1.0], [3.0, 0.5]])  # (out 3, in 2)
    assert linear(np.array([[1.0, 1.0], [2.0, 0.0]]), weight, np.array([0.0, 1.0, -1.0])).tolist() == \
        [[3, 0, 2.5], [2, 1, 5]]


def test_mlp_reads_torch_state_dict_names():
    weights = {
        "net.linears.0.weight": np.array([[1.0, -1.0], [1.0, 1.0]]),
        "net.linears.0.bias": np.array([0.0, -1.0]),
        "net.linears.1.weight": np.array([[2.0, 1.0]]),
        "net.linears.1.bias": np.array([-5.0]),
    }
    # x = (1, 3): layer 0 gives relu(-2, 3) = (0, 3); layer 1 gives 2*0 + 3 - 5.
    x = np.array([[1.0, 3.0]])
    assert mlp(NUMPY, weights, x, "net.", activation="relu", activate_last=False).tolist() == [[-2.0]]
    # With the last layer activated as well, the negative output is cut to 0.
    assert mlp(NUMPY, weights, x, "net.", activation="relu").tolist() == [[0.0]]
    with pytest.raises(KeyError, match="other"):
        mlp(NUMPY, weights, x, "other.", activation="relu")
    # Standardised inputs: (1 - 0) / 2 and (3 - 1) / 4.
    assert standardised({"input_mean": np.array([0.0, 1.0]), "input_std": np.array([2.0, 4.0])}, x).tolist() == \
        [[0.5, 0.5]]


def test_edge_convolution_on_a_hand_worked_graph():
    # Nodes x = 0, 1, 3; edges 1 -> 0, 2 -> 0, 0 -> 1; node 2 receives nothing.
    x = np.array([[0.0], [1.0], [3.0]])
    edges = np.array([[1, 2, 0], [0, 0, 1]])
    # Message weight [1, 1] reads x_i + (x_j - x_i) = x_j: node 0 max(1, 3), node 1 gets 0.
    weights = {"conv.mlp.linears.0.weight": np.array([[1.0, 1.0]]), "conv.mlp.linears.0.bias": np.zeros(1)}
    def convolved(**settings):
        return edge_convolution(NUMPY, weights, x, edges, "conv.", activation="relu", **settings).tolist()

    assert convolved(activate_last=False) == [[3], [0], [0]]
    # Message weight [0, 1] reads x_j - x_i: node 0 max(1, 3), node 1 gets 0 - 1; mean and min differ.
    weights["conv.mlp.linears.0.weight"] = np.array([[0.0, 1.0]])
    assert convolved(activate_last=False) == [[3], [-1], [0]]
    assert convolved(aggregation="mean", activate_last=False) == [[2], [-1], [0]]
    assert convolved(aggregation="min") == [[1], [0], [0]]


@pytest.mark.parametrize("activation", sorted(NUMPY.activations))
def test_a_max_aggregated_one_layer_edge_convolution_equals_its_per_edge_rows_to_the_last_bit(activation):
    """numpy takes the largest of a receiver's messages ``f(a_i + b_j)`` as ``f(a_i + max_j b_j)`` (one
    activation per node, not per edge); written per edge (the table under another name, as torch runs it)
    the numbers are the same bit for bit: float32, senders with equal features (ties), nodes that receive
    nothing."""
    rng = np.random.default_rng(3)
    x = rng.normal(size=(60, 8)).astype(np.float32)
    x[10:14] = x[9]  # senders whose messages tie
    edges = rng.integers(0, 50, size=(2, 400))  # nodes 50..59 receive nothing
    edges[0, :20] = rng.integers(9, 14, size=20)
    weights = {"conv.mlp.linears.0.weight": rng.normal(size=(16, 16)).astype(np.float32),
               "conv.mlp.linears.0.bias": rng.normal(size=16).astype(np.float32)}
    per_edge = dataclasses.replace(NUMPY, name="numpy, per edge")
    for activate_last in (True, False):
        fast = edge_convolution(NUMPY, weights, x, edges, "conv.", activation=activation, activate_last=activate_last)
        rows = edge_convolution(per_edge, weights, x, edges, "conv.", activation=activation,
                                activate_last=activate_last)
        assert fast.dtype == rows.dtype == np.float32
        assert np.array_equal(fast, rows)
        assert not fast[50:].any() and fast[:50].any()


def test_multi_aggregator_convolution_on_a_hand_worked_graph():
    # The graph above: nodes x = 0, 1, 3; edges 1 -> 0, 2 -> 0, 0 -> 1; node 2 receives nothing.
    x = np.array([[0.0], [1.0], [3.0]])
    edges = np.array([[1, 2, 0], [0, 0, 1]])
    # Message weight [0, 1] reads x_j - x_i: node 0 gets 1 and 3, node 1 gets -1.
    weights = {"maconv.mlp.linears.0.weight": np.array([[0.0, 1.0]]), "maconv.mlp.linears.0.bias": np.zeros(1),
               "maconv.summary.linears.0.weight": np.eye(4), "maconv.summary.linears.0.bias": np.zeros(4)}
    # An identity summary shows the pooled (mean, max, min, std) of each node.
    def convolved(prefix="maconv.", activation="relu", **settings):
        return multi_aggregator_convolution(NUMPY, weights, x, edges, prefix, activation=activation,
                                            **settings).tolist()

    pooled = np.array(convolved(activation="none"))
    assert pooled.tolist() == [[2, 3, 1, 1], [-1, -1, -1, 0], [0, 0, 0, 0]]
    # With relu the message -1 becomes 0; the summary then adds the four up and
    # takes max - min - 0.5: node 0 gives 7 and 1.5, node 1 gives 0 and relu(-0.5).
    weights["maconv.summary.linears.0.weight"] = np.array([[1.0, 1, 1, 1], [0, 1, -1, 0]])
    weights["maconv.summary.linears.0.bias"] = np.array([0.0, -0.5])
    assert convolved() == [[7, 1.5], [0, 0], [0, 0]]
    # Any subset of the aggregators, in the order given: (sum, min) of node 0 is (4, 1).
    weights["maconv.summary.linears.0.weight"] = np.eye(2)
    weights["maconv.summary.linears.0.bias"] = np.zeros(2)
    assert convolved(aggregations=("sum", "min"), activation="none") == [[4, 1], [-1, -1], [0, 0]]
    with pytest.raises(KeyError, match="other"):
        convolved("other.")
