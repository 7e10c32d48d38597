"""The skeleton networks' numpy forward passes (inference inside Blender:
core/rigging/joint_network.py and connectivity.py) against their torch
twins (training: core/nn/training/rig_networks.py), and the shipped weights
(core/rigging/trained/) against the torch modules' parameter names."""

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from autorig_addon.core.nn.graph import mesh_edges  # noqa: E402
from autorig_addon.core.nn.training.export import load_module_weights, module_weights  # noqa: E402
from autorig_addon.core.nn.training.rig_networks import NETWORKS  # noqa: E402
from autorig_addon.core.nn.weights_io import load_weights  # noqa: E402
from autorig_addon.core.rigging import predict  # noqa: E402
from autorig_addon.core.rigging.connectivity import (  # noqa: E402
    PAIR_FEATURES, ROOT_FEATURES, bone_probabilities, root_scores,
)
from autorig_addon.core.rigging.joint_features import VERTEX_FEATURES, JointGraph, joint_graph  # noqa: E402
from autorig_addon.core.rigging.joint_network import joint_outputs  # noqa: E402
from geometry_fixtures import procedural_sample  # noqa: E402

#: How far numpy and torch may differ (float32, as the extension runs them).
TWIN_TOLERANCE = 1e-5
#: Voxel resolution of the test's depth features (the default 96 is slower
#: and changes nothing the twin test checks).
RESOLUTION = 32


@pytest.fixture(autouse=True)
def one_torch_thread():
    """These inputs are small: two threads on a busy 2-core machine are
    many times slower than one."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


@pytest.fixture(scope="module")
def procedural_graph():
    """The joint network's input on a small normalised procedural character
    (seed 5: 762 vertices)."""
    from autorig_addon.core.rigging.joint_features import solid_depth

    mesh = procedural_sample(5).mesh
    return joint_graph(mesh, solid_depth(mesh, RESOLUTION))


def random_graph(seed, vertex_count=60):
    """A JointGraph of random features over a random triangle soup, the last
    vertex left out of every triangle (it only has its self loop)."""
    rng = np.random.default_rng(seed)
    triangles = np.array([rng.choice(vertex_count - 1, 3, replace=False) for _ in range(vertex_count)])
    edges = mesh_edges(triangles, vertex_count, self_loops=True)
    ball = np.concatenate([edges, rng.integers(0, vertex_count - 1, (2, 3 * vertex_count))], axis=1)
    return JointGraph(rng.uniform(-0.5, 0.5, (vertex_count, 3)),
                      rng.normal(size=(vertex_count, VERTEX_FEATURES)).astype(np.float32), edges, ball)


def trained_like(name, seed):
    """A network with seeded random parameters doubled (outputs of a few
    units, as after training) and, for the bone and root networks, a
    standardisation that is not the identity; in eval mode."""
    torch.manual_seed(seed)
    network = NETWORKS[name]().eval()
    with torch.no_grad():
        for parameter in network.parameters():
            parameter.mul_(2.0)
        if name != "joints":
            features = network.input_mean.shape[0]
            network.input_mean.copy_(torch.randn(features))
            network.input_std.copy_(torch.rand(features) + 0.5)
    return network


def joint_network_both_ways(network, graph):
    """((offsets, attention) in numpy, the same in torch)."""
    result = joint_outputs(module_weights(network), graph)
    with torch.no_grad():
        offsets, logits = network(torch.from_numpy(graph.vertex_features), torch.from_numpy(graph.mesh_edges),
                                  torch.from_numpy(graph.ball_edges))
    return result, (offsets.numpy(), torch.sigmoid(logits).numpy())


def assert_joint_outputs_agree(network, graph):
    (offsets, attention), (expected_offsets, expected_attention) = joint_network_both_ways(network, graph)
    assert offsets.shape == (graph.vertex_count, 3) and attention.shape == (graph.vertex_count,)
    np.testing.assert_allclose(offsets, expected_offsets, atol=TWIN_TOLERANCE, rtol=0)
    np.testing.assert_allclose(attention, expected_attention, atol=TWIN_TOLERANCE, rtol=0)
    assert np.all((attention > 0) & (attention < 1))
    return offsets, attention


def test_joint_network_numpy_and_torch_agree_on_a_procedural_character(procedural_graph):
    assert procedural_graph.vertex_features.shape == (762, VERTEX_FEATURES)
    offsets, attention = assert_joint_outputs_agree(trained_like("joints", 1), procedural_graph)
    # Outputs that vary (a constant would agree trivially).
    assert offsets.std(axis=0).min() > 0.01 and attention.std() > 0.01


@pytest.mark.parametrize("seed", [2, 3])
def test_joint_network_numpy_and_torch_agree_on_random_graphs(seed):
    assert_joint_outputs_agree(trained_like("joints", seed), random_graph(seed))


@pytest.mark.parametrize("name, features", [("bones", PAIR_FEATURES), ("root", ROOT_FEATURES)])
def test_bone_and_root_networks_numpy_and_torch_agree_on_random_features(name, features):
    network = trained_like(name, 4)
    x = np.random.default_rng(5).normal(size=(300, features)).astype(np.float32)
    with torch.no_grad():
        logits = network(torch.from_numpy(x)).numpy()
    weights = module_weights(network)
    if name == "bones":
        result, expected = bone_probabilities(weights, x), torch.sigmoid(torch.from_numpy(logits)).numpy()
        assert np.all((result > 0) & (result < 1))
    else:
        result, expected = root_scores(weights, x), logits
    assert result.shape == (300,)
    np.testing.assert_allclose(result, expected, atol=TWIN_TOLERANCE, rtol=0)
    assert result.std() > 0.05
    # The standardisation is part of both: without it the outputs differ.
    with torch.no_grad():
        unstandardised = network.mlp(torch.from_numpy(x))[:, 0].numpy()
    assert np.abs(unstandardised - logits).max() > 0.1


@pytest.fixture(scope="module")
def procedural_connectivity_features(procedural_graph):
    """Pair and root features of the procedural character's own joints (on a
    solid of the test's resolution), as the bone and root networks see them."""
    from autorig_addon.core.rigging.connectivity import candidate_pairs, pair_features, root_features
    from autorig_addon.core.rigging.joint_features import solid_depth
    from autorig_addon.core.rigging.training_set import reference_skeleton
    from autorig_addon.core.types import Mesh

    sample = procedural_sample(5)
    solid = solid_depth(Mesh(procedural_graph.vertices, sample.triangles), RESOLUTION)
    joints = reference_skeleton(sample).joints
    pairs = candidate_pairs(joints)
    return {"bones": pair_features(joints, pairs, solid, np.full(len(joints), -1)),
            "root": root_features(joints, solid)}


@pytest.mark.parametrize("name", sorted(predict.NETWORK_FILES))
def test_shipped_weights_load_into_the_torch_modules_with_strict_names(name, procedural_graph,
                                                                       procedural_connectivity_features):
    path = predict.trained_weights_path(name)
    if not path.is_file():
        pytest.fail(f"the shipped {name} weights are missing: {path}")
    weights = load_weights(str(path)).weights
    network = NETWORKS[name]().eval()
    load_module_weights(network, weights)  # strict: a missing or extra name raises
    assert set(weights) == set(network.state_dict())
    # The loaded module computes what the numpy pass computes from the file,
    # on the features of a character.
    if name == "joints":
        assert_joint_outputs_agree(network, procedural_graph)
        return
    x = procedural_connectivity_features[name]
    with torch.no_grad():
        logits = network(torch.from_numpy(x))
    if name == "bones":
        np.testing.assert_allclose(bone_probabilities(weights, x), torch.sigmoid(logits).numpy(),
                                   atol=TWIN_TOLERANCE, rtol=0)
    else:
        np.testing.assert_allclose(root_scores(weights, x), logits.numpy(), atol=TWIN_TOLERANCE, rtol=0)
