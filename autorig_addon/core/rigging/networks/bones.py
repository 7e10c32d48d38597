"""The bone network: whether a candidate pair of joints is a bone.

RigNet's BoneNet, with features that generalise from a few dozen
characters (:func:`..tree_features.pair_features`: the pair's offsets, its
place on the body and how the solid looks along the segment between the
joints): one logit per pair (the probability is its sigmoid) from a
standardised MLP (:mod:`.standardised`).
"""

from __future__ import annotations

from ...nn.spec import TrainingSettings
from ..tree_features import PAIR_FEATURES
from .standardised import standardised_network

SPEC = standardised_network(
    "bones", "Bones", "Scores each pair of nearby joints as a bone or not, from how the body looks between them",
    "pair features (p, PAIR_FEATURES)", PAIR_FEATURES, width=64,
    # Full batch: one step per epoch. On the 31-character set the kept epoch was 397 of 1,500; the
    # 419-character set's batch is five times larger, so 500 epochs keep the run short.
    training=TrainingSettings(epochs=500, learning_rate=3e-3))
