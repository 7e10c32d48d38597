"""Argument types and options shared by the subcommands.

Each type checks a value against the bounds the core declares (the same
ones the Blender panel offers); a value out of bounds is a usage error
whose message names the bounds (argparse prints it and exits 2).
"""

from __future__ import annotations

import argparse
from typing import Callable

from ..core.geometry.smoothing import DEFAULT_SMOOTHING_STRENGTH, MAX_SMOOTHING_ITERATIONS
from ..core.weights import MAX_INFLUENCES


def _number(convert: Callable, text: str):
    try:
        return convert(text)
    except ValueError:
        kind = "an integer" if convert is int else "a number"
        raise argparse.ArgumentTypeError(f"{text} is not {kind}") from None


def bounded(convert: Callable, low, high) -> Callable[[str], float]:
    """A ``type=`` for argparse: ``convert(text)`` (``int`` or ``float``) in ``[low, high]``."""

    def parse(text: str):
        value = _number(convert, text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text} is not between {low:g} and {high:g}")
        return value

    return parse


def positive(text: str) -> float:
    """A float greater than zero."""
    value = _number(float, text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} is not positive")
    return value


#: A share in [0, 1] (blend factors, mix factors).
fraction = bounded(float, 0.0, 1.0)


def add_weight_arguments(parser: argparse.ArgumentParser, max_influences: int, smoothing_iterations: int,
                         smoothing_help: str, max_influences_hint: str = "",
                         smoothing_strength_help: str = "Blend factor of one smoothing pass") -> None:
    """``--max-influences``, ``--smoothing-iterations`` and ``--smoothing-strength``
    with the given defaults, bounded as in the panel."""
    parser.add_argument("--max-influences", type=bounded(int, 0, MAX_INFLUENCES), default=max_influences,
                        help=f"Bones per vertex to keep, 0 to {MAX_INFLUENCES}, 0 = no limit "
                             f"(default {max_influences}{max_influences_hint})")
    parser.add_argument("--smoothing-iterations", type=bounded(int, 0, MAX_SMOOTHING_ITERATIONS),
                        default=smoothing_iterations,
                        help=f"{smoothing_help}, 0 to {MAX_SMOOTHING_ITERATIONS} (default {smoothing_iterations})")
    parser.add_argument("--smoothing-strength", type=fraction, default=DEFAULT_SMOOTHING_STRENGTH,
                        help=f"{smoothing_strength_help}, 0 to 1 (default {DEFAULT_SMOOTHING_STRENGTH:g})")
