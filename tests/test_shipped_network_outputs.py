"""The shipped networks give what they gave when their outputs were
recorded (``network_outputs.py``, ``data/network_outputs.npz``): a change of
the code that runs them (a refactoring, a faster kernel) must leave every
network's output, the skin weights and the predicted skeleton as they were.
A retraining records them again on purpose."""

import numpy as np
import pytest

from network_outputs import NETWORK_OUTPUTS_FILE, rig_outputs, skeleton_outputs, skin_outputs

#: float32 outputs of the same weights on the same inputs: round-off only.
OUTPUT_TOLERANCE = 1e-5
#: Joint and tail positions of the predicted skeleton (metres on a ~2 m
#: biped): the mean shift moves a mode by about its votes' round-off.
POSITION_TOLERANCE = 1e-4


@pytest.fixture(scope="module")
def recorded():
    with np.load(NETWORK_OUTPUTS_FILE) as data:
        return {name: data[name] for name in data.files}


def assert_same_arrays(now: dict, recorded: dict, tolerance: float) -> None:
    for name, value in now.items():
        assert value.shape == recorded[name].shape, name
        np.testing.assert_allclose(value, recorded[name], atol=tolerance, rtol=0, err_msg=name)


def test_every_skin_network_gives_its_recorded_candidates_and_weights(recorded):
    now = skin_outputs()
    assert sorted(now) == sorted(name for name in recorded if name.startswith("skin."))
    assert_same_arrays(now, recorded, OUTPUT_TOLERANCE)


def test_the_skeleton_networks_give_their_recorded_outputs(recorded):
    now = rig_outputs()
    assert sorted(now) == ["bones.probabilities", "joints.attention", "joints.offsets", "landmarks.kind_logits",
                           "landmarks.points", "landmarks_long.points", "root.scores", "upright.probabilities"]
    assert_same_arrays(now, recorded, OUTPUT_TOLERANCE)


def test_the_predicted_skeleton_is_the_recorded_one(recorded):
    now = skeleton_outputs()
    assert list(now["skeleton.names"]) == list(recorded["skeleton.names"])
    np.testing.assert_array_equal(now["skeleton.parents"], recorded["skeleton.parents"])
    for name in ("skeleton.joints", "skeleton.tails"):
        np.testing.assert_allclose(now[name], recorded[name], atol=POSITION_TOLERANCE, rtol=0, err_msg=name)
