"""Helpers of the sidebar panels (autorig_addon.blender.ui.panels)."""

from autorig_addon.blender.ui.panels import MAX_LISTED_OBJECTS, _short_list


def test_short_list_names_the_first_objects_and_counts_the_rest():
    assert MAX_LISTED_OBJECTS == 3
    assert _short_list(["Shirt", "Pants", "Hat", "Belt", "Shoe"]) == "Shirt, Pants, Hat +2"
    assert _short_list(["Shirt", "Pants", "Hat"]) == "Shirt, Pants, Hat"
    assert _short_list(["Shirt"]) == "Shirt"
    assert _short_list([]) == ""
