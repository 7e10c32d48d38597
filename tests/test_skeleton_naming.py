"""Blender's bone naming conventions (core/skeleton/naming.py)."""

import pytest

from autorig_addon.core.skeleton.naming import chain_names, mirror_name


@pytest.mark.parametrize("name, twin", [
    ("upper_arm.L", "upper_arm.R"),
    ("hand.R", "hand.L"),
    ("f_index.01.L", "f_index.01.R"),
    ("spine.001", "spine.001"),  # midline bones are their own twin
    ("beak.001.T", "beak.001.T"),
    ("Left", "Left"),  # only the suffix counts
    (".L.x", ".L.x"),
])
def test_mirror_name_swaps_the_side_suffix(name, twin):
    assert mirror_name(name) == twin
    assert mirror_name(twin) == name


def test_chain_names_number_the_bones_before_the_side():
    assert chain_names("tail", 3) == ["tail", "tail.001", "tail.002"]
    assert chain_names("wing", 2, ".L") == ["wing.L", "wing.001.L"]
    assert chain_names("hair", 1) == ["hair"]
