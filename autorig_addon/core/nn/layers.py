"""Dense layers written once against an operations table (:mod:`.operations`):
the multi-layer perceptron and the standardised input of the small networks.

Parameters come from a flat weights dict whose names are the torch
``state_dict`` keys of the module the training package builds from the
network's spec (:mod:`.spec`): :func:`mlp` reads ``PREFIX + "linears.K.weight"``
/ ``".bias"`` for layer ``K`` (weight (out, in) as torch keeps it).
"""

from __future__ import annotations

from .operations import Array, Operations


def layer_count(params: dict, prefix: str) -> int:
    """How many linear layers the MLP ``prefix`` has in ``params`` (0: none)."""
    count = 0
    while f"{prefix}linears.{count}.weight" in params:
        count += 1
    return count


def mlp(ops: Operations, params: dict, x: Array, prefix: str, *, activation: str, activate_last: bool = True,
        first_linear_applied: bool = False) -> Array:
    """A multi-layer perceptron: each layer is linear -> activation.

    Parameters
    ----------
    ops : Operations
    params : dict of str -> array, holding ``prefix + "linears.K.weight"``
        (and ``.bias``) for ``K = 0, 1, ...``; the layer count is how many there are
    x : (r, in) float array
    prefix : str, the MLP's name with its trailing dot (``"conv1.mlp."``)
    activation : str, a key of ``ops.activations``
    activate_last : bool, whether the last layer is also activated (False
        for an output layer of raw scores)
    first_linear_applied : bool, ``x`` already holds layer 0's linear output
        (EdgeConv computes it per node, :mod:`.convolution`)

    Returns
    -------
    (r, out) float array.
    """
    activate = ops.activations[activation]
    count = layer_count(params, prefix)
    if count == 0:
        raise KeyError(f"No MLP named {prefix!r} in the weights (no {prefix}linears.0.weight).")
    for layer in range(count):
        name = f"{prefix}linears.{layer}."
        if layer > 0 or not first_linear_applied:
            x = ops.linear(x, params[name + "weight"], params.get(name + "bias"))
        if layer < count - 1 or activate_last:
            x = activate(x)
    return x


def standardised(params: dict, features: Array) -> Array:
    """Features standardised by the training data's ``input_mean`` and
    ``input_std`` (the :class:`.spec.Standardiser` of a network)."""
    return (features - params["input_mean"]) / params["input_std"]


def standardised_scores(ops: Operations, params: dict, features: Array, *, activation: str = "leaky_relu") -> Array:
    """(r,) one raw score per row of (r, f) features: the MLP ``"mlp."`` on
    the standardised features (:class:`.spec.StandardisedMLP`)."""
    return mlp(ops, params, standardised(params, features), "mlp.", activation=activation, activate_last=False)[:, 0]
