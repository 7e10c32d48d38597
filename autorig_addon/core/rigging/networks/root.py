"""The root network: which joint is the skeleton's root.

RigNet's RootNet with our joint features (:func:`..tree_features.root_features`:
place, depth inside the body, how central and crowded the joint is): a
small MLP on those features standardised by the training data's mean and
spread, one score per joint (softmaxed over the joints in training).
"""

from __future__ import annotations

from ...nn.layers import mlp, standardised
from ...nn.operations import Array, Operations
from ...nn.spec import Dense, NetworkSpec, Standardiser, TrainingSettings
from ..tree_features import ROOT_FEATURES
from .trained import TRAINED_FOLDER

WIDTH = 32


def root_network(ops: Operations, params: dict, features: Array) -> Array:
    """(j,) root scores of (j, ROOT_FEATURES) joint features (higher: more likely the root)."""
    return mlp(ops, params, standardised(params, features), "mlp.", activation=SPEC.activation,
               activate_last=False)[:, 0]


SPEC = NetworkSpec(
    name="root",
    label="Root",
    description="Picks the skeleton's root among the joints, from where each lies in the body",
    inputs="joint features (j, ROOT_FEATURES)",
    layers=(Standardiser(ROOT_FEATURES), Dense("mlp", (ROOT_FEATURES, WIDTH, WIDTH, 1))),
    forward=root_network,
    # Full batch: one step per epoch.
    training=TrainingSettings(epochs=600, learning_rate=3e-3),
    weights_file=TRAINED_FOLDER / "root.npz",
)
