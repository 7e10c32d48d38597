"""An option of an algorithm, declared once beside it: its name, type,
default, bounds, unit, label and help.

The option tables (``core.transfer.options``, ``core.skinning.options``,
``core.rigging.options``) are made of :class:`Option` s; the Blender
properties (``blender.ui.option_properties``) and the command-line options
(``cli.arguments``) are both made from them, so a default, a bound or a
sentence of help is written once.

Values are in the core's units: an angle in degrees (the panel shows it
in radians, converted where the property is made), a choice by the core's
name for it.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Units (:attr:`Option.unit`).
#: A share in [0, 1] of a size or of a blend (the panel shows a slider).
FRACTION = "fraction"
#: An angle, in degrees (the panel shows radians, as Blender stores angles).
DEGREES = "degrees"
#: A length in scene units.
LENGTH = "length"
#: A count of voxel cells.
CELLS = "cells"


@dataclass(frozen=True)
class Choice:
    """One value of an option with choices.

    Attributes
    ----------
    value : str, the core's name for it
    label : str, what the panel's menu shows
    help : str, one sentence: the tooltip and the command line's help
    word : str, the command line's word for it ("" = ``value`` lower-cased)
    """

    value: str
    label: str
    help: str
    word: str = ""

    @property
    def command_word(self) -> str:
        """The command line's word for the choice."""
        return self.word or self.value.lower()


@dataclass(frozen=True)
class Option:
    """An option of an algorithm or a job.

    Attributes
    ----------
    name : str, the field of the options dataclass (and the command line's
        destination)
    kind : bool, int, float or str
    default : the default, in the core's unit
    label : str, the panel's short name
    help : str, what it does, one sentence without bounds or default (the
        panel's tooltip; the command line adds the bounds and the default)
    low, high : hard bounds (inclusive), or None
    low_is_open : bool, ``low`` itself is refused (the panel cannot refuse it
        and takes it as its minimum)
    soft_low, soft_high : the panel slider's range (larger values can be typed in)
    unit : "" or one of :data:`FRACTION`, :data:`DEGREES`, :data:`LENGTH`, :data:`CELLS`
    choices : tuple of Choice (the default is one of their values)
    flag : str or None, the command line's flag ("" = ``--name-with-dashes``;
        None: the option is the panel's alone)
    precision, step : how the panel shows and steps a float (None: Blender's default)
    """

    name: str
    kind: type
    default: object
    label: str
    help: str
    low: float | None = None
    high: float | None = None
    low_is_open: bool = False
    soft_low: float | None = None
    soft_high: float | None = None
    unit: str = ""
    choices: tuple = ()
    flag: str | None = ""
    precision: int | None = None
    step: float | None = None

    @property
    def command_flag(self) -> str | None:
        """The command line's flag, or None when the option is not on the command line."""
        if self.flag is None:
            return None
        return self.flag or "--" + self.name.replace("_", "-")

    def choice_of_word(self, word: str) -> str:
        """The value of the choice the command line calls ``word``."""
        return next(choice.value for choice in self.choices if choice.command_word == word)

    def word_of_choice(self, value: str) -> str:
        """The command line's word for the choice ``value``."""
        return next(choice.command_word for choice in self.choices if choice.value == value)


def option_table(*options: Option) -> dict[str, Option]:
    """``options`` by name, in the order given (the panel's and ``--help``'s)."""
    table = {option.name: option for option in options}
    if len(table) != len(options):
        raise ValueError("two options share a name")
    return table
