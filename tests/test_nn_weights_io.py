"""Network weight files (core/nn/weights_io.py): round trip, format version,
and clear messages for files that are not weights."""

import os

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.nn.weights_io import (
    FORMAT_VERSION_KEY,
    METADATA_KEY,
    WEIGHTS_FORMAT_VERSION,
    load_weights,
    save_weights,
)


def test_weights_and_metadata_round_trip(tmp_path):
    weights = {
        "conv1.mlp.linears.0.weight": np.arange(6, dtype=np.float32).reshape(2, 3),
        "conv1.mlp.linears.0.bias": np.array([0.5, -1.5], dtype=np.float32),
        "norms.0.num_batches_tracked": np.asarray(12, dtype=np.int64),
    }
    path = str(tmp_path / "rignet.npz")
    save_weights(path, weights, {"model": "rignet", "k": 5})
    loaded = load_weights(path)
    assert loaded.metadata == {"model": "rignet", "k": 5}
    assert sorted(loaded.weights) == sorted(weights)
    for name, array in weights.items():
        assert loaded.weights[name].dtype == array.dtype
        assert np.array_equal(loaded.weights[name], array)
    # Only the file itself is left in the folder (no temporary file).
    assert os.listdir(tmp_path) == ["rignet.npz"]
    assert load_weights(path).weights.keys() == weights.keys()
    save_weights(path, {}, None)  # overwriting works; no metadata reads back as {}
    assert load_weights(path) == ({}, {})


def test_weights_saved_at_half_precision_load_as_float32_rounded_to_it(tmp_path):
    rng = np.random.default_rng(0)
    weights = {
        "mlp.linears.0.weight": rng.normal(size=(64, 32)).astype(np.float32),
        "wide.weight": np.array([[2.5e6, 1.0]], dtype=np.float32),  # beyond float16's 65504: kept whole
        # A vector stays whole: a running mean of 1000.3 would round to 1000.5 at half precision.
        "norm.running_mean": np.array([1000.3, -2.7e-3], dtype=np.float32),
        "norm.num_batches_tracked": np.asarray(12, dtype=np.int64),
    }
    full, half = str(tmp_path / "full.npz"), str(tmp_path / "half.npz")
    save_weights(full, weights)
    save_weights(half, weights, {"model": "tiny"}, half_precision=True)
    loaded = load_weights(half)
    assert loaded.metadata == {"model": "tiny"}
    assert {name: array.dtype for name, array in loaded.weights.items()} == {
        "mlp.linears.0.weight": np.float32, "wide.weight": np.float32, "norm.running_mean": np.float32,
        "norm.num_batches_tracked": np.int64}
    matrix = weights["mlp.linears.0.weight"]
    assert np.array_equal(loaded.weights["mlp.linears.0.weight"], matrix.astype(np.float16).astype(np.float32))
    assert 0 < np.abs(loaded.weights["mlp.linears.0.weight"] - matrix).max() <= 2.0 ** -11 * np.abs(matrix).max()
    assert np.array_equal(loaded.weights["wide.weight"], weights["wide.weight"])
    assert np.array_equal(loaded.weights["norm.running_mean"], weights["norm.running_mean"])
    assert loaded.weights["norm.num_batches_tracked"] == 12
    # 2,048 numbers at two bytes instead of four: the file is about half as large.
    assert os.path.getsize(half) < 0.6 * os.path.getsize(full)


def test_bad_names_and_values_are_refused_before_writing(tmp_path):
    path = str(tmp_path / "model.npz")
    with pytest.raises(ValueError, match="Invalid weight name '__format_version__'"):
        save_weights(path, {FORMAT_VERSION_KEY: np.zeros(1)})
    with pytest.raises(ValueError, match="dtype object"):
        save_weights(path, {"a": np.array([None])})
    with pytest.raises(TypeError):
        save_weights(path, {"a": np.zeros(1)}, {"not json": object()})
    assert os.listdir(tmp_path) == []


def test_files_that_are_not_weights_get_a_clear_message(tmp_path):
    missing = str(tmp_path / "missing.npz")
    with pytest.raises(InputError, match=r"^Network weights file .*missing\.npz does not exist\.$"):
        load_weights(missing)
    text = tmp_path / "notes.npz"
    text.write_text("not a zip")
    with pytest.raises(InputError, match=r"notes\.npz is not a network weights file"):
        load_weights(str(text))
    plain_array = tmp_path / "array.npy"
    np.save(plain_array, np.zeros(3))
    with pytest.raises(InputError, match=r"array\.npy is not a network weights file \(a single array"):
        load_weights(str(plain_array))
    other_npz = tmp_path / "sample.npz"
    np.savez(other_npz, vertices=np.zeros((3, 3)))
    with pytest.raises(InputError, match=r"sample\.npz is not a network weights file \(no format version"):
        load_weights(str(other_npz))


def test_a_newer_format_is_refused(tmp_path):
    path = tmp_path / "future.npz"
    np.savez(path, **{FORMAT_VERSION_KEY: np.asarray(WEIGHTS_FORMAT_VERSION + 1), METADATA_KEY: np.asarray("{}"),
                      "a": np.zeros(2)})
    with pytest.raises(InputError, match=f"holds weights in format {WEIGHTS_FORMAT_VERSION + 1}, but this add-on "
                                         f"reads format {WEIGHTS_FORMAT_VERSION}"):
        load_weights(str(path))


def test_a_saved_file_gets_the_usual_permissions(tmp_path):
    previous = os.umask(0o022)
    try:
        save_weights(str(tmp_path / "net.npz"), {"a": np.zeros(2)})
    finally:
        os.umask(previous)
    assert (tmp_path / "net.npz").stat().st_mode & 0o777 == 0o644
    assert [path.name for path in tmp_path.iterdir()] == ["net.npz"]


def test_corrupted_metadata_is_an_input_error(tmp_path):
    path = tmp_path / "broken.npz"
    np.savez(path, **{FORMAT_VERSION_KEY: np.asarray(WEIGHTS_FORMAT_VERSION), METADATA_KEY: np.asarray("{not json"),
                      "a": np.zeros(2)})
    with pytest.raises(InputError,
                       match=r"broken\.npz is not a network weights file \(unreadable version or metadata: "):
        load_weights(str(path))
