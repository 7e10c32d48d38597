"""Training the skinning networks: the examples and their variants
(training/skinning/learned/training_set.py), the on-the-fly augmentation,
the loss and a tiny reproducible run (training/skinning/learned/train.py)."""

import math

import numpy as np
import pytest

from autorig_addon.core.nn.graph import mesh_edges
from autorig_addon.core.skinning.learned import predict
from autorig_addon.core.skinning.learned.features import (
    BONE_FEATURES,
    BONE_VECTORS,
    PAIR_FEATURES,
    PAIR_VECTORS,
    VERTEX_FEATURES,
    VERTEX_VECTORS,
    candidate_targets,
    skin_graph,
)
from autorig_addon.core.skinning.learned.networks import SKIN_NETWORKS
from autorig_addon.core.types import Mesh, Skeleton
from autorig_addon.training.skinning.learned import training_set
from geometry_fixtures import procedural_sample, random_skin_inputs

torch = pytest.importorskip("torch")
pytestmark = pytest.mark.torch

from autorig_addon.training.nn.modules import as_tensors  # noqa: E402
from autorig_addon.training.runs import procedural_samples, start_run  # noqa: E402
from autorig_addon.training.skinning.learned.train import (  # noqa: E402
    augmented,
    candidate_cross_entropy,
    holdout_scores,
    train_network,
)

#: Voxel resolution of the tests' distances (fast; the default is 88).
RESOLUTION = 32
TURN = math.radians(30.0)
TURN_MATRIX = np.array([[math.cos(TURN), -math.sin(TURN), 0.0], [math.sin(TURN), math.cos(TURN), 0.0], [0, 0, 1]])
MIRROR_MATRIX = np.diag([-1.0, 1.0, 1.0])


def vector_columns(starts, width):
    """(vector columns, other columns) of a feature table ``width`` wide."""
    vectors = [column for start in starts for column in range(start, start + 3)]
    return vectors, [column for column in range(width) if column not in vectors]


@pytest.mark.parametrize("matrix", [TURN_MATRIX, MIRROR_MATRIX], ids=["turn", "mirror"])
def test_augmented_turns_the_vector_columns_and_nothing_else(matrix):
    graph = skin_graph(*random_skin_inputs(1, 30, 7))
    result = augmented(as_tensors(graph), matrix)
    for name, starts, width in (("vertex_features", VERTEX_VECTORS, VERTEX_FEATURES),
                                ("pair_features", PAIR_VECTORS, PAIR_FEATURES),
                                ("bone_features", BONE_VECTORS, BONE_FEATURES)):
        before, after = getattr(graph, name), getattr(result, name).numpy()
        assert after.shape == before.shape and after.dtype == np.float32
        _, others = vector_columns(starts, width)
        for start in starts:
            np.testing.assert_allclose(after[..., start:start + 3], before[..., start:start + 3] @ matrix.T,
                                       atol=1e-6, err_msg=name)
        assert np.array_equal(after[..., others], before[..., others]), name
    if matrix is MIRROR_MATRIX:  # only x changes sign
        x_columns = list(VERTEX_VECTORS)
        np.testing.assert_array_equal(result.vertex_features[:, x_columns].numpy(),
                                      -graph.vertex_features[:, x_columns])
        assert np.array_equal(result.vertex_features[:, [1, 2, 4, 5]].numpy(), graph.vertex_features[:, [1, 2, 4, 5]])
    for name in ("candidates", "valid", "prior", "mesh_edges", "ball_edges", "bone_edges"):
        assert np.array_equal(getattr(result, name).numpy(), getattr(graph, name)), name


@pytest.mark.parametrize("matrix", [TURN_MATRIX, MIRROR_MATRIX], ids=["turn", "mirror"])
def test_augmented_features_are_those_of_the_turned_character(matrix):
    # Turning or mirroring the character changes no distance, so the features
    # of the moved character are the augmented ones (a mirror also flips the
    # triangles' winding, which keeps the normals outward).
    mesh, skeleton, distances, prior = random_skin_inputs(2, 30, 7)
    moved_mesh = Mesh(mesh.vertices @ matrix.T,
                      mesh.triangles[:, ::-1] if np.linalg.det(matrix) < 0 else mesh.triangles)
    moved_skeleton = Skeleton(skeleton.joints @ matrix.T, skeleton.parents, skeleton.names, skeleton.tails @ matrix.T)
    moved = skin_graph(moved_mesh, moved_skeleton, distances, prior)
    result = augmented(as_tensors(skin_graph(mesh, skeleton, distances, prior)), matrix)
    for name in ("vertex_features", "pair_features", "bone_features"):
        np.testing.assert_allclose(getattr(result, name).numpy(), getattr(moved, name), atol=1e-5, err_msg=name)


def test_candidate_cross_entropy_by_hand():
    predicted = torch.tensor([[0.5, 0.5, 0, 0, 0], [0.25, 0.75, 0, 0, 0], [0.9, 0.1, 0, 0, 0]])
    target = torch.tensor([[1.0, 0, 0, 0, 0], [0.5, 0.5, 0, 0, 0], [0, 0, 0, 0, 0]])
    # Row 0: -log 0.5; row 1: -(log 0.25 + log 0.75) / 2; row 2 has no weight and is left out.
    expected = (math.log(2) + (math.log(4) + math.log(4 / 3)) / 2) / 2
    assert float(candidate_cross_entropy(predicted, target)) == pytest.approx(expected, rel=1e-6)


@pytest.fixture(scope="module")
def tiny_training_set():
    """Two procedural characters' SkinningNet inputs: ``(train, holdout)``."""
    train, holdout = [], []
    for seed in (5, 4):
        sample = procedural_sample(seed)
        graph = predict.network_graph(sample.mesh, sample.skeleton, "geodesic", resolution=RESOLUTION)
        train.append((sample.name, graph, candidate_targets(graph, sample.weights)))
        if seed == 5:
            holdout.append((sample.name, graph, sample.weights))
    return train, holdout


def test_a_training_run_is_reproducible_and_keeps_its_best_epoch(tiny_training_set):
    train, holdout = tiny_training_set
    spec = SKIN_NETWORKS["skinningnet"]
    runs = []
    for _ in range(2):
        lines = []
        record = start_run(spec, seed=3, device="cpu", epochs=2, learning_rate=None, score_name="l1")
        runs.append(train_network(spec, train, holdout, record, log=lines.append))
    first, second = runs
    assert sorted(first) == sorted(second)
    for name in first:
        assert np.array_equal(first[name], second[name]), name
    assert [entry["epoch"] for entry in record.history] == [0, 1, 2]
    assert record.history[0]["loss"] is None and all(entry["loss"] > 0 for entry in record.history[1:])
    l1s = [entry["l1"] for entry in record.history]
    assert record.best_score == min(l1s) and record.best_epoch == l1s.index(min(l1s))
    # The returned weights are the kept epoch's: the numpy forward pass scores them the same.
    assert holdout_scores(spec, first, [(graph, reference) for _, graph, reference in holdout])["l1"] == \
        pytest.approx(record.best_score, abs=1e-12)
    assert record.parameters == sum(value.size for name, value in first.items())
    assert record.learning_rate == spec.training.learning_rate and record.details["train_examples"] == 2
    assert len(lines) == 3 and "epoch 2/2" in lines[-1]
    # Another seed trains another network.
    other = train_network(spec, train, holdout, start_run(spec, seed=4, device="cpu", epochs=1, learning_rate=None,
                                                          score_name="l1"), log=lambda line: None)
    assert not np.array_equal(other["join.linears.0.weight"], first["join.linears.0.weight"])


def test_sample_variants_are_normalised_stretched_and_posed():
    sample = procedural_sample(4)
    variants = training_set.sample_variants(sample, seed=11)
    assert [suffix for suffix, _, _ in variants] == ["rest", "stretch0", "stretch1", "pose0", "pose1"]
    rest = variants[0][1]
    assert np.array_equal(rest.vertices, sample.vertices)
    rest_extent = np.ptp(rest.vertices, axis=0)
    for suffix, mesh, skeleton in variants:
        assert mesh.vertex_count == sample.mesh.vertex_count and np.array_equal(mesh.triangles, sample.triangles)
        assert skeleton.names == sample.deform_names and skeleton.deform.all()
        low, high = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
        assert abs((high - low).max() - 1) < 1e-9 and abs(low[2]) < 1e-12, suffix
        np.testing.assert_allclose((low + high)[:2] / 2, 0, atol=1e-12, err_msg=suffix)
        if suffix.startswith("stretch"):  # the proportions change
            assert np.abs(np.ptp(mesh.vertices, axis=0) / rest_extent - 1).max() > 0.02, suffix
    # Re-posed: the mesh moves, but an edge whose two ends follow one bone
    # alone keeps its length (up to the one scale of the new normalisation).
    edges = mesh_edges(sample.triangles, sample.mesh.vertex_count)
    single = sample.weights.max(axis=1) > 1 - 1e-12
    bone = sample.weights.argmax(axis=1)
    rigid = single[edges[0]] & single[edges[1]] & (bone[edges[0]] == bone[edges[1]])
    assert rigid.mean() > 0.3
    rest_lengths = np.linalg.norm(rest.vertices[edges[0]] - rest.vertices[edges[1]], axis=1)
    for suffix, mesh, _ in variants[3:]:
        assert np.abs(mesh.vertices - rest.vertices).max() > 0.02, suffix
        ratios = np.linalg.norm(mesh.vertices[edges[0]] - mesh.vertices[edges[1]], axis=1) / rest_lengths
        scale = np.median(ratios[rigid])
        np.testing.assert_allclose(ratios[rigid], scale, rtol=1e-9, err_msg=suffix)
        assert np.abs(ratios[~rigid] / scale - 1).max() > 0.01, suffix
    # The same seed gives the same variants; no augmentation gives the rest alone.
    again = training_set.sample_variants(sample, seed=11)
    assert all(np.array_equal(a[1].vertices, b[1].vertices) for a, b in zip(variants, again))
    assert [suffix for suffix, _, _ in training_set.sample_variants(sample, seed=11, augment=False)] == ["rest"]


def test_examples_are_written_once_and_read_back(tmp_path):
    sample = procedural_sample(5)
    paths = training_set.build_examples([sample], "hollow", augment=False, folder=tmp_path)
    assert paths == [tmp_path / f"v{training_set.EXAMPLE_FORMAT_VERSION}" / "hollow" / "seed0"
                     / "procedural_5--rest.npz"]
    graph, target, reference, name = training_set.load_example(paths[0])
    expected = predict.network_graph(sample.mesh, sample.skeleton, "hollow")
    for field, array in expected.arrays().items():
        assert np.array_equal(getattr(graph, field), array), field
    assert np.array_equal(target, candidate_targets(expected, sample.weights))
    assert reference.dtype == np.float32 and np.array_equal(reference, sample.weights.astype(np.float32))
    assert name == "procedural_5--rest"
    written = paths[0].stat().st_mtime_ns
    assert training_set.build_examples([sample], "hollow", augment=False, folder=tmp_path) == paths
    assert paths[0].stat().st_mtime_ns == written
    assert [path.name for path in paths[0].parent.iterdir()] == ["procedural_5--rest.npz"]  # no temporary left


def test_procedural_samples_are_normalised_characters_named_by_kind_and_seed():
    samples = procedural_samples(2)
    assert [sample.name.split("_")[-1] for sample in samples] == ["0", "1"]
    for sample in samples:
        assert sample.name == f"procedural/{sample.category}_{sample.name.split('_')[-1]}"
        extent = sample.vertices.max(axis=0) - sample.vertices.min(axis=0)
        assert (extent.max() == pytest.approx(1.0, abs=1e-9)
                and sample.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-9))
        np.testing.assert_allclose(sample.weights.sum(axis=1), 1.0, atol=1e-9)


def test_an_unknown_prior_is_refused():
    mesh, skeleton = procedural_sample(5).mesh, procedural_sample(5).skeleton
    with pytest.raises(ValueError, match=r"^Unknown prior 'magic'"):
        predict.network_graph(mesh, skeleton, "hollow", prior="magic", resolution=32)
