"""Wording shared by the messages and notes the user reads."""

from __future__ import annotations

from typing import Sequence

#: Names listed in a message before the rest are only counted ("and N more").
MAX_LISTED_NAMES = 5


def listed_names(names: Sequence[str], quoted: bool = False, limit: int = MAX_LISTED_NAMES) -> str:
    """``names`` joined by commas, those past ``limit`` counted as "and N more".

    Examples
    --------
    >>> listed_names(["a", "b", "c"], quoted=True, limit=2)
    "'a', 'b' and 1 more"
    """
    shown = [f"'{name}'" if quoted else str(name) for name in names]
    text = ", ".join(shown[:limit])
    return text + (f" and {len(shown) - limit} more" if len(shown) > limit else "")
