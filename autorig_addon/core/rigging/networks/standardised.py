"""The small networks that score rows of hand-made features (pairs of
joints, joints): one kind, an MLP on the features standardised by the
training data's mean and spread (:class:`...nn.spec.StandardisedMLP`), one
raw score per row (:func:`...nn.layers.standardised_scores`)."""

from __future__ import annotations

from ...nn.layers import standardised_scores
from ...nn.spec import NetworkSpec, StandardisedMLP, TrainingSettings
from .trained import TRAINED_FOLDER


def standardised_network(name: str, label: str, description: str, inputs: str, features: int, width: int,
                         training: TrainingSettings) -> NetworkSpec:
    """The spec of a network of this kind with two hidden layers of ``width``,
    shipped as ``trained/NAME.npz``; ``features`` columns in."""
    return NetworkSpec(name=name, label=label, description=description, inputs=inputs,
                       layers=(StandardisedMLP(features, (width, width, 1)),), forward=standardised_scores,
                       training=training, weights_file=TRAINED_FOLDER / f"{name}.npz")
