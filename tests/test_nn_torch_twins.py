"""The torch kernels (core/nn/training) against their numpy twins, and
gradients through the torch aggregators.

The twins must agree to 1e-6 on random graphs with self loops and nodes
that receive no edge, so a network trained in torch gives the same weights
when Blender runs it with numpy.
"""

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from autorig_addon.core.nn import aggregation as numpy_aggregation  # noqa: E402
from autorig_addon.core.nn import layers as numpy_layers  # noqa: E402
from autorig_addon.core.nn.convolution import edge_convolution, multi_aggregator_convolution  # noqa: E402
from autorig_addon.core.nn.training import aggregation as torch_aggregation  # noqa: E402
from autorig_addon.core.nn.training import layers as torch_layers  # noqa: E402
from autorig_addon.core.nn.training.convolution import EdgeConv, MultiAggregatorConv, edge_messages  # noqa: E402
from autorig_addon.core.nn.training.export import load_module_weights, module_weights, save_module  # noqa: E402
from autorig_addon.core.nn.training.layers import MLP  # noqa: E402
from autorig_addon.core.nn.weights_io import load_weights  # noqa: E402

NODE_COUNT = 40
#: Nodes at or above this index receive no edge (empty segments).
RECEIVING_NODES = 30


def random_graph(seed, edge_count=200, self_loops=10):
    """(2, e) edges: random ones into the first RECEIVING_NODES nodes plus self loops."""
    rng = np.random.default_rng(seed)
    senders = rng.integers(0, NODE_COUNT, edge_count)
    receivers = rng.integers(0, RECEIVING_NODES, edge_count)
    loops = rng.choice(RECEIVING_NODES, self_loops, replace=False)
    return np.stack([np.concatenate([senders, loops]), np.concatenate([receivers, loops])]).astype(np.int64)


@pytest.mark.parametrize("dtype, tolerance", [(np.float64, 1e-6), (np.float32, 1e-5)])
@pytest.mark.parametrize("name", sorted(numpy_aggregation.AGGREGATIONS))
def test_torch_and_numpy_reductions_agree_on_random_graphs(name, dtype, tolerance):
    for seed in range(3):
        edges = random_graph(seed)
        values = np.random.default_rng(seed + 10).normal(size=(edges.shape[1], 6)).astype(dtype)
        expected = numpy_aggregation.AGGREGATIONS[name](values, edges[1], NODE_COUNT)
        result = torch_aggregation.AGGREGATIONS[name](torch.from_numpy(values), torch.from_numpy(edges[1]), NODE_COUNT)
        assert result.dtype == torch.from_numpy(values).dtype
        np.testing.assert_allclose(result.numpy(), expected, atol=tolerance, rtol=0)
        assert not expected[RECEIVING_NODES:].any()  # empty segments give 0 in both
        # Features of more than one axis reduce the same way.
        three_axes = values.reshape(len(values), 2, 3)
        np.testing.assert_allclose(
            torch_aggregation.AGGREGATIONS[name](torch.from_numpy(three_axes), torch.from_numpy(edges[1]),
                                                 NODE_COUNT).numpy(),
            numpy_aggregation.AGGREGATIONS[name](three_axes, edges[1], NODE_COUNT), atol=tolerance, rtol=0)


@pytest.mark.parametrize("name", ["max", "min"])
def test_torch_and_numpy_max_and_min_agree_around_a_hub(name):
    # One node receives most edges, so the numpy twin sorts and reduces runs
    # instead of padding every node to the hub's width.
    rng = np.random.default_rng(11)
    receivers = np.where(rng.random(300) < 0.8, 0, rng.integers(1, RECEIVING_NODES, 300))
    values = rng.normal(size=(300, 4))
    assert NODE_COUNT * np.bincount(receivers).max() > numpy_aggregation.PADDED_BLOCK_SIZE_LIMIT * len(values)
    expected = numpy_aggregation.AGGREGATIONS[name](values, receivers, NODE_COUNT)
    result = torch_aggregation.AGGREGATIONS[name](torch.from_numpy(values), torch.from_numpy(receivers), NODE_COUNT)
    np.testing.assert_array_equal(result.numpy(), expected)
    assert not expected[RECEIVING_NODES:].any()
    reduce = np.max if name == "max" else np.min
    np.testing.assert_array_equal(expected[0], reduce(values[receivers == 0], axis=0))


def test_torch_and_numpy_softmax_and_gather_agree():
    edges = random_graph(4)
    scores = np.random.default_rng(5).normal(scale=30.0, size=(edges.shape[1], 3))
    expected = numpy_aggregation.segment_softmax(scores, edges[1], NODE_COUNT)
    result = torch_aggregation.segment_softmax(torch.from_numpy(scores), torch.from_numpy(edges[1]), NODE_COUNT)
    np.testing.assert_allclose(result.numpy(), expected, atol=1e-6, rtol=0)
    np.testing.assert_allclose(numpy_aggregation.segment_sum(expected, edges[1], NODE_COUNT)[:RECEIVING_NODES], 1.0,
                               rtol=1e-12)
    x = np.random.default_rng(6).normal(size=(NODE_COUNT, 4))
    assert np.array_equal(torch_aggregation.gather(torch.from_numpy(x), torch.from_numpy(edges[0])).numpy(),
                          numpy_aggregation.gather(x, edges[0]))


def test_gradients_of_max_and_mean_reach_the_right_edges():
    # Edges 0 and 1 (values 1 and 3) go to node 0, edge 2 (value 5) to node 1; node 2 is empty.
    values = torch.tensor([[1.0], [3.0], [5.0]], requires_grad=True)
    index = torch.tensor([0, 0, 1])
    torch_aggregation.segment_max(values, index, 3).sum().backward()
    assert values.grad.flatten().tolist() == [0.0, 1.0, 1.0]
    values.grad = None
    torch_aggregation.segment_mean(values, index, 3).sum().backward()
    assert values.grad.flatten().tolist() == [0.5, 0.5, 1.0]


@pytest.mark.parametrize("name", ["sum", "mean", "max", "min", "std", "softmax"])
def test_torch_aggregators_pass_gradcheck(name):
    generator = torch.Generator().manual_seed(7)
    index = torch.tensor([0, 2, 0, 1, 2, 0, 2, 1])  # node 3 receives nothing
    values = torch.randn(8, 3, generator=generator, dtype=torch.float64, requires_grad=True)
    if name == "softmax":
        function = lambda v: torch_aggregation.segment_softmax(v, index, 4)  # noqa: E731
    else:
        function = lambda v: torch_aggregation.AGGREGATIONS[name](v, index, 4)  # noqa: E731
    assert torch.autograd.gradcheck(function, (values,), eps=1e-6, atol=1e-5)


def test_segment_std_gradient_stays_finite_on_constant_and_empty_segments():
    values = torch.tensor([[2.0], [2.0], [1.0], [4.0]], dtype=torch.float64, requires_grad=True)
    result = torch_aggregation.segment_std(values, torch.tensor([0, 0, 1, 1]), 3)
    assert result.flatten().tolist() == [0.0, 1.5, 0.0]
    result.sum().backward()
    assert torch.isfinite(values.grad).all()
    # d std / d x_k = (x_k - mean) / (count * std): (1 - 2.5) / 3 and (4 - 2.5) / 3.
    np.testing.assert_allclose(values.grad.flatten().numpy(), [0.0, 0.0, -0.5, 0.5], atol=1e-12)


def trained_like_mlp(channels, norm, activation, activate_last, seed):
    """An MLP in eval mode whose batch-norm statistics and norm parameters are
    not the defaults (so the twin test would see a wrong formula)."""
    torch.manual_seed(seed)
    module = MLP(channels, activation=activation, norm=norm, activate_last=activate_last).double()
    with torch.no_grad():
        for name, tensor in module.named_buffers():
            if name.endswith("running_mean"):
                tensor.normal_()
            elif name.endswith("running_var"):
                tensor.uniform_(0.5, 2.0)
        for name, parameter in module.named_parameters():
            if name.startswith("norms."):
                parameter.normal_()
    return module.eval()


@pytest.mark.parametrize("norm", numpy_layers.NORM_KINDS)
@pytest.mark.parametrize("activation", sorted(numpy_layers.ACTIVATIONS))
def test_exported_torch_mlp_matches_the_numpy_mlp(norm, activation):
    module = trained_like_mlp([5, 16, 8, 3], norm, activation, activate_last=False, seed=1)
    x = np.random.default_rng(2).normal(size=(50, 5))
    expected = module(torch.from_numpy(x)).detach().numpy()
    result = numpy_layers.mlp(x, module_weights(module), "", activation=activation, norm=norm, activate_last=False)
    np.testing.assert_allclose(result, expected, atol=1e-6, rtol=0)
    # float32, as the extension runs it.
    module32 = module.float()
    expected32 = module32(torch.from_numpy(x.astype(np.float32))).detach().numpy()
    result32 = numpy_layers.mlp(x.astype(np.float32), module_weights(module32), "", activation=activation, norm=norm,
                                activate_last=False)
    assert result32.dtype == np.float32
    np.testing.assert_allclose(result32, expected32, atol=1e-5, rtol=0)


def test_functional_layers_agree():
    rng = np.random.default_rng(3)
    x, weight, bias = rng.normal(size=(7, 4)), rng.normal(size=(3, 4)), rng.normal(size=3)
    t = torch.from_numpy
    np.testing.assert_allclose(torch_layers.linear(t(x), t(weight), t(bias)).numpy(),
                               numpy_layers.linear(x, weight, bias), atol=1e-12)
    for name in numpy_layers.ACTIVATIONS:
        np.testing.assert_allclose(torch_layers.ACTIVATIONS[name](t(x)).numpy(), numpy_layers.ACTIVATIONS[name](x),
                                   atol=1e-12)
    scale, shift, mean, variance = rng.normal(size=4), rng.normal(size=4), rng.normal(size=4), rng.uniform(0.5, 2, 4)
    np.testing.assert_allclose(torch_layers.layer_norm(t(x), t(scale), t(shift)).numpy(),
                               numpy_layers.layer_norm(x, scale, shift), atol=1e-12)
    np.testing.assert_allclose(torch_layers.batch_norm(t(x), t(mean), t(variance), t(scale), t(shift)).numpy(),
                               numpy_layers.batch_norm(x, mean, variance, scale, shift), atol=1e-12)


@pytest.mark.parametrize("aggregation", sorted(numpy_aggregation.AGGREGATIONS))
def test_torch_and_numpy_edge_convolution_agree(aggregation):
    edges = random_graph(8)
    x = np.random.default_rng(9).normal(size=(NODE_COUNT, 4))
    torch.manual_seed(0)
    layer = EdgeConv(4, [16, 8], aggregation=aggregation, norm="layer").double().eval()
    expected = layer(torch.from_numpy(x), torch.from_numpy(edges)).detach().numpy()
    result = edge_convolution(x, edges, module_weights(layer), "", aggregation=aggregation, norm="layer")
    assert result.shape == (NODE_COUNT, 8)
    np.testing.assert_allclose(result, expected, atol=1e-6, rtol=0)
    assert not result[RECEIVING_NODES:].any()


@pytest.mark.parametrize("norm, aggregations", [(None, ("mean", "max", "min", "std")), ("layer", ("sum", "std"))])
def test_torch_and_numpy_multi_aggregator_convolution_agree(norm, aggregations):
    edges = random_graph(13)
    x = np.random.default_rng(14).normal(size=(NODE_COUNT, 4)).astype(np.float32)
    torch.manual_seed(2)
    layer = MultiAggregatorConv(4, [16, 8], aggregations=aggregations, activation="leaky_relu", norm=norm).eval()
    expected = layer(torch.from_numpy(x), torch.from_numpy(edges)).detach().numpy()
    weights = module_weights(layer)
    assert weights["summary.linears.0.weight"].shape == (8, 8 * len(aggregations))
    result = multi_aggregator_convolution(x, edges, weights, "", aggregations=aggregations, activation="leaky_relu",
                                          norm=norm)
    assert result.shape == (NODE_COUNT, 8) and result.dtype == np.float32
    np.testing.assert_allclose(result, expected, atol=1e-5, rtol=0)
    # A node that receives nothing pools zeros, so it gets the summary of 0.
    empty = multi_aggregator_convolution(np.zeros((1, 4), np.float32), np.zeros((2, 0), np.int64), weights, "",
                                         aggregations=aggregations, activation="leaky_relu", norm=norm)
    np.testing.assert_allclose(result[RECEIVING_NODES:], np.repeat(empty, NODE_COUNT - RECEIVING_NODES, axis=0),
                               atol=1e-6)
    # Every parameter learns (the std aggregator's gradient included).
    layer.train()
    layer(torch.from_numpy(x), torch.from_numpy(edges)).sum().backward()
    assert all(parameter.grad is not None and parameter.grad.abs().sum() > 0 for parameter in layer.parameters())


def test_edge_convolution_equals_the_mlp_of_the_written_out_messages():
    # The first layer computed per node and gathered is the same linear map.
    edges = torch.from_numpy(random_graph(12))
    torch.manual_seed(1)
    layer = EdgeConv(5, [7, 3], norm="batch", activation="elu").double().eval()
    x = torch.randn(NODE_COUNT, 5, dtype=torch.float64)
    written_out = torch_aggregation.segment_max(layer.mlp(edge_messages(x, edges)), edges[1], NODE_COUNT)
    torch.testing.assert_close(layer(x, edges), written_out, atol=1e-12, rtol=0)


def test_edge_convolution_gradients_reach_every_parameter():
    edges = torch.from_numpy(random_graph(10))
    layer = EdgeConv(3, [8, 4]).double()
    layer(torch.randn(NODE_COUNT, 3, dtype=torch.float64), edges).sum().backward()
    assert all(parameter.grad is not None and parameter.grad.abs().sum() > 0 for parameter in layer.parameters())


def test_saved_module_loads_back_into_torch_and_numpy(tmp_path):
    module = trained_like_mlp([4, 6, 2], "batch", "elu", activate_last=False, seed=4).float()
    path = tmp_path / "model.npz"
    save_module(module, str(path), metadata={"model": "test", "channels": [4, 6, 2]})
    loaded = load_weights(str(path))
    assert loaded.metadata == {"model": "test", "channels": [4, 6, 2]}
    assert sorted(loaded.weights) == sorted(module.state_dict())
    assert loaded.weights["norms.0.num_batches_tracked"].dtype == np.int64
    fresh = MLP([4, 6, 2], activation="elu", norm="batch", activate_last=False).eval()
    load_module_weights(fresh, loaded.weights)
    x = torch.randn(9, 4)
    assert torch.equal(fresh(x), module(x))
    np.testing.assert_allclose(numpy_layers.mlp(x.numpy(), loaded.weights, "", activation="elu", norm="batch",
                                                activate_last=False), module(x).detach().numpy(), atol=1e-5)
