"""The skinning networks, one module each (its forward and its spec), and
their registry: adding a network is adding its module and one line here."""

from __future__ import annotations

from ....errors import InputError
from . import heterskinnet, rignet, skinningnet
from .scoring import SkinNetworkSpec

#: Every skinning network by name, in the order the panel lists them.
SKIN_NETWORKS: dict[str, SkinNetworkSpec] = {spec.name: spec for spec in (rignet.SPEC, heterskinnet.SPEC,
                                                                          skinningnet.SPEC)}
#: Names a ``--method`` or the panel accepts for a network.
NETWORK_NAMES = tuple(SKIN_NETWORKS)


def skin_network(name: str) -> SkinNetworkSpec:
    """The spec of the skinning network ``name``; InputError for an unknown name."""
    if name not in SKIN_NETWORKS:
        raise InputError(f"Unknown skinning network '{name}': use one of {', '.join(NETWORK_NAMES)}.")
    return SKIN_NETWORKS[name]
