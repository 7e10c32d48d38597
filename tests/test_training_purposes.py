"""Skin training reads the training characters whose weights are trusted; skeleton training reads them all."""

import pytest

from autorig_addon.core.dataset.split import PURPOSE_SKELETON, PURPOSE_SKIN

pytest.importorskip("torch")
pytestmark = pytest.mark.torch

from autorig_addon.training.rigging import train as rig_train  # noqa: E402
from autorig_addon.training.skinning.learned import train as skin_train  # noqa: E402


class SamplesAsked(Exception):
    """Raised by the stand-in reader once a run has said which samples it wants."""


def recording_reader(asked: list):
    def training_samples(sample_dir=None, split_file=None, purpose=PURPOSE_SKELETON):
        asked.append(purpose)
        raise SamplesAsked

    return training_samples


def test_skin_training_asks_for_samples_usable_for_skin_weights(monkeypatch, tmp_path):
    asked = []
    monkeypatch.setattr(skin_train, "training_samples", recording_reader(asked))
    with pytest.raises(SamplesAsked):
        skin_train.run_training("heterskinnet", sample_dir=tmp_path, device="cpu")
    assert asked == [PURPOSE_SKIN]


def test_skeleton_training_asks_for_every_training_character(monkeypatch, tmp_path):
    asked = []
    monkeypatch.setattr(rig_train, "training_samples", recording_reader(asked))
    with pytest.raises(SamplesAsked):
        rig_train.run_rig_training("joints", sample_dir=tmp_path, examples_dir=tmp_path, device="cpu")
    assert asked == [PURPOSE_SKELETON]
