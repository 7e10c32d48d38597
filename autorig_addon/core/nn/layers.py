"""Dense layers in numpy, in inference form: linear maps, activations,
layer and batch normalisation, and the multi-layer perceptron built of them.

The inference twins of :mod:`autorig_addon.core.nn.training.layers`
(torch). Parameters come from a flat weights dict whose names are the torch
``state_dict`` keys, so :func:`mlp` reads exactly what the torch ``MLP``
module stores: ``PREFIX + "linears.K.weight"`` / ``".bias"`` for layer
``K`` (weight (out, in) as torch keeps it) and ``PREFIX + "norms.K.*"``
for its normalisation.
"""

from __future__ import annotations

from typing import Callable, Optional

import numpy as np

#: Slope of leaky ReLU for negative inputs (torch's default).
LEAKY_RELU_SLOPE = 0.01
#: ELU's saturation value for very negative inputs is -ELU_ALPHA (torch's default).
ELU_ALPHA = 1.0
#: Added to the variance before dividing in layer and batch normalisation
#: (torch's default), so a constant feature does not divide by 0.
NORM_EPSILON = 1e-5
#: Normalisations an MLP layer can use: none, over each row's features
#: (layer norm), or with the training set's running statistics (batch norm).
NORM_KINDS = (None, "layer", "batch")


def linear(x: np.ndarray, weight: np.ndarray, bias: Optional[np.ndarray] = None) -> np.ndarray:
    """``x @ weight.T + bias``: (r, in), (out, in) and (out,) give (r, out)."""
    y = x @ weight.T
    return y if bias is None else y + bias


def relu(x: np.ndarray) -> np.ndarray:
    return np.maximum(x, 0)


def leaky_relu(x: np.ndarray, slope: float = LEAKY_RELU_SLOPE) -> np.ndarray:
    return np.where(x > 0, x, x * np.asarray(slope, dtype=x.dtype))


def elu(x: np.ndarray, alpha: float = ELU_ALPHA) -> np.ndarray:
    return np.where(x > 0, x, np.asarray(alpha, dtype=x.dtype) * np.expm1(np.minimum(x, 0)))


def identity(x: np.ndarray) -> np.ndarray:
    return x


def sigmoid(x: np.ndarray) -> np.ndarray:
    """The logistic function ``1 / (1 + exp(-x))``, written with ``tanh`` so
    that no ``exp`` overflows for large ``|x|``."""
    return 0.5 * (1.0 + np.tanh(0.5 * x))


#: Activations by name, for layers that take theirs as a setting.
ACTIVATIONS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "relu": relu,
    "leaky_relu": leaky_relu,
    "elu": elu,
    "none": identity,
}


def layer_norm(x: np.ndarray, weight: np.ndarray, bias: np.ndarray, epsilon: float = NORM_EPSILON) -> np.ndarray:
    """Each row scaled to zero mean and unit variance over its last axis,
    then ``* weight + bias``; (r, c), (c,), (c,) give (r, c)."""
    mean = x.mean(axis=-1, keepdims=True)
    centred = x - mean
    variance = (centred * centred).mean(axis=-1, keepdims=True)
    return centred / np.sqrt(variance + epsilon) * weight + bias


def batch_norm(x: np.ndarray, running_mean: np.ndarray, running_var: np.ndarray, weight: np.ndarray,
               bias: np.ndarray, epsilon: float = NORM_EPSILON) -> np.ndarray:
    """Batch normalisation with the statistics gathered in training (torch's
    ``eval()`` mode); (r, c) and four (c,) arrays give (r, c)."""
    return (x - running_mean) / np.sqrt(running_var + epsilon) * weight + bias


def mlp(x: np.ndarray, weights: dict, prefix: str, *, activation: str = "relu", norm: Optional[str] = None,
        activate_last: bool = True, first_linear_applied: bool = False) -> np.ndarray:
    """A multi-layer perceptron: each layer is linear -> norm -> activation.

    Parameters
    ----------
    x : (r, in) float array
    weights : dict of str -> array
        Holds ``prefix + "linears.K.weight"`` (and ``.bias``) for ``K = 0,
        1, ...``; the layer count is how many there are. With a norm, layer
        ``K``'s parameters are ``prefix + "norms.K.weight"``, ``.bias`` and
        for batch norm ``.running_mean``, ``.running_var``.
    prefix : str
        Name of the MLP in ``weights`` with its trailing dot (``"conv1.mlp."``).
    activation : str, a key of :data:`ACTIVATIONS`
    norm : None, "layer" or "batch" (:data:`NORM_KINDS`)
    activate_last : bool
        Whether the last layer also gets the norm and activation (False for
        an output layer of raw scores).
    first_linear_applied : bool
        ``x`` already holds layer 0's linear output (EdgeConv computes it
        per node, :mod:`.convolution`); the MLP goes on from layer 0's norm.

    Returns
    -------
    (r, out) float array.
    """
    if norm not in NORM_KINDS:
        raise ValueError(f"Unknown norm {norm!r}; choose from {NORM_KINDS}.")
    activate = ACTIVATIONS[activation]
    layer_count = 0
    while f"{prefix}linears.{layer_count}.weight" in weights:
        layer_count += 1
    if layer_count == 0:
        raise KeyError(f"No MLP named {prefix!r} in the weights (no {prefix}linears.0.weight).")
    for layer in range(layer_count):
        name = f"{prefix}linears.{layer}."
        if layer > 0 or not first_linear_applied:
            x = linear(x, weights[name + "weight"], weights.get(name + "bias"))
        if layer < layer_count - 1 or activate_last:
            norm_name = f"{prefix}norms.{layer}."
            if norm == "layer":
                x = layer_norm(x, weights[norm_name + "weight"], weights[norm_name + "bias"])
            elif norm == "batch":
                x = batch_norm(x, weights[norm_name + "running_mean"], weights[norm_name + "running_var"],
                               weights[norm_name + "weight"], weights[norm_name + "bias"])
            x = activate(x)
    return x
