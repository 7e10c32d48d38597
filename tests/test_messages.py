"""Names listed in messages (autorig_addon.core.messages)."""

from autorig_addon.core.messages import listed_names


def test_names_past_the_limit_are_counted():
    assert listed_names(["a", "b", "c", "d"], limit=2) == "a, b and 2 more"
    assert listed_names(["hand.L", "hand.R"], quoted=True) == "'hand.L', 'hand.R'"
    assert listed_names([]) == ""
