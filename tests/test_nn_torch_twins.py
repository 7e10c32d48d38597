"""The two operations tables, numpy (core/nn/numpy_kernels.py, inside
Blender) and torch (training/nn/torch_kernels.py), kernel by kernel, the
layers written once on them run through both, and gradients through the
torch kernels.

The twins must agree to 1e-6 on random graphs with self loops and nodes
that receive no edge, so a network trained in torch gives the same weights
when Blender runs it with numpy.
"""

from dataclasses import fields

import numpy as np
import pytest

from autorig_addon.core.nn.aggregation import AGGREGATION_NAMES, aggregate
from autorig_addon.core.nn.convolution import (
    edge_convolution,
    edge_messages,
    gmedge_block,
    multi_aggregator_convolution,
)
from autorig_addon.core.nn.layers import mlp
from autorig_addon.core.nn.numpy_kernels import NUMPY, PADDED_BLOCK_SIZE_LIMIT
from autorig_addon.core.nn.operations import Operations
from autorig_addon.core.nn.spec import Dense, NetworkSpec, TrainingSettings
from autorig_addon.core.nn.weights_io import load_weights

torch = pytest.importorskip("torch")
pytestmark = pytest.mark.torch

from autorig_addon.training.nn.modules import (  # noqa: E402
    NetworkModule,
    load_module_weights,
    module_weights,
    save_module,
)
from autorig_addon.training.nn.torch_kernels import TORCH  # noqa: E402

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


def tensors(value):
    """numpy arrays (in a dict, list or alone) as tensors; anything else as it is."""
    if isinstance(value, dict):
        return {name: tensors(item) for name, item in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(tensors(item) for item in value)
    return torch.from_numpy(value) if isinstance(value, np.ndarray) else value


def both(function, *arguments):
    """``function(NUMPY, *arguments)`` and ``function(TORCH, *tensors)`` as numpy arrays."""
    expected = function(NUMPY, *arguments)
    with torch.no_grad():
        result = function(TORCH, *tensors(list(arguments)))
    return expected, result.numpy()


def test_both_tables_fill_every_operation():
    for table in (NUMPY, TORCH):
        assert all(getattr(table, field.name) is not None for field in fields(Operations))
    assert sorted(NUMPY.activations) == sorted(TORCH.activations)


@pytest.mark.parametrize("dtype, tolerance", [(np.float64, 1e-6), (np.float32, 1e-5)])
@pytest.mark.parametrize("name", AGGREGATION_NAMES)
def test_reductions_agree_on_random_graphs(name, dtype, tolerance):
    for seed in range(3):
        edges = random_graph(seed)
        values = np.random.default_rng(seed + 10).normal(size=(edges.shape[1], 6)).astype(dtype)
        expected, result = both(lambda ops, v, i: aggregate(ops, name, v, i, NODE_COUNT), values, edges[1])
        assert result.dtype == expected.dtype == dtype
        np.testing.assert_allclose(result, expected, atol=tolerance, rtol=0)
        assert not expected[RECEIVING_NODES:].any()  # empty segments give 0 in both
        # Features of more than one axis reduce the same way.
        expected, result = both(lambda ops, v, i: aggregate(ops, name, v, i, NODE_COUNT),
                                values.reshape(len(values), 2, 3), edges[1])
        np.testing.assert_allclose(result, expected, atol=tolerance, rtol=0)


@pytest.mark.parametrize("name", ["max", "min"])
def test_max_and_min_agree_around_a_hub(name):
    # One node receives most edges, so the numpy kernel sorts and reduces
    # runs instead of padding every node to the hub's width.
    rng = np.random.default_rng(11)
    receivers = np.where(rng.random(300) < 0.8, 0, rng.integers(1, RECEIVING_NODES, 300))
    values = rng.normal(size=(300, 4))
    assert NODE_COUNT * np.bincount(receivers).max() > PADDED_BLOCK_SIZE_LIMIT * len(values)
    expected, result = both(lambda ops, v, i: aggregate(ops, name, v, i, NODE_COUNT), values, receivers)
    np.testing.assert_array_equal(result, expected)
    assert not expected[RECEIVING_NODES:].any()
    reduce = np.max if name == "max" else np.min
    np.testing.assert_array_equal(expected[0], reduce(values[receivers == 0], axis=0))


def test_the_other_kernels_agree():
    rng = np.random.default_rng(3)
    x, weight, bias = rng.normal(size=(7, 4)), rng.normal(size=(3, 4)), rng.normal(size=3)
    index = np.array([6, 0, 0, 3])
    mask = x > 0.3
    valid = rng.random((7, 4)) < 0.6
    valid[:, 0] = True  # every row has a valid entry
    cases = {
        "linear": (lambda ops: ops.linear(*tensors_for(ops, x, weight, bias))),
        "linear without bias": (lambda ops: ops.linear(*tensors_for(ops, x, weight), None)),
        "concat": (lambda ops: ops.concat(tensors_for(ops, x, x[:, :2]), 1)),
        "column max": (lambda ops: ops.column_max(*tensors_for(ops, x))),
        "repeat rows": (lambda ops: ops.repeat_rows(*tensors_for(ops, x[:1]), 5)),
        "gather": (lambda ops: ops.gather(*tensors_for(ops, x, index))),
        "log": (lambda ops: ops.log(*tensors_for(ops, np.abs(x) + 0.1))),
        "sqrt": (lambda ops: ops.sqrt(*tensors_for(ops, np.abs(x)))),
        "clamp min": (lambda ops: ops.clamp_min(*tensors_for(ops, x), 0.2)),
        "where": (lambda ops: ops.where(*tensors_for(ops, mask, x), 0.0)),
        "nonzero": (lambda ops: ops.nonzero(*tensors_for(ops, mask.reshape(-1)))),
        "scatter": (lambda ops: ops.scatter(*tensors_for(ops, x[:4, 0], np.array([9, 2, 5, 0])), 12)),
        "masked row softmax": (lambda ops: ops.masked_row_softmax(*tensors_for(ops, 30 * x, valid))),
        "column softmax": (lambda ops: ops.column_softmax(*tensors_for(ops, 30 * x))),
        **{f"activation {name}": (lambda ops, name=name: ops.activations[name](*tensors_for(ops, x)))
           for name in NUMPY.activations},
    }
    for case, function in cases.items():
        expected = function(NUMPY)
        result = function(TORCH).numpy()
        assert result.shape == expected.shape, case
        np.testing.assert_allclose(result, expected, atol=1e-12, err_msg=case)
    assert cases["nonzero"](NUMPY).dtype == np.int64


def tensors_for(ops, *arrays):
    return arrays if ops is NUMPY else tuple(torch.from_numpy(np.asarray(array)) for array in arrays)


def test_gradients_of_max_and_mean_reach_the_right_edges():
    # Edges 0 and 1 (values 1 and 3) go to node 0, edge 2 (value 5) to node 1; node 2 is empty.
    values = torch.tensor([[1.0], [3.0], [5.0]], requires_grad=True)
    index = torch.tensor([0, 0, 1])
    TORCH.segment_max(values, index, 3).sum().backward()
    assert values.grad.flatten().tolist() == [0.0, 1.0, 1.0]
    values.grad = None
    TORCH.segment_mean(values, index, 3).sum().backward()
    assert values.grad.flatten().tolist() == [0.5, 0.5, 1.0]


@pytest.mark.parametrize("name", AGGREGATION_NAMES)
def test_torch_reductions_pass_gradcheck(name):
    generator = torch.Generator().manual_seed(7)
    index = torch.tensor([0, 2, 0, 1, 2, 0, 2, 1])  # node 3 receives nothing
    values = torch.randn(8, 3, generator=generator, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda v: aggregate(TORCH, name, v, index, 4), (values,), eps=1e-6, atol=1e-5)


def test_segment_std_gradient_stays_finite_on_constant_and_empty_segments():
    values = torch.tensor([[2.0], [2.0], [1.0], [4.0]], dtype=torch.float64, requires_grad=True)
    result = aggregate(TORCH, "std", values, torch.tensor([0, 0, 1, 1]), 3)
    assert result.flatten().tolist() == [0.0, 1.5, 0.0]
    result.sum().backward()
    assert torch.isfinite(values.grad).all()
    # d std / d x_k = (x_k - mean) / (count * std): (1 - 2.5) / 3 and (4 - 2.5) / 3.
    np.testing.assert_allclose(values.grad.flatten().numpy(), [0.0, 0.0, -0.5, 0.5], atol=1e-12)


def random_params(seed, layers):
    """Random float32 weights of MLPs ``{prefix: widths}`` by state_dict name."""
    rng = np.random.default_rng(seed)
    params = {}
    for prefix, widths in layers.items():
        for index, (width_in, width_out) in enumerate(zip(widths[:-1], widths[1:])):
            params[f"{prefix}linears.{index}.weight"] = rng.normal(0, 0.5, (width_out, width_in)).astype(np.float32)
            params[f"{prefix}linears.{index}.bias"] = rng.normal(0, 0.5, width_out).astype(np.float32)
    return params


@pytest.mark.parametrize("activation", sorted(NUMPY.activations))
def test_mlp_agrees(activation):
    params = random_params(1, {"net.": (5, 16, 8, 3)})
    x = np.random.default_rng(2).normal(size=(50, 5)).astype(np.float32)
    for last in (True, False):
        expected, result = both(lambda ops, p, v: mlp(ops, p, v, "net.", activation=activation, activate_last=last),
                                params, x)
        assert expected.dtype == np.float32
        np.testing.assert_allclose(result, expected, atol=1e-5, rtol=0)


@pytest.mark.parametrize("aggregation", AGGREGATION_NAMES)
def test_edge_convolution_agrees(aggregation):
    edges = random_graph(8)
    x = np.random.default_rng(9).normal(size=(NODE_COUNT, 4)).astype(np.float32)
    params = random_params(0, {"conv.mlp.": (8, 16, 8)})
    expected, result = both(lambda ops, p, v, e: edge_convolution(ops, p, v, e, "conv.", activation="leaky_relu",
                                                                  aggregation=aggregation), params, x, edges)
    assert expected.shape == (NODE_COUNT, 8)
    np.testing.assert_allclose(result, expected, atol=1e-5, rtol=0)
    assert not expected[RECEIVING_NODES:].any()


def test_gmedge_block_and_multi_aggregator_convolution_agree():
    edges, ball = random_graph(13), random_graph(14, edge_count=400)
    x = np.random.default_rng(15).normal(size=(NODE_COUNT, 4)).astype(np.float32)
    params = random_params(2, {"block.one_ring.mlp.": (8, 4), "block.ball.mlp.": (8, 4), "block.fuse.": (8, 4),
                               "multi.mlp.": (8, 16, 8), "multi.summary.": (32, 8)})
    expected, result = both(lambda ops, p, v, e, b: gmedge_block(ops, p, v, e, b, "block.", activation="leaky_relu"),
                            params, x, edges, ball)
    np.testing.assert_allclose(result, expected, atol=1e-5, rtol=0)
    # The residual: a node that receives nothing keeps its features plus the fused zeros.
    fused_zeros = mlp(NUMPY, params, np.zeros((1, 8), np.float32), "block.fuse.", activation="leaky_relu")
    np.testing.assert_allclose(expected[RECEIVING_NODES:], x[RECEIVING_NODES:] + fused_zeros, atol=1e-6)
    expected, result = both(lambda ops, p, v, e: multi_aggregator_convolution(ops, p, v, e, "multi.",
                                                                              activation="leaky_relu"),
                            params, x, edges)
    assert expected.shape == (NODE_COUNT, 8) and expected.dtype == np.float32
    np.testing.assert_allclose(result, expected, atol=1e-5, rtol=0)


def test_edge_convolution_equals_the_mlp_of_the_written_out_messages():
    # The first layer computed per node and gathered is the same linear map.
    edges = random_graph(12)
    x = np.random.default_rng(4).normal(size=(NODE_COUNT, 5))
    params = {name: value.astype(np.float64) for name, value in random_params(5, {"conv.mlp.": (10, 7, 3)}).items()}
    for ops in (NUMPY, TORCH):
        arguments = tensors_for(ops, x, edges) if ops is TORCH else (x, edges)
        weights = tensors(params) if ops is TORCH else params
        written_out = ops.segment_max(mlp(ops, weights, edge_messages(ops, *arguments), "conv.mlp.", activation="relu"),
                                      arguments[1][1], NODE_COUNT)
        convolved = edge_convolution(ops, weights, *arguments, "conv.", activation="relu")
        np.testing.assert_allclose(np.asarray(convolved), np.asarray(written_out), atol=1e-12, rtol=0)


def test_a_saved_module_loads_back_into_torch_and_numpy(tmp_path):
    spec = NetworkSpec(name="tiny", label="Tiny", description="A two-layer MLP", inputs="(r, 4) features",
                       layers=(Dense("mlp", (4, 6, 2)),),
                       forward=lambda ops, params, x: mlp(ops, params, x, "mlp.", activation="leaky_relu"),
                       training=TrainingSettings(1, 1e-3), weights_file=tmp_path / "tiny.npz")
    torch.manual_seed(4)
    module = NetworkModule(spec).eval()
    save_module(module, str(spec.weights_file), metadata={"model": "tiny", "channels": [4, 6, 2]})
    loaded = load_weights(str(spec.weights_file))
    assert loaded.metadata == {"model": "tiny", "channels": [4, 6, 2]}
    assert {name: value.shape for name, value in loaded.weights.items()} == spec.parameter_shapes()
    spec.check_weights(loaded.weights, "tiny.npz")
    fresh = NetworkModule(spec).eval()
    load_module_weights(fresh, loaded.weights)
    x = torch.randn(9, 4)
    assert torch.equal(fresh(x), module(x))
    np.testing.assert_allclose(spec.forward(NUMPY, loaded.weights, x.numpy()), module(x).detach().numpy(), atol=1e-6)
    assert module_weights(fresh).keys() == loaded.weights.keys()
