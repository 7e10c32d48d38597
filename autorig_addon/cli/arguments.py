"""Command-line options made from the core's option tables (``core.options``).

Each option gets the flag, default, bounds and help its table declares (the
same the Blender panel offers, see ``blender.ui.option_properties``); a
value out of bounds is a usage error whose message names the bounds
(argparse prints it and exits 2).
"""

from __future__ import annotations

import argparse
import dataclasses
from typing import Callable

from ..core.options import DEGREES, Option

#: What :func:`add_option` takes as "the table's default".
_TABLE_DEFAULT = object()


def _number(convert: Callable, text: str):
    try:
        return convert(text)
    except ValueError:
        kind = "an integer" if convert is int else "a number"
        raise argparse.ArgumentTypeError(f"{text} is not {kind}") from None


def _bounds_words(low, high, low_is_open: bool) -> str:
    """The allowed range in words: "between 0 and 1", "positive", ..."""
    if low is not None and high is not None:
        return f"{'above' if low_is_open else 'between'} {low:g} and {'at most ' if low_is_open else ''}{high:g}"
    if low is not None:
        return "positive" if low_is_open and low == 0 else f"{'above' if low_is_open else 'at least'} {low:g}"
    return f"at most {high:g}"


def bounded(convert: Callable, low=None, high=None, low_is_open: bool = False) -> Callable[[str], float]:
    """A ``type=`` for argparse: ``convert(text)`` (``int`` or ``float``) within
    ``[low, high]`` (``low`` itself refused when ``low_is_open``; None: no
    bound on that side). NaN is refused."""

    def parse(text: str):
        value = _number(convert, text)
        above_low = low is None or (value > low if low_is_open else value >= low)
        if not (above_low and (high is None or value <= high)):
            raise argparse.ArgumentTypeError(f"{text} is not {_bounds_words(low, high, low_is_open)}")
        return value

    return parse


def _with_aside(text: str, aside: str) -> str:
    """``text`` with ``aside`` in parentheses, inside those it ends with if any."""
    if not aside:
        return text
    return f"{text[:-1]}; {aside})" if text.endswith(")") else f"{text} ({aside})"


def option_help(option: Option, note: str = "") -> str:
    """The ``--help`` text of ``option``: its help, its unit where the panel
    shows it otherwise, its bounds and, in parentheses, ``note`` or its default."""
    if option.choices:
        default = note or f"default {option.word_of_choice(option.default)}"
        meanings = "; ".join(f"{choice.command_word}: {choice.help}" for choice in option.choices)
        return f"{_with_aside(option.help, default)}. {meanings}."
    text = option.help + (", in degrees" if option.unit == DEGREES else "")
    if option.kind is bool:
        default = f"default {'on' if option.default else 'off'}"
    elif option.kind is str:
        default = f"default '{option.default}'" if option.default else ""
    else:
        if option.low is not None and option.high is not None:
            text += f", {option.low:g} to {option.high:g}"
        default = f"default {option.default:g}"
    return _with_aside(text, note or default)


def add_option(parser: argparse.ArgumentParser, option: Option, *, default=_TABLE_DEFAULT, note: str = "") -> None:
    """Add ``option`` to ``parser`` under its flag, with the destination
    ``option.name``. A choice is given by its command-line word; a switch
    on by default gets ``--no-...`` as well.

    Parameters
    ----------
    default : the default on the command line (e.g. None: "not given"),
        instead of the table's
    note : what the help says in parentheses instead of the default
    """
    if default is _TABLE_DEFAULT:
        default = option.word_of_choice(option.default) if option.choices else option.default
    keywords = {"dest": option.name, "default": default, "help": option_help(option, note)}
    if option.kind is bool:
        keywords["action"] = argparse.BooleanOptionalAction if option.default else "store_true"
    elif option.choices:
        keywords["choices"] = tuple(choice.command_word for choice in option.choices)
    else:
        # Shown after the flag in --help: named after the flag, not the destination.
        keywords["metavar"] = option.command_flag[2:].replace("-", "_").upper()
        if option.kind in (int, float):
            keywords["type"] = bounded(option.kind, option.low, option.high, option.low_is_open)
    parser.add_argument(option.command_flag, **keywords)


def add_options(parser: argparse.ArgumentParser, table: dict, *, leave_out: tuple = ()) -> None:
    """Every option of ``table`` that has a command-line flag, in the table's
    order, except the names in ``leave_out`` (which the caller adds itself)."""
    for option in table.values():
        if option.command_flag is not None and option.name not in leave_out:
            add_option(parser, option)


def options_from(args: argparse.Namespace, options_class):
    """An instance of the dataclass ``options_class`` whose fields are the
    parsed arguments of the same names."""
    return options_class(**{field.name: getattr(args, field.name) for field in dataclasses.fields(options_class)})
