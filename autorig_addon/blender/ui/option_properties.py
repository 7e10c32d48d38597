"""Blender properties made from the core's option tables (``core.options``),
and their values read back in the core's units.

Each :class:`~autorig_addon.core.options.Option` becomes the ``bpy.props``
declaration its kind calls for, named by its label, its help the tooltip,
with its default and bounds (slider range, display precision and step
where the table gives them). Units become Blender's subtypes: a fraction a
slider, a length a distance in scene units, an angle an angle, which
Blender stores in radians while the core counts degrees: the conversion
both ways is here and nowhere else. A choice's identifier is its core
value upper-cased (Blender's habit).
"""

from __future__ import annotations

import math

from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from ...core.options import DEGREES, FRACTION, LENGTH, Option

#: Float subtypes (and units) of the core's units.
_FLOAT_DISPLAY = {FRACTION: {"subtype": "FACTOR"}, DEGREES: {"subtype": "ANGLE"},
                  LENGTH: {"subtype": "DISTANCE", "unit": "LENGTH"}}


def _identifier(value: str) -> str:
    """The enum identifier of a choice's core value."""
    return value.upper()


def _to_panel(option: Option, value):
    """A value of ``option`` in the core's unit as the property stores it."""
    return math.radians(value) if option.unit == DEGREES else value


def option_property(option: Option, update=None):
    """The ``bpy.props`` declaration of ``option`` (an annotation of a
    property group or an operator); ``update``: Blender's update callback."""
    common = {"name": option.label, "description": option.help}
    if update is not None:
        common["update"] = update
    if option.choices:
        items = tuple((_identifier(choice.value), choice.label, choice.help) for choice in option.choices)
        return EnumProperty(items=items, default=_identifier(option.default), **common)
    if option.kind is bool:
        return BoolProperty(default=option.default, **common)
    if option.kind is str:
        return StringProperty(default=option.default, **common)
    limits = {key: _to_panel(option, value) for key, value in (
        ("min", option.low), ("max", option.high), ("soft_min", option.soft_low), ("soft_max", option.soft_high),
    ) if value is not None}
    if option.kind is int:
        return IntProperty(default=option.default, **limits, **common)
    display = {key: value for key, value in (("precision", option.precision), ("step", option.step))
               if value is not None}
    return FloatProperty(default=_to_panel(option, option.default), **limits, **display,
                         **_FLOAT_DISPLAY.get(option.unit, {}), **common)


def option_properties(table: dict, prefix: str = "", update=None) -> dict:
    """{property name: declaration} of every option of ``table``, the names
    being ``prefix + option.name``: the annotations of a mix-in class."""
    return {prefix + option.name: option_property(option, update) for option in table.values()}


def option_values(props, table: dict, prefix: str = "") -> dict:
    """{option name: value in the core's unit} read from the properties
    ``props`` made by :func:`option_properties` (an operator or the scene
    settings): angles in degrees, choices by their core value."""
    values = {}
    for option in table.values():
        value = getattr(props, prefix + option.name)
        if option.choices:
            value = next(choice.value for choice in option.choices if _identifier(choice.value) == value)
        elif option.unit == DEGREES:
            value = math.degrees(value)
        if option.kind is float:
            value = _within_table_bounds(option, value)
        values[option.name] = value
    return values


def _within_table_bounds(option: Option, value: float) -> float:
    """``value`` clamped to the table's bounds. Blender keeps a float property
    in float32 and clamps it to its bounds rounded to float32, so a value
    set to an end reads back a hair outside the table's bound (0.2 reads
    0.20000000298) and the core would refuse the end the slider offers."""
    if option.low is not None:
        value = max(value, option.low)
    if option.high is not None:
        value = min(value, option.high)
    return value
