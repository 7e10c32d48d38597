"""One module per character kind (or family of kinds).

Each ``build_<kind>(ch)`` draws a skeleton morphology from a
:class:`..character_builder.CharacterBuilder`, grows the body and the
optional pieces, and returns the variant it made (``"spider"``,
``"dragon"``, ``"door"``...). :data:`BUILDERS` maps each kind of
:data:`..character.KINDS` to its builder.
"""

from __future__ import annotations

from .biped import build_biped
from .fish import build_fish
from .long_chain import build_long_chain
from .multileg import build_multileg
from .prop import build_prop
from .quadruped import build_quadruped
from .tailed import build_tailed
from .winged import build_winged

#: Builder of each character kind.
BUILDERS = {
    "biped": build_biped,
    "quadruped": build_quadruped,
    "multileg": build_multileg,
    "winged": build_winged,
    "tailed": build_tailed,
    "long_chain": build_long_chain,
    "fish": build_fish,
    "prop": build_prop,
}
