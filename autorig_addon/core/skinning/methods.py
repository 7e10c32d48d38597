"""The skinning methods the Skin job offers, and the one call that runs any of them.

``geometric`` is :func:`.geometric.geometric_weights` (bone heat diffused
over the surface from voxel distances); the others are the trained networks
of :mod:`.learned` (:func:`.learned.predict.learned_weights`). The panel's
*Method*, the ``skin --method`` option and ``SkinSettings.method`` all take
their names, labels, descriptions and default from here.

Some options belong to the geometric method alone
(:data:`GEOMETRIC_OPTIONS`: the distance kind, the heat falloff, the extra
smoothing): a network ignores them (the panel disables them, the command
line says so when one was changed); the resolution of the voxel distances
and the influence limit apply to every method.
"""

from __future__ import annotations

import inspect

from ..distances.grid import DEFAULT_RESOLUTION
from ..errors import InputError
from ..progress import ProgressCallback
from ..types import Mesh, Skeleton, Weights
from .geometric import DEFAULT_MAX_INFLUENCES, geometric_weights
from .learned.networks import NETWORK_NAMES, SKIN_NETWORKS
from .learned.predict import learned_weights

#: The method without training: :func:`.geometric.geometric_weights`.
GEOMETRIC = "geometric"
#: Every name ``--method`` and the panel accept, the geometric method first.
SKIN_METHODS = (GEOMETRIC,) + NETWORK_NAMES
#: The default is the network that scores best on the validation characters
#: (``eval skin``, tables in docs/skinning.md): HeterSkinNet has the lowest
#: mean and median L1 of the three and, seeing HollowDist, also weights
#: open meshes and bones outside the body.
DEFAULT_SKIN_METHOD = "heterskinnet"
#: Short names the panel shows, per method (the networks' from their specs).
SKIN_METHOD_LABELS = {GEOMETRIC: "Geometric", **{name: spec.label for name, spec in SKIN_NETWORKS.items()}}
#: One line per method: the panel's tooltips, the command line's help and
#: ``eval``'s method list (the networks' from their specs).
SKIN_METHOD_DESCRIPTIONS = {
    GEOMETRIC: "Bone heat diffused over the surface from voxel distances through the shape, no training",
    **{name: spec.description for name, spec in SKIN_NETWORKS.items()},
}
#: Options of the geometric method alone, by their names here (and in
#: ``SkinSettings`` and on the command line) -> the keyword of
#: :func:`.geometric.geometric_weights` they set. Networks ignore them.
GEOMETRIC_OPTIONS = {
    "distance": "distance",
    "falloff": "falloff",
    "smoothing_iterations": "smoothing_iterations",
    "smoothing_strength": "smoothing_strength",
}


def check_skin_method(method: str) -> None:
    """Raise :class:`InputError` unless ``method`` is one of :data:`SKIN_METHODS`."""
    if method not in SKIN_METHODS:
        raise InputError(f"Unknown skinning method '{method}': use one of {', '.join(SKIN_METHODS)}.")


def geometric_option_default(name: str):
    """The default of the geometric-only option ``name`` (a key of
    :data:`GEOMETRIC_OPTIONS`), read off :func:`.geometric.geometric_weights`
    where it is declared."""
    return inspect.signature(geometric_weights).parameters[GEOMETRIC_OPTIONS[name]].default


def ignored_options(method: str, options: dict) -> tuple[str, ...]:
    """The geometric-only options among ``options`` (name -> value) set to
    something other than their default, which ``method`` ignores: none for
    the geometric method, in :data:`GEOMETRIC_OPTIONS` order."""
    if method == GEOMETRIC:
        return ()
    return tuple(name for name in GEOMETRIC_OPTIONS
                 if name in options and options[name] != geometric_option_default(name))


def skin_weights(mesh: Mesh, skeleton: Skeleton, method: str, *, max_influences: int = DEFAULT_MAX_INFLUENCES,
                 resolution: int = DEFAULT_RESOLUTION, progress: ProgressCallback | None = None,
                 **geometric_options) -> Weights:
    """Skin weights of ``mesh`` for the deform bones of ``skeleton`` by ``method``.

    Parameters
    ----------
    mesh : Mesh
    skeleton : Skeleton; only bones with ``deform`` set get weights
    method : one of :data:`SKIN_METHODS`
    max_influences : int >= 0, bones kept per vertex (0: no limit)
    resolution : int, voxel cells along the longest side of the mesh
    progress : optional ProgressCallback (raising in it stops the run)
    **geometric_options : keys of :data:`GEOMETRIC_OPTIONS` (``distance``,
        ``falloff``, ``smoothing_iterations``, ``smoothing_strength``),
        passed to the geometric method and ignored by the networks

    Returns
    -------
    Weights with one column per deform bone (in skeleton order); every row
    is non-negative, sums to 1 and has at most ``max_influences`` non-zeros
    (when that is above 0).

    Raises
    ------
    InputError for an unknown method and for the methods' own bad input
    (no deform bones, no vertices, a network's missing weights file).
    TypeError for an option that is not in :data:`GEOMETRIC_OPTIONS`.
    """
    unknown = sorted(set(geometric_options) - set(GEOMETRIC_OPTIONS))
    if unknown:
        raise TypeError(f"skin_weights() got unknown options: {', '.join(unknown)}")
    check_skin_method(method)
    if method != GEOMETRIC:
        return learned_weights(mesh, skeleton, method, max_influences=max_influences, resolution=resolution,
                               progress=progress)
    keywords = {GEOMETRIC_OPTIONS[name]: value for name, value in geometric_options.items()}
    return geometric_weights(mesh, skeleton, max_influences=max_influences, resolution=resolution, progress=progress,
                             **keywords)
