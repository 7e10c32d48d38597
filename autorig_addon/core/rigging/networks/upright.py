"""The upright network: which of four ways a character stands is up.

Given a character whose mirror plane is x = const, one score for each of
the four rotations about x that could bring its up to +z
(:data:`..orientation.UP_CANDIDATES`: as it is, on its back or front,
upside down), from the shape's height profile seen that way
(:func:`..orientation.up_features`: extents, the height of the area's
centre, and per height band the area, the spreads and how much of the
midline is filled), softmaxed over the four in training: a linear score
of the standardised cues. Tried on the validation characters, a linear
score chose as well as MLPs of 8 or 16 hidden units (73 % of the four-way
choices against 72 and 69 %) and, unlike them, was never sure of a wrong
answer (no wrong choice at a probability of 0.95 or more, where the MLPs
made 14 and 12; docs/models.md).
"""

from __future__ import annotations

from ...nn.layers import standardised_scores
from ...nn.spec import NetworkSpec, StandardisedMLP, TrainingSettings
from ..up_features import UP_FEATURE_COUNT
from .trained import TRAINED_FOLDER

SPEC = NetworkSpec(
    name="upright", label="Upright",
    description="Tells which way is up for a character lying, standing or upside down, from its shape",
    inputs="up cues of each candidate (4, UP_FEATURE_COUNT)",
    layers=(StandardisedMLP(UP_FEATURE_COUNT, (1,)),), forward=standardised_scores,
    # Full batch: one step per epoch.
    training=TrainingSettings(epochs=1500, learning_rate=3e-3), weights_file=TRAINED_FOLDER / "upright.npz")
