"""Numpy kernels of the graph networks (core/nn/aggregation, layers,
convolution) against answers worked out by hand."""

import numpy as np
import pytest

from autorig_addon.core.nn.aggregation import (
    AGGREGATIONS,
    STD_VARIANCE_FLOOR,
    gather,
    segment_counts,
    segment_softmax,
    segment_std,
)
from autorig_addon.core.nn.convolution import edge_convolution, edge_messages, multi_aggregator_convolution
from autorig_addon.core.nn.layers import batch_norm, elu, layer_norm, leaky_relu, linear, mlp, relu

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
    result = AGGREGATIONS[name](VALUES, RECEIVERS, 4)
    assert result.shape == (4, 2)
    np.testing.assert_allclose(result, EXPECTED[name], atol=1e-12)
    # Sorted receivers (the edge builders' order) give the same answer.
    order = np.argsort(RECEIVERS, kind="stable")
    np.testing.assert_allclose(AGGREGATIONS[name](VALUES[order], RECEIVERS[order], 4), EXPECTED[name], atol=1e-12)


def test_reductions_of_no_edges_and_float32_keep_shape_and_dtype():
    for name, reduce in AGGREGATIONS.items():
        empty = reduce(np.zeros((0, 3), np.float32), np.zeros(0, np.int64), 2)
        assert empty.shape == (2, 3) and empty.dtype == np.float32 and not empty.any(), name
        assert reduce(VALUES.astype(np.float32), RECEIVERS, 4).dtype == np.float32, name
    assert segment_counts(RECEIVERS, 4).tolist() == [2, 1, 2, 0]
    with pytest.raises(ValueError, match=r"outside 0\.\.1"):
        AGGREGATIONS["sum"](VALUES, RECEIVERS, 2)


def test_segment_std_is_zero_at_or_below_the_variance_floor():
    spread = np.sqrt(STD_VARIANCE_FLOOR)  # values +-spread have variance exactly the floor
    values = np.array([[7.0], [7.0], [1.0 - spread], [1.0 + 2 * spread]])
    result = segment_std(values, np.array([0, 0, 1, 1]), 2)
    assert result[0, 0] == 0.0
    np.testing.assert_allclose(result[1, 0], 1.5 * spread, rtol=1e-6)


def test_segment_softmax_on_a_hand_worked_graph():
    # exp(scores) = 1, 1, 3, 3, 7: node 2 gets 1 and 3 (0.25, 0.75), node 0
    # gets 1 and 3, node 1 gets 7 alone (1.0). A shift of 1000 changes nothing.
    scores = np.log([1.0, 1.0, 3.0, 3.0, 7.0]) + 1000.0
    np.testing.assert_allclose(segment_softmax(scores, RECEIVERS, 4), [0.25, 0.25, 0.75, 0.75, 1.0], rtol=1e-12)
    two_columns = segment_softmax(np.stack([scores, -scores], axis=1), RECEIVERS, 4)
    np.testing.assert_allclose(two_columns[:, 1], [0.75, 0.75, 0.25, 0.25, 1.0], rtol=1e-12)


def test_gather_and_edge_messages():
    x = np.array([[0.0, 1.0], [1.0, 3.0], [3.0, 9.0]])
    assert gather(x, np.array([2, 2, 0])).tolist() == [[3, 9], [3, 9], [0, 1]]
    # Edge 1 -> 0 carries [x_0, x_1 - x_0].
    assert edge_messages(x, np.array([[1], [0]])).tolist() == [[0, 1, 1, 2]]


def test_activations_and_linear():
    x = np.array([-2.0, -0.5, 0.0, 1.5])
    assert relu(x).tolist() == [0, 0, 0, 1.5]
    assert leaky_relu(x).tolist() == [-0.02, -0.005, 0, 1.5]
    np.testing.assert_allclose(elu(x), [np.exp(-2) - 1, np.exp(-0.5) - 1, 0, 1.5], rtol=1e-12)
    weight = np.array([[1.0, 2.0], [0.0, -1.0], [3.0, 0.5]])  # (out 3, in 2)
    assert linear(np.array([[1.0, 1.0], [2.0, 0.0]]), weight, np.array([0.0, 1.0, -1.0])).tolist() == \
        [[3, 0, 2.5], [2, 1, 5]]


def test_layer_and_batch_norm():
    x = np.array([[1.0, 3.0], [2.0, 2.0]])
    # Row [1, 3]: mean 2, variance 1 -> [-1, 1] / sqrt(1 + eps); row [2, 2] -> [0, 0].
    result = layer_norm(x, np.array([2.0, 1.0]), np.array([0.0, 10.0]))
    np.testing.assert_allclose(result, [[-2 / np.sqrt(1 + 1e-5), 10 + 1 / np.sqrt(1 + 1e-5)], [0, 10]], rtol=1e-12)
    result = batch_norm(x, np.array([1.0, 3.0]), np.array([4.0, 1.0]), np.array([1.0, 1.0]), np.array([0.0, 0.0]),
                        epsilon=0.0)
    assert result.tolist() == [[0, 0], [0.5, -1]]


def test_mlp_reads_torch_state_dict_names():
    weights = {
        "net.linears.0.weight": np.array([[1.0, -1.0], [1.0, 1.0]]),
        "net.linears.0.bias": np.array([0.0, -1.0]),
        "net.linears.1.weight": np.array([[2.0, 1.0]]),
        "net.linears.1.bias": np.array([-5.0]),
    }
    # x = (1, 3): layer 0 gives relu(-2, 3) = (0, 3); layer 1 gives 2*0 + 3 - 5.
    x = np.array([[1.0, 3.0]])
    assert mlp(x, weights, "net.", activate_last=False).tolist() == [[-2.0]]
    # With the last layer activated as well, the negative output is cut to 0.
    assert mlp(x, weights, "net.").tolist() == [[0.0]]
    with pytest.raises(KeyError, match="other"):
        mlp(x, weights, "other.")


def test_edge_convolution_on_a_hand_worked_graph():
    # Nodes x = 0, 1, 3; edges 1 -> 0, 2 -> 0, 0 -> 1; node 2 receives nothing.
    x = np.array([[0.0], [1.0], [3.0]])
    edges = np.array([[1, 2, 0], [0, 0, 1]])
    # Message weight [1, 1] reads x_i + (x_j - x_i) = x_j: node 0 max(1, 3), node 1 gets 0.
    weights = {"conv.mlp.linears.0.weight": np.array([[1.0, 1.0]]), "conv.mlp.linears.0.bias": np.zeros(1)}
    assert edge_convolution(x, edges, weights, "conv.", activate_last=False).tolist() == [[3], [0], [0]]
    # Message weight [0, 1] reads x_j - x_i: node 0 max(1, 3), node 1 gets 0 - 1; mean and min differ.
    weights["conv.mlp.linears.0.weight"] = np.array([[0.0, 1.0]])
    assert edge_convolution(x, edges, weights, "conv.", activate_last=False).tolist() == [[3], [-1], [0]]
    assert edge_convolution(x, edges, weights, "conv.", aggregation="mean", activate_last=False).tolist() == \
        [[2], [-1], [0]]
    assert edge_convolution(x, edges, weights, "conv.", aggregation="min").tolist() == [[1], [0], [0]]


def test_multi_aggregator_convolution_on_a_hand_worked_graph():
    # The graph above: nodes x = 0, 1, 3; edges 1 -> 0, 2 -> 0, 0 -> 1; node 2 receives nothing.
    x = np.array([[0.0], [1.0], [3.0]])
    edges = np.array([[1, 2, 0], [0, 0, 1]])
    # Message weight [0, 1] reads x_j - x_i: node 0 gets 1 and 3, node 1 gets -1.
    weights = {"maconv.mlp.linears.0.weight": np.array([[0.0, 1.0]]), "maconv.mlp.linears.0.bias": np.zeros(1),
               "maconv.summary.linears.0.weight": np.eye(4), "maconv.summary.linears.0.bias": np.zeros(4)}
    # An identity summary shows the pooled (mean, max, min, std) of each node.
    pooled = multi_aggregator_convolution(x, edges, weights, "maconv.", activation="none")
    assert pooled.tolist() == [[2, 3, 1, 1], [-1, -1, -1, 0], [0, 0, 0, 0]]
    # With relu the message -1 becomes 0; the summary then adds the four up and
    # takes max - min - 0.5: node 0 gives 7 and 1.5, node 1 gives 0 and relu(-0.5).
    weights["maconv.summary.linears.0.weight"] = np.array([[1.0, 1, 1, 1], [0, 1, -1, 0]])
    weights["maconv.summary.linears.0.bias"] = np.array([0.0, -0.5])
    assert multi_aggregator_convolution(x, edges, weights, "maconv.").tolist() == [[7, 1.5], [0, 0], [0, 0]]
    # Any subset of the aggregators, in the order given: (sum, min) of node 0 is (4, 1).
    weights["maconv.summary.linears.0.weight"] = np.eye(2)
    weights["maconv.summary.linears.0.bias"] = np.zeros(2)
    assert multi_aggregator_convolution(x, edges, weights, "maconv.", aggregations=("sum", "min"),
                                        activation="none").tolist() == [[4, 1], [-1, -1], [0, 0]]
    with pytest.raises(KeyError, match="other"):
        multi_aggregator_convolution(x, edges, weights, "other.")
