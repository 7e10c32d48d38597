"""Training the skeleton networks (training/rigging/train.py) through the
shared loop (training/nn/fit.py): tiny runs on procedural characters that
reproduce with their seed, keep their best epoch and write weights the
predictor reads."""

from dataclasses import replace

import numpy as np
import pytest

from autorig_addon.core.nn.spec import shipped_weights
from autorig_addon.core.nn.weights_io import load_weights
from autorig_addon.core.rigging.networks import RIG_NETWORKS
from autorig_addon.core.rigging.networks.landmarks import LANDMARKS, sample_landmarks
from autorig_addon.core.rigging.up_features import UP_FEATURE_COUNT
from autorig_addon.core.skeleton.key_joints import KEY_JOINT_TWINS
from autorig_addon.training.rigging.proportions import proportion_variant, reproportioned, source_character
from autorig_addon.training.rigging.training_set import reference_skeleton, sample_examples
from geometry_fixtures import procedural_sample

torch = pytest.importorskip("torch")
pytestmark = pytest.mark.torch

from autorig_addon.training.rigging.landmarks import (  # noqa: E402
    UNTAUGHT_KIND,
    holdout_scores,
    landmark_data,
    train_landmark_network,
)
from autorig_addon.training.rigging.train import (  # noqa: E402
    JITTER_COPIES,
    connectivity_data,
    holdout_j2j,
    train_connectivity_network,
    train_full_batch,
    train_joint_network,
)
from autorig_addon.training.rigging.upright import copies_per_character, upright_data  # noqa: E402
from autorig_addon.training.runs import start_run, write_weights  # noqa: E402


@pytest.fixture(scope="module")
def examples():
    """``(train, holdout)``: one stretched variant of two procedural
    characters to train on, the third character as it is to hold out."""
    train = []
    for seed in (5, 8):
        train += sample_examples(procedural_sample(seed), np.random.default_rng(seed), variants=1)
    return train, sample_examples(procedural_sample(4), np.random.default_rng(4), variants=0)


def run(name, examples, seed, epochs):
    record = start_run(RIG_NETWORKS[name], seed=seed, device="cpu", epochs=epochs, learning_rate=None,
                       score_name="cd_j2j" if name == "joints" else "cross_entropy")
    train, holdout = examples
    if name == "joints":
        weights = train_joint_network(train, holdout, record)
    else:
        weights = train_connectivity_network(RIG_NETWORKS[name], train, holdout, record)
    return weights, record


def test_a_joint_network_run_reproduces_and_keeps_its_best_epoch(examples):
    first, record = run("joints", examples, seed=2, epochs=2)
    second, _ = run("joints", examples, seed=2, epochs=2)
    assert all(np.array_equal(first[name], second[name]) for name in first)
    assert [entry["epoch"] for entry in record.history] == [0, 1, 2]
    scores = [entry["cd_j2j"] for entry in record.history]
    assert record.best_score == min(scores) and record.best_epoch == scores.index(min(scores))
    # The kept weights are scored the same by the numpy forward and the mean shift.
    assert holdout_j2j(first, examples[1]) == pytest.approx(record.best_score, abs=1e-12)
    assert record.parameters == sum(value.size for value in first.values())
    RIG_NETWORKS["joints"].check_weights(first, "the run")


@pytest.mark.parametrize("name", ["bones", "root"])
def test_a_full_batch_run_learns_and_reports_its_held_out_accuracy(name, examples):
    weights, record = run(name, examples, seed=1, epochs=30)
    again, _ = run(name, examples, seed=1, epochs=30)
    assert all(np.array_equal(weights[key], again[key]) for key in weights)
    held_out = [entry["cross_entropy"] for entry in record.history]
    # Logged at the start and at the last epoch (every 100 epochs otherwise).
    assert [entry["epoch"] for entry in record.history] == [0, 30]
    assert record.history[0]["loss"] is None and record.history[-1]["loss"] > 0  # the training loss
    assert record.best_score == min(held_out) and held_out[-1] < held_out[0]
    assert 0.0 <= record.details["holdout_accuracy"] <= 1.0
    # The standardisation is the training features': each feature's mean over every jittered copy.
    data = connectivity_data(examples[0], np.random.default_rng(1))
    features = data["pair_features"] if name == "bones" else np.concatenate([f for f, _ in data["roots"]])
    np.testing.assert_allclose(weights["input_mean"], features.mean(axis=0), rtol=1e-5, atol=1e-6)
    assert len(data["roots"]) == JITTER_COPIES * len(examples[0])


def test_written_weights_are_what_the_predictor_reads(examples, tmp_path):
    weights, record = run("root", examples, seed=0, epochs=3)
    path = write_weights(RIG_NETWORKS["root"], weights, record, tmp_path / "root.npz")
    loaded = load_weights(str(path))
    # Saved at half precision: each weight matrix rounded to float16 and read back as float32; the rest (vectors
    # such as biases and feature means, integers) as they were.
    assert loaded.weights.keys() == weights.keys()
    for name, value in weights.items():
        value = np.asarray(value)
        halved = value.dtype.kind == "f" and value.ndim >= 2
        expected = value.astype(np.float16).astype(np.float32) if halved else value
        assert np.array_equal(loaded.weights[name], expected), name
    assert loaded.metadata["network"] == "root" and loaded.metadata["epochs"] == 3
    assert loaded.metadata["holdout_accuracy"] == record.details["holdout_accuracy"]
    assert "torch_version" in loaded.metadata
    # The shipped weights are untouched by a run written elsewhere.
    assert not np.array_equal(shipped_weights(RIG_NETWORKS["root"]).weights["mlp.linears.0.weight"],
                              weights["mlp.linears.0.weight"])


def test_a_landmark_network_run_reproduces_and_scores_its_kept_epoch(examples):
    samples = {f"procedural_{seed}": procedural_sample(seed) for seed in (4, 5, 8)}
    train, holdout = examples

    def landmark_run():
        record = start_run(RIG_NETWORKS["landmarks"], seed=3, device="cpu", epochs=2, learning_rate=None,
                           score_name="landmark_error")
        return train_landmark_network(samples, train, holdout, record), record

    first, record = landmark_run()
    second, _ = landmark_run()
    assert all(np.array_equal(first[name], second[name]) for name in first)
    errors = [entry["landmark_error"] for entry in record.history]
    assert record.best_score == min(errors) and len(errors) == 3
    again = holdout_scores(RIG_NETWORKS["landmarks"], first, landmark_data(samples, holdout))
    assert again["landmark_error"] == pytest.approx(record.best_score, abs=1e-12)
    RIG_NETWORKS["landmarks"].check_weights(first, "the run")


def test_landmark_targets_follow_a_stretched_variant_and_mirroring_swaps_sides():
    sample = procedural_sample(5)
    original, variant = sample_examples(sample, np.random.default_rng(0), variants=1)
    targets, known, kind = sample_landmarks(sample)
    (_, same, _, _), (_, moved, _, _) = landmark_data({sample.name: sample}, [original, variant])
    np.testing.assert_allclose(same[known > 0], targets[known > 0], atol=1e-5)
    # The variant's joints are the character's stretched per axis: so are its landmarks, to float precision.
    source = reference_skeleton(sample).joints
    scale = np.ptp(variant.joints, axis=0) / np.ptp(source, axis=0)
    shift = variant.joints.min(axis=0) - scale * source.min(axis=0)
    np.testing.assert_allclose(moved[known > 0], (scale * targets + shift)[known > 0], atol=1e-5)
    # Mirroring swaps each left landmark with its right twin and keeps the midline ones.
    assert [LANDMARKS[index] for index in KEY_JOINT_TWINS[:4]] == ["hips", "neck", "head", "shoulder.R"]
    assert sorted(KEY_JOINT_TWINS) == list(range(len(LANDMARKS)))


def test_the_upright_network_learns_which_way_is_up_and_its_run_reproduces():
    # Three procedural characters stand upright in their samples; copies tilted up to 10 degrees, each with its
    # four ways to stand (as it is, on its back, upside down, on its front): the first is right.
    samples = [procedural_sample(seed) for seed in (4, 5, 8)]
    copies = [8, 8, 8]

    def train(seed):
        record = start_run(RIG_NETWORKS["upright"], seed=seed, device="cpu", epochs=300, learning_rate=None,
                           score_name="cross_entropy")
        rng = np.random.default_rng(seed)
        data = upright_data(samples, copies, rng)
        return train_full_batch(RIG_NETWORKS["upright"], data, upright_data(samples, [4, 4, 4], rng), record), \
            record, data

    first, record, data = train(6)
    second, _, _ = train(6)
    assert all(np.array_equal(first[name], second[name]) for name in first)
    assert data["root_features"].shape == (4 * 24, UP_FEATURE_COUNT)
    np.testing.assert_array_equal(data["root_rows"], 4 * np.arange(24))
    # Untrained (measured 1.64), no better than guessing among four (log 4 = 1.39); trained (0.30), the upright
    # way is picked on most of 12 copies tilted otherwise (measured 10).
    assert record.history[0]["cross_entropy"] > np.log(4.0)
    assert record.best_score < 0.5
    assert record.details["holdout_accuracy"] >= 0.75
    RIG_NETWORKS["upright"].check_weights(first, "the run")


def test_copies_are_shared_out_so_each_family_weighs_alike():
    families = {"a1": 0, "a2": 0, "a3": 0, "a4": 0, "b": 1, "c1": 2, "c2": 2}
    assert copies_per_character(sorted(families), families) == [4, 4, 4, 4, 16, 8, 8]


def test_a_proportion_variant_moves_every_joint_with_the_mesh_and_counts_as_its_character():
    sample = procedural_sample(5)
    variant = proportion_variant(sample, 1, seed=0)
    assert variant.name == "procedural_5~proportions1"
    assert source_character(variant.name + "#0") == source_character("procedural_5#3") == "procedural_5"
    # Normalised again: feet on the ground, largest side 1.
    assert variant.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-12)
    assert np.ptp(variant.vertices, axis=0).max() == pytest.approx(1.0, abs=1e-12)
    # The same map on any point: a joint exactly at a vertex stays exactly at that vertex.
    glued = replace(sample, joints=sample.vertices[[10, 200, 500]], tails=sample.vertices[[11, 201, 501]],
                    parents=np.array([-1, 0, 1]), names=("a", "b", "c"), deform=np.ones(3, dtype=bool),
                    weights=np.zeros((len(sample.vertices), 3)))
    moved = proportion_variant(glued, 1, seed=0)
    np.testing.assert_allclose(moved.joints, moved.vertices[[10, 200, 500]], atol=1e-12)
    np.testing.assert_allclose(moved.tails, moved.vertices[[11, 201, 501]], atol=1e-12)
    # Heights keep their order (the map increases) but the bands' shares change: proportions, not a scale.
    order = np.argsort(sample.vertices[:, 2], kind="stable")
    assert np.all(np.diff(variant.vertices[order, 2]) >= -1e-12)
    ratio = variant.vertices[:, 2] / np.where(sample.vertices[:, 2] > 0, sample.vertices[:, 2], np.nan)
    assert np.nanmax(ratio) / np.nanmin(ratio) > 1.2
    # Reproducible from the seed, and another number is another map.
    np.testing.assert_array_equal(proportion_variant(sample, 1, seed=0).vertices, variant.vertices)
    assert not np.allclose(proportion_variant(sample, 2, seed=0).vertices, variant.vertices)


def test_a_band_map_has_the_heights_and_widths_it_was_drawn_with():
    heights, widths = np.array([0.0, 0.1, 0.3, 0.6, 0.7]), np.array([1.0, 1.0, 2.0, 1.0, 1.0])
    points = np.array([[0.1, 0.2, 0.0], [0.1, 0.2, 0.25], [0.1, 0.2, 0.5], [0.1, 0.2, 0.625], [0.1, 0.2, 1.0]])
    moved = reproportioned(points, 1.0, heights, widths)
    # Band edges go to the drawn heights; half way up the third band is half way between its new edges.
    np.testing.assert_allclose(moved[:, 2], [0.0, 0.1, 0.3, 0.45, 0.7])
    # Width factor 2 at half height, 1.5 half way to the next edge, about the vertical axis.
    np.testing.assert_allclose(moved[:, :2], [[0.1, 0.2], [0.1, 0.2], [0.2, 0.4], [0.15, 0.3], [0.1, 0.2]])


def test_a_proportion_variant_teaches_its_moved_landmarks_and_no_kind():
    sample = procedural_sample(23)  # a biped: all 15 key joints named
    variant = proportion_variant(sample, 2, seed=0)
    (example,) = sample_examples(variant, np.random.default_rng(0), variants=0)
    ((_, targets, known, kind),) = landmark_data({variant.name: variant}, [example])
    assert kind == UNTAUGHT_KIND
    expected, expected_known, own_kind = sample_landmarks(variant)
    np.testing.assert_array_equal(known, expected_known)
    assert known.sum() == 15
    np.testing.assert_allclose(targets[known > 0], expected[known > 0], atol=1e-5)
    # Reshaped: the variant's landmarks are not the character's.
    assert np.abs(targets - sample_landmarks(sample)[0]).max() > 0.01
    # The character itself still teaches its kind.
    ((_, _, _, kind),) = landmark_data({sample.name: sample}, sample_examples(sample, np.random.default_rng(0), 0))
    assert kind == own_kind != UNTAUGHT_KIND
