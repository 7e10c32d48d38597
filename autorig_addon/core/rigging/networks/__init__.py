"""The skeleton networks, one module each (its forward and its spec), and
their registry: adding a network is adding its module and one line here."""

from __future__ import annotations

from ...errors import InputError
from ...nn.spec import NetworkSpec
from . import bones, joints, landmarks, root, upright

#: Every skeleton network by name: the free-form skeleton's in the order
#: they run, then the standard skeleton's, then the one that finds up.
RIG_NETWORKS: dict[str, NetworkSpec] = {
    spec.name: spec for spec in (joints.SPEC, bones.SPEC, root.SPEC, landmarks.SPEC, landmarks.LONG_SPEC, upright.SPEC)}
#: Names ``train rig --model`` accepts.
NETWORK_NAMES = tuple(RIG_NETWORKS)


def rig_network(name: str) -> NetworkSpec:
    """The spec of the skeleton network ``name``; InputError for an unknown name."""
    if name not in RIG_NETWORKS:
        raise InputError(f"Unknown skeleton network '{name}': use one of {', '.join(NETWORK_NAMES)}.")
    return RIG_NETWORKS[name]
