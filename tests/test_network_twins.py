"""Every network, written once (its spec's forward), gives the same outputs
run by numpy inside Blender and by torch in training: same weights, same
outputs to 1e-5 on random inputs and on a real (procedural) character; the
shipped weights load into the torch module by their exact names; an
untrained skinning network gives back its prior."""

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.nn.numpy_kernels import NUMPY
from autorig_addon.core.nn.spec import shipped_weights
from autorig_addon.core.rigging.joint_features import VERTEX_FEATURES, JointGraph, joint_graph, solid_depth
from autorig_addon.core.rigging.networks import RIG_NETWORKS
from autorig_addon.core.rigging.networks.landmarks import LANDMARK_NETWORK_NAMES
from autorig_addon.core.rigging.tree_features import (
    PAIR_FEATURES,
    ROOT_FEATURES,
    candidate_pairs,
    pair_features,
    root_features,
)
from autorig_addon.core.rigging.up_features import UP_FEATURE_COUNT, area_centroids, candidate_features
from autorig_addon.core.skinning.learned import predict
from autorig_addon.core.skinning.learned.features import PRIOR_FLOOR, skin_graph
from autorig_addon.core.skinning.learned.networks import SKIN_NETWORKS
from autorig_addon.core.skinning.learned.networks.scoring import candidate_weights
from autorig_addon.core.types import Mesh
from geometry_fixtures import procedural_sample, random_skin_inputs, two_bone_skeleton

torch = pytest.importorskip("torch")
pytestmark = pytest.mark.torch

from autorig_addon.core.nn.graph import mesh_edges  # noqa: E402
from autorig_addon.training.nn.modules import (  # noqa: E402
    NetworkModule,
    as_tensors,
    load_module_weights,
    module_weights,
)
from autorig_addon.training.nn.torch_kernels import TORCH  # noqa: E402
from autorig_addon.training.rigging.training_set import reference_skeleton  # noqa: E402

#: How far numpy and torch may differ on an output (float32, as the extension runs them).
TWIN_TOLERANCE = 1e-5
#: Voxel resolution of the tests' distances and depths (the defaults are
#: slower and change nothing these tests check).
RESOLUTION = 32
NETWORKS = {**SKIN_NETWORKS, **RIG_NETWORKS}


def trained_like(name, seed, prior_scale=0.8):
    """The network's module with seeded random parameters doubled (outputs of
    a few units, as after training; the skinning score heads, which start at
    zero, get random values too), a prior scale that is not 1 and a
    standardisation that is not the identity; in eval mode."""
    torch.manual_seed(seed)
    module = NetworkModule(NETWORKS[name]).eval()
    with torch.no_grad():
        for parameter_name, parameter in module.named_parameters():
            if parameter_name == "prior_scale":
                parameter.fill_(prior_scale)
            elif not parameter.abs().sum():
                parameter.normal_(0.0, 0.1)
            else:
                parameter.mul_(2.0)
        if hasattr(module, "input_mean"):
            features = module.input_mean.shape[0]
            module.input_mean.copy_(torch.randn(features))
            module.input_std.copy_(torch.rand(features) + 0.5)
    return module


def random_joint_graph(seed, vertex_count=60):
    """A JointGraph of random features over a random triangle soup, the last
    vertex left out of every triangle (it only has its self loop)."""
    rng = np.random.default_rng(seed)
    triangles = np.array([rng.choice(vertex_count - 1, 3, replace=False) for _ in range(vertex_count)])
    edges = mesh_edges(triangles, vertex_count, self_loops=True)
    ball = np.concatenate([edges, rng.integers(0, vertex_count - 1, (2, 3 * vertex_count))], axis=1)
    return JointGraph(rng.uniform(-0.5, 0.5, (vertex_count, 3)),
                      rng.normal(size=(vertex_count, VERTEX_FEATURES)).astype(np.float32), edges, ball)


def random_inputs(name, seed):
    """Random inputs of the network ``name``."""
    rng = np.random.default_rng(seed)
    if name in SKIN_NETWORKS:
        bone_count = (1, 3, 9)[seed % 3]
        return skin_graph(*random_skin_inputs(seed, 40 + bone_count, bone_count))
    if name in ("joints", *LANDMARK_NETWORK_NAMES):
        return random_joint_graph(seed)
    columns = {"bones": PAIR_FEATURES, "root": ROOT_FEATURES, "upright": UP_FEATURE_COUNT}[name]
    return rng.normal(size=(300, columns)).astype(np.float32)


@pytest.fixture(scope="module")
def procedural_inputs():
    """Every network's inputs on the procedural character of seed 5 (762
    vertices, 30 bones), normalised: skin graphs by distance kind, its
    joint graph, and the pair and root features of its own joints."""
    sample = procedural_sample(5)
    skin = {distance: predict.network_graph(sample.mesh, sample.skeleton, distance, resolution=RESOLUTION)
            for distance in ("geodesic", "hollow")}
    solid = solid_depth(sample.mesh, RESOLUTION)
    joints = reference_skeleton(sample).joints
    inputs = {name: skin[spec.distance] for name, spec in SKIN_NETWORKS.items()}
    graph = joint_graph(sample.mesh, solid)
    inputs.update(joints=graph, **dict.fromkeys(LANDMARK_NETWORK_NAMES, graph),
                  bones=pair_features(joints, candidate_pairs(joints), solid, np.full(len(joints), -1)),
                  root=root_features(joints, solid),
                  upright=candidate_features(*area_centroids(sample.mesh.vertices, sample.mesh.triangles)).astype(
                      np.float32))
    return inputs


def both_ways(module, inputs):
    """The network's outputs as a tuple of numpy arrays: (numpy forward on
    the exported weights, torch module); a skinning network's are its
    candidate weights."""
    spec, weights = module.spec, module_weights(module)
    numpy_outputs = spec.forward(NUMPY, weights, inputs)
    tensors = as_tensors(inputs)
    with torch.no_grad():
        torch_outputs = module(tensors)
        if spec.name in SKIN_NETWORKS:
            numpy_outputs = candidate_weights(NUMPY, weights, inputs, numpy_outputs)
            torch_outputs = candidate_weights(TORCH, module.params(), tensors, torch_outputs)

    def as_tuple(outputs):
        return outputs if isinstance(outputs, tuple) else (outputs,)

    return as_tuple(numpy_outputs), tuple(output.numpy() for output in as_tuple(torch_outputs))


def assert_agree(module, inputs):
    numpy_outputs, torch_outputs = both_ways(module, inputs)
    for result, expected in zip(numpy_outputs, torch_outputs, strict=True):
        assert result.dtype == np.float32 and result.shape == expected.shape
        np.testing.assert_allclose(result, expected, atol=TWIN_TOLERANCE, rtol=0)
    return numpy_outputs


@pytest.mark.parametrize("name", sorted(NETWORKS))
def test_numpy_and_torch_give_the_same_outputs_on_random_inputs(name):
    for seed in range(3):
        outputs = assert_agree(trained_like(name, seed), random_inputs(name, seed))
        # Outputs that vary (a constant would agree trivially).
        assert max(float(np.std(output)) for output in outputs) > 0.01


@pytest.mark.parametrize("name", sorted(NETWORKS))
def test_numpy_and_torch_give_the_same_outputs_on_a_procedural_character(name, procedural_inputs):
    inputs = procedural_inputs[name]
    outputs = assert_agree(trained_like(name, 7), inputs)
    assert max(float(np.std(output)) for output in outputs) > 0.01
    if name in SKIN_NETWORKS:
        np.testing.assert_allclose(outputs[0].sum(axis=1), 1, atol=1e-6)
        assert not outputs[0][~inputs.valid].any()
        assert np.abs(outputs[0] - prior_weights(inputs)).max() > 0.05  # moved well away from the prior


@pytest.mark.parametrize("name", sorted(NETWORKS))
def test_shipped_weights_load_by_their_exact_names_and_run_alike(name, procedural_inputs):
    spec = NETWORKS[name]
    weights = shipped_weights(spec).weights
    module = NetworkModule(spec).eval()
    load_module_weights(module, weights)  # strict: a missing or extra name raises
    assert {key: tuple(value.shape) for key, value in module.state_dict().items()} == spec.parameter_shapes()
    assert_agree(module, procedural_inputs[name])


def test_a_weights_file_of_another_network_is_refused_by_name():
    weights = shipped_weights(RIG_NETWORKS["root"]).weights
    with pytest.raises(InputError, match=r"^root\.npz does not hold the bones network's weights \(other shape: "
                                         r"input_mean, input_std, mlp\.linears\.0\.bias, mlp\.linears\.0\.weight "
                                         r"\.\.\.\)\.$"):
        RIG_NETWORKS["bones"].check_weights(weights, "root.npz")
    with pytest.raises(InputError, match=r"skinningnet network.s weights \(missing: bone_encoder.*"
                                         r"unexpected: input_mean"):
        SKIN_NETWORKS["skinningnet"].check_weights(weights, "root.npz")


def prior_weights(graph):
    """What a network whose scores are all 0 gives with prior_scale 1:
    softmax of log(prior + floor) over the valid candidates, i.e. the
    prior plus the floor, renormalised over them."""
    lifted = np.where(graph.valid, graph.prior.astype(np.float64) + PRIOR_FLOOR, 0.0)
    return lifted / lifted.sum(axis=1, keepdims=True)


@pytest.mark.parametrize("name", sorted(SKIN_NETWORKS))
def test_an_untrained_skinning_network_gives_back_its_prior(name, procedural_inputs):
    # Built from its spec, the score head starts at zero and the prior scale at 1.
    module = NetworkModule(SKIN_NETWORKS[name]).eval()
    graph = procedural_inputs[name]
    (result,), (expected,) = both_ways(module, graph)
    np.testing.assert_allclose(result, prior_weights(graph), atol=1e-6)
    np.testing.assert_allclose(expected, prior_weights(graph), atol=1e-6)
    # By hand on a two-bone chain: a prior (0.8, 0.2) becomes (0.801, 0.201)
    # / 1.002; a bone the prior leaves at 0 keeps 0.001 / 1.002.
    chain = skin_graph(Mesh([[1.0, 0, 0.5], [1, 1, 0.5], [1, 0, 1.5]], [[0, 1, 2]]), two_bone_skeleton(2.0),
                       np.array([[1.0, 1.5], [1.0, 1.5], [1.0, 1.5]]), np.array([[0.8, 0.2], [1.0, 0.0], [0.5, 0.5]]))
    (result,), (expected,) = both_ways(module, chain)
    by_hand = [[0.801 / 1.002, 0.201 / 1.002, 0, 0, 0], [1.001 / 1.002, 0.001 / 1.002, 0, 0, 0],
               [0.5, 0.5, 0, 0, 0]]
    np.testing.assert_allclose(result, by_hand, atol=1e-6)
    np.testing.assert_allclose(expected, by_hand, atol=1e-6)


@pytest.mark.parametrize("name", sorted(NETWORKS))
def test_every_parameter_learns(name, procedural_inputs):
    module = trained_like(name, 3).train()
    outputs = module(as_tensors(procedural_inputs[name]))
    sum(output.square().sum() for output in (outputs if isinstance(outputs, tuple) else (outputs,))).backward()
    frozen = [key for key, parameter in module.named_parameters() if name in SKIN_NETWORKS and key == "prior_scale"
              or parameter.grad is None or not parameter.grad.abs().sum()]
    # The prior scale only enters the candidate weights, not the scores.
    assert frozen == (["prior_scale"] if name in SKIN_NETWORKS else [])
