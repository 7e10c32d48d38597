"""What defines a network, once: its :class:`NetworkSpec`.

A spec says what the network is called and does (name, label, one-line
description, what it reads), how its parameters are laid out
(:attr:`NetworkSpec.layers`, in the order training creates them), the one
forward function written against an operations table (:mod:`.operations`),
how it is trained (:class:`TrainingSettings`) and where its shipped weights
lie. Inside Blender the forward runs on numpy with the shipped weights
(:func:`shipped_weights`); the training package builds a torch module from
the same layers and trains the same forward. Adding a network is one module
holding its forward and its spec, and one line in its task's registry
(``core/skinning/learned/networks/__init__.py``,
``core/rigging/networks/__init__.py``).

Parameter names are torch ``state_dict`` keys: a :class:`Dense` layer
``"encoder"`` owns ``encoder.linears.K.weight`` (out, in) and ``.bias``
(out,); the composite layers name their parts below it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Callable, Union

import numpy as np

from ..errors import InputError
from .convolution import MULTI_AGGREGATIONS
from .weights_io import LoadedWeights, load_weights


@dataclass(frozen=True)
class Dense:
    """A multi-layer perceptron ``prefix`` of widths ``[in, hidden..., out]``.

    ``zero_last``: its last layer starts at zero, so a residual head gives
    exactly its prior before training (the skinning networks' scores).
    """

    prefix: str
    widths: tuple
    zero_last: bool = False

    def parts(self) -> tuple:
        return (self,)


@dataclass(frozen=True)
class GMEdge:
    """RigNet's GMEdgeConv block on ``width`` features
    (:func:`.convolution.gmedge_block`): EdgeConvs ``prefix.one_ring`` and
    ``prefix.ball`` and the fusing layer ``prefix.fuse``."""

    prefix: str
    width: int

    def parts(self) -> tuple:
        double = (2 * self.width, self.width)
        return (Dense(f"{self.prefix}.one_ring.mlp", double), Dense(f"{self.prefix}.ball.mlp", double),
                Dense(f"{self.prefix}.fuse", double))


@dataclass(frozen=True)
class GMEdgeTrunk:
    """RigNet's trunk (:func:`.convolution.gmedge_trunk`): the encoder
    ``encoder`` from ``in_width`` through ``2 * width`` to ``width``
    features, GMEdgeConv ``blocks`` of ``width``, and the shape code
    ``shape`` of ``shape_width``; :attr:`out_width` features per node."""

    in_width: int
    width: int
    blocks: tuple
    shape_width: int

    @property
    def out_width(self) -> int:
        return (len(self.blocks) + 1) * self.width + self.shape_width

    def parts(self) -> tuple:
        return (Dense("encoder", (self.in_width, 2 * self.width, self.width)),
                *(part for block in self.blocks for part in GMEdge(block, self.width).parts()),
                Dense("shape", (self.width, self.shape_width)))


@dataclass(frozen=True)
class MultiAggregator:
    """SkinningNet's convolution (:func:`.convolution.multi_aggregator_convolution`)
    from ``in_width`` features through message widths ``widths``: the
    message MLP ``prefix.mlp`` and the summary ``prefix.summary``."""

    prefix: str
    in_width: int
    widths: tuple
    aggregations: tuple = MULTI_AGGREGATIONS

    def parts(self) -> tuple:
        out = self.widths[-1]
        return (Dense(f"{self.prefix}.mlp", (2 * self.in_width, *self.widths)),
                Dense(f"{self.prefix}.summary", (len(self.aggregations) * out, out)))


@dataclass(frozen=True)
class Scalar:
    """One learned number ``name`` starting at ``value`` (the skinning
    networks' prior scale)."""

    name: str
    value: float

    def parts(self) -> tuple:
        return (self,)


@dataclass(frozen=True)
class StandardisedMLP:
    """An MLP ``mlp`` of widths ``[features, hidden..., 1]`` on features
    standardised by a :class:`Standardiser` (:func:`.layers.standardised_scores`)."""

    features: int
    widths: tuple

    def parts(self) -> tuple:
        return (Standardiser(self.features), Dense("mlp", (self.features, *self.widths)))


@dataclass(frozen=True)
class Standardiser:
    """The training data's per-feature mean and spread (``input_mean``,
    ``input_std``, fixed buffers rather than learned) that a small network
    standardises its ``features`` inputs by (:func:`.layers.standardised`)."""

    features: int

    def parts(self) -> tuple:
        return (self,)


Layer = Union[Dense, GMEdge, GMEdgeTrunk, MultiAggregator, Scalar, StandardisedMLP, Standardiser]


@dataclass(frozen=True)
class TrainingSettings:
    """How a network's shipped weights were trained, and so what its
    training command does unless told otherwise: ``epochs`` and Adam's
    starting ``learning_rate`` (a cosine schedule takes it to 0)."""

    epochs: int
    learning_rate: float


@dataclass(frozen=True, kw_only=True)
class NetworkSpec:
    """One network (see the module docstring).

    Attributes
    ----------
    name : str, the name commands, files and the panel use (``"heterskinnet"``)
    label : str, the short name the panel shows (``"HeterSkinNet"``)
    description : str, one line: tooltips, ``--help`` and ``eval``'s method list
    inputs : str, what the forward reads (a class of the task's features)
    layers : tuple of :data:`Layer`, the parameters in the order training
        creates them (so a seeded run starts from the same numbers)
    forward : callable ``forward(ops, params, inputs)``, the network once
        for numpy and torch; its outputs are the task's (logits, scores)
    training : TrainingSettings
    weights_file : Path, the shipped weights inside the package
    activation : str, every hidden layer's activation
    """

    name: str
    label: str
    description: str
    inputs: str
    layers: tuple
    forward: Callable
    training: TrainingSettings
    weights_file: Path
    activation: str = "leaky_relu"

    def parts(self) -> tuple:
        """The layers with the composite ones split into their MLPs."""
        return tuple(part for layer in self.layers for part in layer.parts())

    def parameter_shapes(self) -> dict:
        """``{state_dict name: shape}`` of every parameter and buffer."""
        shapes = {}
        for part in self.parts():
            if isinstance(part, Dense):
                for index, (width_in, width_out) in enumerate(zip(part.widths[:-1], part.widths[1:])):
                    shapes[f"{part.prefix}.linears.{index}.weight"] = (width_out, width_in)
                    shapes[f"{part.prefix}.linears.{index}.bias"] = (width_out,)
            elif isinstance(part, Scalar):
                shapes[part.name] = ()
            else:
                shapes["input_mean"] = shapes["input_std"] = (part.features,)
        return shapes

    def check_weights(self, weights: dict, source: str) -> None:
        """Raise :class:`InputError` unless ``weights`` has exactly this
        network's names and shapes (a file of another network, or of an
        older layout, is refused by name rather than failing mid-run)."""
        expected = self.parameter_shapes()
        found = {name: tuple(np.shape(value)) for name, value in weights.items()}
        if found != expected:
            missing = sorted(set(expected) - set(found))
            extra = sorted(set(found) - set(expected))
            reshaped = sorted(name for name in set(found) & set(expected) if found[name] != expected[name])
            details = "; ".join(f"{what}: {', '.join(names[:4])}{' ...' if len(names) > 4 else ''}"
                                for what, names in (("missing", missing), ("unexpected", extra),
                                                    ("other shape", reshaped)) if names)
            raise InputError(f"{source} does not hold the {self.name} network's weights ({details}).")


@lru_cache(maxsize=None)
def _loaded(path: str, spec: NetworkSpec) -> LoadedWeights:
    loaded = load_weights(path)
    spec.check_weights(loaded.weights, path)
    return loaded


def shipped_weights(spec: NetworkSpec) -> LoadedWeights:
    """The shipped ``(weights, metadata)`` of ``spec``, read and checked once per process.

    Raises
    ------
    InputError for a missing file (a broken install) or one that does not
    hold this network's parameters.
    """
    if not spec.weights_file.is_file():
        raise InputError(f"The trained weights of '{spec.name}' are missing ({spec.weights_file}); "
                         "reinstall the extension.")
    return _loaded(str(spec.weights_file), spec)


def forget_shipped_weights() -> None:
    """Read the shipped weights from disk again next time (after a training
    run wrote them, or a test replaced one)."""
    _loaded.cache_clear()
