"""Skin weights from a trained network, with numpy alone (inside Blender).

Steps, for a mesh and any armature (one an artist edited included):

1. The network sees the mesh welded at its seams (UV and normal splits
   would cut its graph) and, above :data:`NETWORK_PROXY_VERTICES`,
   simplified to about that many vertices (vertex clustering that keeps
   every connected part, :mod:`...geometry.proxy`): the networks were
   trained on welded characters of about 3,000 vertices, and the same
   character at its full resolution scores worse (``docs/models.md``).
2. The character is moved into the normalised frame the networks were
   trained in (:func:`...dataset.normalise.normalise`).
3. The network's distance through the shape (volumetric geodesic or
   HollowDist, :data:`NETWORK_DISTANCES`) and the prior's weights
   from it (the prior, :func:`..geometric.geometric_weights`).
4. The network's candidate weights (:mod:`.networks`), spread into the
   (n, d) matrix.
5. Back on the original mesh (interpolated at each vertex's closest point
   on the proxy surface, so no blocky seams), and last: at most
   ``max_influences`` bones per vertex, weights at or below
   :data:`PRUNE_BELOW` dropped, rows normalised. Every row keeps at least
   its largest weight, so no vertex is left unweighted.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from ...dataset.normalise import normalise
from ...distances.grid import DEFAULT_RESOLUTION
from ...distances.hollow_dist import hollow_distances
from ...distances.volumetric_geodesic import volumetric_geodesic_distances
from ...errors import InputError
from ...geometry.proxy import simplified_proxy
from ...nn.weights_io import load_weights
from ...progress import ProgressCallback, report, sub_progress
from ...types import Mesh, Skeleton, Weights
from ...weights import limit_influences, prune_small
from ..heat_prior import heat_prior_weights
from ..geometric import DEFAULT_MAX_INFLUENCES, deform_bones_of, geometric_weights
from .features import CANDIDATE_BONES, SkinGraph, skin_graph
from .networks import SCORE_FUNCTIONS, candidate_weights

#: The trained networks, by name, and the distance each one sees: RigNet
#: and SkinningNet the volumetric geodesic distance (RigNet's), HeterSkinNet
#: HollowDist (its paper's, which also reaches bones outside the body).
NETWORK_DISTANCES = {"rignet": "geodesic", "heterskinnet": "hollow", "skinningnet": "geodesic"}
#: Fewest deform bones a network weights correctly. RigNet's network reads
#: each vertex's candidates side by side, and no training character has
#: fewer than 5 deform bones, so the empty candidate slots of a smaller
#: skeleton are inputs it has never seen (a two-bone tube came out with its
#: top on the wrong bone); the other two score each (vertex, bone) pair on
#: its own and take any skeleton.
MIN_DEFORM_BONES = {"rignet": CANDIDATE_BONES}
#: The prior each network corrects: our geometric method's weights, or bone
#: heat as Blender computes it (:mod:`..heat_prior`).
NETWORK_PRIORS = {"rignet": "geometric", "heterskinnet": "heat", "skinningnet": "geometric"}
#: The priors :func:`network_graph` can build.
PRIOR_KINDS = ("geometric", "heat")
#: Names a ``--method`` or the panel accepts for a network.
NETWORK_NAMES = tuple(NETWORK_DISTANCES)
#: Folder of the trained weights shipped inside the package, one
#: ``NAME.npz`` per network (:mod:`...nn.weights_io`).
TRAINED_FOLDER = Path(__file__).resolve().parent / "trained"
#: Vertices of the proxy the networks see: the training characters' count
#: (RigNet's users see 1k to 5k).
NETWORK_PROXY_VERTICES = 3_000
#: Weights at or below this (after the influence limit) are dropped and
#: the row renormalised: a softmax never gives exactly 0, and a bone with
#: a few percent is noise an artist would have to clean. Chosen on the
#: held-out training characters as the threshold of lowest L1 (RigNet:
#: 0.3125 at 0.03, influence precision 0.885 and recall 0.836; 0.02 gives
#: 0.3127, 0.859 / 0.859; 0.05 gives 0.3138, 0.912 / 0.795;
#: ``docs/models.md``).
PRUNE_BELOW = 0.03


def trained_weights_path(network: str) -> Path:
    """The shipped weights file of ``network``."""
    return TRAINED_FOLDER / f"{network}.npz"


def network_distance(network: str) -> str:
    """The distance ``network`` sees; InputError for an unknown name."""
    if network not in NETWORK_DISTANCES:
        raise InputError(f"Unknown skinning network '{network}': use one of {', '.join(NETWORK_NAMES)}.")
    return NETWORK_DISTANCES[network]


@functools.lru_cache(maxsize=len(NETWORK_NAMES))
def trained_network(network: str) -> tuple[dict, dict]:
    """``(weights, metadata)`` of a shipped network, read once per process.

    Raises
    ------
    InputError for an unknown name or a missing file (a broken install).
    """
    network_distance(network)
    path = trained_weights_path(network)
    if not path.is_file():
        raise InputError(f"The trained weights of '{network}' are missing ({path}); reinstall the extension.")
    loaded = load_weights(str(path))
    return loaded.weights, loaded.metadata


def network_graph(mesh: Mesh, skeleton: Skeleton, distance: str, *, prior: str = "geometric",
                  resolution: int = DEFAULT_RESOLUTION, progress: ProgressCallback | None = None) -> SkinGraph:
    """The inputs of a network for a character already in the normalised
    frame: its distances, the prior on them, the features.

    Parameters
    ----------
    mesh, skeleton : normalised (:func:`...dataset.normalise.normalise`)
    distance : "geodesic" or "hollow"
    prior : "geometric" or "heat" (a value of :data:`NETWORK_PRIORS`)
    resolution : int, voxel cells along the longest side
    progress : optional ProgressCallback
    """
    deform = np.flatnonzero(skeleton.deform)
    compute = volumetric_geodesic_distances if distance == "geodesic" else hollow_distances
    distances = compute(mesh, skeleton.joints[deform], skeleton.tails[deform], resolution=resolution,
                        progress=sub_progress(progress, 0.0, 0.8))
    report(progress, 0.85, "Geometric prior")
    if prior not in PRIOR_KINDS:
        raise ValueError(f"Unknown prior {prior!r}; choose from {PRIOR_KINDS}.")
    if prior == "heat":
        prior_weights = heat_prior_weights(mesh, skeleton.joints[deform], skeleton.tails[deform], distances)
    else:
        prior_weights = geometric_weights(mesh, skeleton, distances=distances, method=distance).matrix
    report(progress, 0.95, "Network inputs")
    return skin_graph(mesh, skeleton, distances, prior_weights)


def network_candidate_weights(network: str, graph: SkinGraph) -> np.ndarray:
    """(n, K) candidate weights of a shipped network on ``graph``."""
    weights, _ = trained_network(network)
    return candidate_weights(SCORE_FUNCTIONS[network](weights, graph), graph, float(weights["prior_scale"]))


def dense_weights(graph: SkinGraph, candidate: np.ndarray) -> np.ndarray:
    """(n, d) matrix of (n, K) candidate weights."""
    dense = np.zeros((graph.vertex_count, graph.bone_count))
    rows = np.repeat(np.arange(graph.vertex_count), graph.valid.shape[1])
    keep = graph.valid.reshape(-1)
    np.add.at(dense, (rows[keep], graph.candidates.reshape(-1)[keep]), candidate.reshape(-1)[keep])
    return dense


def finished_weights(weights: np.ndarray, max_influences: int) -> np.ndarray:
    """The last step on the full mesh: influence limit, pruning at
    :data:`PRUNE_BELOW`, rows normalised."""
    return prune_small(limit_influences(weights, max_influences), PRUNE_BELOW)


def learned_weights(mesh: Mesh, skeleton: Skeleton, network: str, *, max_influences: int = DEFAULT_MAX_INFLUENCES,
                    resolution: int = DEFAULT_RESOLUTION, progress: ProgressCallback | None = None) -> Weights:
    """Skin weights of ``mesh`` for the deform bones of ``skeleton`` from a
    trained network.

    Parameters
    ----------
    mesh : Mesh, any space (the armature's and the mesh's must agree)
    skeleton : Skeleton; only bones with ``deform`` set get weights
    network : one of :data:`NETWORK_NAMES`
    max_influences : int >= 0, bones kept per vertex (0: no limit)
    resolution : int, voxel cells along the longest side
    progress : optional ProgressCallback

    Returns
    -------
    Weights with one column per deform bone (in skeleton order); every row
    is non-negative, sums to 1 and has at most ``max_influences`` non-zeros.

    Raises
    ------
    InputError for an unknown network, no deform bones or no vertices.
    """
    distance = network_distance(network)
    deform = deform_bones_of(mesh, skeleton)
    fewest = MIN_DEFORM_BONES.get(network, 1)
    if len(deform) < fewest:
        raise InputError(
            f"{network} needs at least {fewest} deform bones and the armature has {len(deform)}: "
            "use heterskinnet, skinningnet or geometric for so small a skeleton.")
    trained_network(network)  # a missing file fails before the long work
    report(progress, 0.0, "Welding and simplifying the mesh")
    proxy = simplified_proxy(mesh, NETWORK_PROXY_VERTICES)
    normalised = normalise(proxy.mesh, skeleton)
    graph = network_graph(normalised.mesh, normalised.skeleton, distance, prior=NETWORK_PRIORS[network],
                          resolution=resolution,
                          progress=sub_progress(progress, 0.05, 0.9))
    report(progress, 0.9, f"Running {network}")
    weights = dense_weights(graph, network_candidate_weights(network, graph))
    report(progress, 0.95, "Carrying the weights to every vertex")
    weights = proxy.carry(weights, lambda rows, carried: finished_weights(carried, max_influences))
    report(progress, 1.0, "Weights done")
    return Weights(weights, tuple(skeleton.names[j] for j in deform))

