"""The skinning methods the Skin job offers, and the one call that runs any of them.

``geometric`` is :func:`.geometric.geometric_weights` (bone heat diffused
over the surface from voxel distances); the others are the trained networks
of :mod:`.learned` and their ensemble (:mod:`.learned.ensemble`), all run by
:func:`.learned.predict.learned_weights`. The panel's
*Method*, the ``skin --method`` option and ``SkinningOptions.method``
(:mod:`.options`) all take their names, labels, descriptions and default
from here.

Some options belong to the geometric method alone
(:data:`GEOMETRIC_OPTIONS`: the distance kind, the heat falloff, the extra
smoothing): a network ignores them (the panel disables them, the command
line says so when one was changed: :func:`.options.ignored_options`); the
resolution of the voxel distances and the influence limit apply to every
method. Every method reads the triangles wound outward
(:mod:`..geometry.outward_faces`): flipped normals give the weights of the
same mesh wound right.
"""

from __future__ import annotations

from ..errors import InputError
from ..geometry.outward_faces import outward_mesh
from ..progress import ProgressCallback
from ..types import Mesh, Skeleton, Weights
from .geometric import geometric_weights
from .learned.ensemble import ENSEMBLE, ENSEMBLE_DESCRIPTION, ENSEMBLE_LABEL
from .learned.networks import NETWORK_NAMES, SKIN_NETWORKS
from .learned.predict import learned_weights
from .rigid_parts import cards_following_the_head, head_columns, rigid_weights

#: The method without training: :func:`.geometric.geometric_weights`.
GEOMETRIC = "geometric"
#: Every name ``--method`` and the panel accept, the geometric method first, the ensemble last.
SKIN_METHODS = (GEOMETRIC,) + NETWORK_NAMES + (ENSEMBLE,)
#: The default is HeterSkinNet. The ensemble of HeterSkinNet and SkinningNet
#: (:mod:`.learned.ensemble`) is nearer the artists' weights on the held-out
#: training characters (L1 0.4082 against 0.4199) and on the validation
#: families with smooth weights, but on the validation set as a whole it is
#: behind (mean L1 0.581 against 0.560, precision 0.697 against 0.725): its
#: wider blends cost most where artists put every vertex on one bone
#: (Kenney's minis, the dungeon monsters; docs/skinning.md). A default is
#: not changed for a method that the validation set measures worse.
#: HeterSkinNet, seeing HollowDist, also weights open meshes and bones
#: outside the body.
DEFAULT_SKIN_METHOD = "heterskinnet"
#: Short names the panel shows, per method (the networks' from their specs).
SKIN_METHOD_LABELS = {GEOMETRIC: "Geometric", **{name: spec.label for name, spec in SKIN_NETWORKS.items()},
                      ENSEMBLE: ENSEMBLE_LABEL}
#: One line per method: the panel's tooltips, the command line's help and
#: ``eval``'s method list (the networks' from their specs).
SKIN_METHOD_DESCRIPTIONS = {
    GEOMETRIC: "Bone heat diffused over the surface from voxel distances through the shape, no training",
    **{name: spec.description for name, spec in SKIN_NETWORKS.items()},
    ENSEMBLE: ENSEMBLE_DESCRIPTION,
}
#: Options of the geometric method alone: fields of ``SkinningOptions`` (and
#: command-line options) named as the keywords of
#: :func:`.geometric.geometric_weights` they set. Networks ignore them.
GEOMETRIC_OPTIONS = ("distance", "falloff", "smoothing_iterations", "smoothing_strength")


def check_skin_method(method: str) -> None:
    """Raise :class:`InputError` unless ``method`` is one of :data:`SKIN_METHODS`."""
    if method not in SKIN_METHODS:
        raise InputError(f"Unknown skinning method '{method}': use one of {', '.join(SKIN_METHODS)}.")


def skin_weights(mesh: Mesh, skeleton: Skeleton, options, *, progress: ProgressCallback | None = None) -> Weights:
    """Skin weights of ``mesh`` for the deform bones of ``skeleton`` by ``options.method``.

    Parameters
    ----------
    mesh : Mesh, its triangles read wound outward whatever their winding
        (:func:`...geometry.outward_faces.outward_mesh`)
    skeleton : Skeleton; only bones with ``deform`` set get weights
    options : SkinningOptions (:mod:`.options`, which imports this module
        for the method names): the method (one of :data:`SKIN_METHODS`), the
        resolution and influence limit every method uses, and the
        :data:`GEOMETRIC_OPTIONS`, which the networks ignore
    progress : optional ProgressCallback (raising in it stops the run)

    Returns
    -------
    Weights with one column per deform bone (in skeleton order); every row
    is non-negative, sums to 1 and has at most ``options.max_influences``
    non-zeros (when that is above 0). With ``options.rigid_parts``, each
    loose part the method weighted mostly to one bone is bound wholly to it,
    and each card hanging from the head (hair) is bound wholly to the head
    (:mod:`.rigid_parts`).

    Raises
    ------
    InputError for an unknown method and for the methods' own bad input
    (no deform bones, no vertices, a network's missing weights file).
    """
    check_skin_method(options.method)
    # Every method's proxy and the networks' normals follow the winding: read it outward whatever the file's.
    mesh = outward_mesh(mesh)[0]
    if options.method != GEOMETRIC:
        weights = learned_weights(mesh, skeleton, options.method, max_influences=options.max_influences,
                                  resolution=options.resolution, progress=progress)
    else:
        weights = geometric_weights(mesh, skeleton, max_influences=options.max_influences,
                                    resolution=options.resolution, progress=progress,
                                    **{name: getattr(options, name) for name in GEOMETRIC_OPTIONS})
    if not options.rigid_parts:
        return weights
    matrix = rigid_weights(mesh, weights.matrix)[0]
    return Weights(cards_following_the_head(mesh, matrix, *head_columns(skeleton))[0], weights.bone_names)
