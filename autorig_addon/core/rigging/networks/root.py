"""The root network: which joint is the skeleton's root.

RigNet's RootNet with our joint features (:func:`..tree_features.root_features`:
place, depth inside the body, how central and crowded the joint is): one
score per joint (softmaxed over the joints in training) from a standardised
MLP (:mod:`.standardised`).
"""

from __future__ import annotations

from ...nn.spec import TrainingSettings
from ..tree_features import ROOT_FEATURES
from .standardised import standardised_network

SPEC = standardised_network(
    "root", "Root", "Picks the skeleton's root among the joints, from where each lies in the body",
    "joint features (j, ROOT_FEATURES)", ROOT_FEATURES, width=32,
    # Full batch: one step per epoch.
    training=TrainingSettings(epochs=600, learning_rate=3e-3))
