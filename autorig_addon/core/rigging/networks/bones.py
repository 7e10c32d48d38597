"""The bone network: whether a candidate pair of joints is a bone.

RigNet's BoneNet, with features that generalise from a few dozen
characters (:func:`..tree_features.pair_features`: the pair's offsets, its
place on the body and how the solid looks along the segment between the
joints): a small MLP on those features standardised by the training data's
mean and spread. It gives one logit per pair (the probability is its
sigmoid).
"""

from __future__ import annotations

from ...nn.layers import mlp, standardised
from ...nn.operations import Array, Operations
from ...nn.spec import Dense, NetworkSpec, Standardiser, TrainingSettings
from ..tree_features import PAIR_FEATURES
from .trained import TRAINED_FOLDER

WIDTH = 64


def bone_network(ops: Operations, params: dict, features: Array) -> Array:
    """(p,) bone logits of (p, PAIR_FEATURES) pair features."""
    return mlp(ops, params, standardised(params, features), "mlp.", activation=SPEC.activation,
               activate_last=False)[:, 0]


SPEC = NetworkSpec(
    name="bones",
    label="Bones",
    description="Scores each pair of nearby joints as a bone or not, from how the body looks between them",
    inputs="pair features (p, PAIR_FEATURES)",
    layers=(Standardiser(PAIR_FEATURES), Dense("mlp", (PAIR_FEATURES, WIDTH, WIDTH, 1))),
    forward=bone_network,
    # Full batch: one step per epoch.
    training=TrainingSettings(epochs=1500, learning_rate=3e-3),
    weights_file=TRAINED_FOLDER / "bones.npz",
)
