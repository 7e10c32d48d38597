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
   HollowDist, its spec's ``distance``) and the weights of the prior it
   corrects (its spec's ``prior``: :func:`..geometric.geometric_weights`
   or :func:`..heat_prior.heat_prior_weights`).
4. The network's candidate weights (:mod:`.networks`, run with numpy),
   spread into the (n, d) matrix.
5. Back on the original mesh (interpolated at each vertex's closest point
   on the proxy surface, so no blocky seams), and last: at most
   ``max_influences`` bones per vertex, weights at or below
   :data:`PRUNE_BELOW` dropped, the rest raised to :data:`SHARPEN_POWER`,
   rows normalised. Every row keeps at least its largest weight, so no
   vertex is left unweighted.
"""

from __future__ import annotations

import numpy as np

from ...dataset.normalise import normalise
from ...distances.grid import DEFAULT_RESOLUTION
from ...distances.hollow_dist import hollow_distances
from ...distances.volumetric_geodesic import volumetric_geodesic_distances
from ...geometry.proxy import simplified_proxy
from ...nn.numpy_kernels import NUMPY
from ...nn.spec import shipped_weights
from ...progress import ProgressCallback, report, sub_progress
from ...types import Mesh, Skeleton, Weights
from ...weights import limit_influences, prune_small, sharpened
from ..geometric import DEFAULT_MAX_INFLUENCES, deform_bones_of, geometric_weights
from ..heat_prior import heat_prior_weights
from .ensemble import member_networks
from .features import SkinGraph, skin_graph
from .networks import skin_network
from .networks.scoring import PRIOR_KINDS, SkinNetworkSpec, candidate_weights

#: Vertices of the proxy the networks see: the training characters' count
#: (RigNet's users see 1k to 5k).
NETWORK_PROXY_VERTICES = 3_000
#: Weights at or below this (after the influence limit) are dropped and
#: the row renormalised: a softmax never gives exactly 0, and a bone with
#: a few percent is noise an artist would have to clean. Chosen on the
#: held-out training characters of the 419-character split as the
#: threshold of lowest L1 for every network (``scripts/tune_skin_pruning.py``;
#: HeterSkinNet 0.4273 at 0.08, precision 0.821, recall 0.730; 0.03 gives
#: 0.4339, 0.748 / 0.834; 0.15 gives 0.4359, 0.870 / 0.618;
#: ``docs/models.md``). The networks trained on more varied artists spread
#: their weights more, so more small ones are noise.
PRUNE_BELOW = 0.08
#: The kept weights are raised to this power and renormalised: the networks
#: blend wider than artists do (a softmax over a graph of the mesh), and a
#: slightly narrower blend is nearer theirs. Chosen with
#: :data:`PRUNE_BELOW` on the same held-out training characters
#: (``scripts/tune_skin_pruning.py``, 2026-11-26): at 0.08, L1 1.0 -> 1.25
#: -> 1.5 -> 2.0: HeterSkinNet 0.4273, 0.4199, 0.4231, 0.4413; RigNet
#: 0.4811, 0.4767, 0.4820, 0.5021; SkinningNet 0.4442, 0.4317, 0.4299,
#: 0.4430. One power for all three, each within 0.002 of its own best
#: (HeterSkinNet 0.4186 at 0.05 and 1.25, SkinningNet 0.4299 at 0.08 and
#: 1.5); precision and recall do not change (the same influences).
SHARPEN_POWER = 1.25


def network_graph(mesh: Mesh, skeleton: Skeleton, distance: str, *, prior: str = "geometric",
                  resolution: int = DEFAULT_RESOLUTION, progress: ProgressCallback | None = None) -> SkinGraph:
    """The inputs of a network for a character already in the normalised
    frame: its distances, the prior on them, the features.

    Parameters
    ----------
    mesh, skeleton : normalised (:func:`...dataset.normalise.normalise`)
    distance : "geodesic" or "hollow"
    prior : one of :data:`.networks.scoring.PRIOR_KINDS`, a network's ``prior``
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
        prior_weights = geometric_weights(mesh, skeleton, distances=distances, distance=distance).matrix
    report(progress, 0.95, "Network inputs")
    return skin_graph(mesh, skeleton, distances, prior_weights)


def network_candidate_weights(spec: SkinNetworkSpec, graph: SkinGraph, weights: dict | None = None) -> np.ndarray:
    """(n, K) candidate weights of a network on ``graph`` with numpy: its
    shipped weights, or ``weights`` (a training run's)."""
    params = shipped_weights(spec).weights if weights is None else weights
    return candidate_weights(NUMPY, params, graph, spec.forward(NUMPY, params, graph))


def dense_weights(graph: SkinGraph, candidate: np.ndarray) -> np.ndarray:
    """(n, d) matrix of (n, K) candidate weights."""
    dense = np.zeros((graph.vertex_count, graph.bone_count))
    rows = np.repeat(np.arange(graph.vertex_count), graph.valid.shape[1])
    keep = graph.valid.reshape(-1)
    np.add.at(dense, (rows[keep], graph.candidates.reshape(-1)[keep]), candidate.reshape(-1)[keep])
    return dense


def pruned_weights(weights: np.ndarray, max_influences: int) -> np.ndarray:
    """Influence limit and pruning at :data:`PRUNE_BELOW`, rows normalised:
    what training scores its held-out characters on to keep an epoch (the
    shipped networks' epochs were kept so, before :data:`SHARPEN_POWER` was
    chosen)."""
    return prune_small(limit_influences(weights, max_influences), PRUNE_BELOW)


def finished_weights(weights: np.ndarray, max_influences: int) -> np.ndarray:
    """The last step on the full mesh: :func:`pruned_weights`, then
    sharpened by :data:`SHARPEN_POWER`."""
    return sharpened(pruned_weights(weights, max_influences), SHARPEN_POWER)


def split_bones(skeleton: Skeleton, pieces: int) -> tuple[Skeleton, np.ndarray]:
    """The deform bones of ``skeleton``, each cut into ``pieces`` equal bones
    chained head to tail, for a network that needs more bones than the
    armature has (:data:`.networks.scoring.SkinNetworkSpec.min_deform_bones`).

    Returns
    -------
    (skeleton, owner): the cut skeleton (deform bones only, each piece named
    ``BONE#k``, its first piece parented to the last piece of the bone's
    nearest deforming ancestor) and, per piece, the index of its bone among
    the deform bones, to sum the pieces' weights back onto it.
    """
    deform = skeleton.deform_subset()
    steps = np.arange(pieces + 1)[:, None] / pieces
    joints, tails, parents, names, owner = [], [], [], [], []
    for bone in range(deform.bone_count):
        points = deform.joints[bone] + steps * (deform.tails[bone] - deform.joints[bone])
        parent = deform.parents[bone]
        for piece in range(pieces):
            parents.append(pieces * parent + pieces - 1 if piece == 0 and parent >= 0 else
                           len(joints) - 1 if piece else -1)
            joints.append(points[piece])
            tails.append(points[piece + 1])
            names.append(f"{deform.names[bone]}#{piece}")
            owner.append(bone)
    return Skeleton(np.array(joints), np.array(parents), tuple(names), np.array(tails)), np.array(owner)


def learned_weights(mesh: Mesh, skeleton: Skeleton, network: str, *, max_influences: int = DEFAULT_MAX_INFLUENCES,
                    resolution: int = DEFAULT_RESOLUTION, progress: ProgressCallback | None = None) -> Weights:
    """Skin weights of ``mesh`` for the deform bones of ``skeleton`` from a
    trained network, or from the ensemble of two (:mod:`.ensemble`).

    Parameters
    ----------
    mesh : Mesh, any space (the armature's and the mesh's must agree)
    skeleton : Skeleton; only bones with ``deform`` set get weights
    network : one of :data:`.networks.NETWORK_NAMES`, or :data:`.ensemble.ENSEMBLE`
    max_influences : int >= 0, bones kept per vertex (0: no limit)
    resolution : int, voxel cells along the longest side
    progress : optional ProgressCallback

    Returns
    -------
    Weights with one column per deform bone (in skeleton order); every row
    is non-negative, sums to 1 and has at most ``max_influences`` non-zeros.

    The ensemble averages its networks' raw weights on the proxy, before
    the influence limit, pruning and sharpening (:func:`finished_weights`),
    which are done once on the mean.

    Raises
    ------
    InputError for an unknown network, no deform bones or no vertices.
    """
    specs = [skin_network(name) for name in member_networks(network)]
    deform = deform_bones_of(mesh, skeleton)
    for spec in specs:
        shipped_weights(spec)  # a missing file fails before the long work
    report(progress, 0.0, "Welding and simplifying the mesh")
    proxy = simplified_proxy(mesh, NETWORK_PROXY_VERTICES)
    shares = np.linspace(0.05, 0.95, len(specs) + 1)
    weights = np.mean([proxy_weights(proxy.mesh, skeleton, spec, resolution=resolution,
                                     progress=sub_progress(progress, start, end))
                       for spec, start, end in zip(specs, shares[:-1], shares[1:])], axis=0)
    report(progress, 0.95, "Carrying the weights to every vertex")
    weights = proxy.carry(weights, lambda rows, carried: finished_weights(carried, max_influences))
    report(progress, 1.0, "Weights done")
    return Weights(weights, tuple(skeleton.names[j] for j in deform))


def proxy_weights(proxy: Mesh, skeleton: Skeleton, spec: SkinNetworkSpec, *, resolution: int = DEFAULT_RESOLUTION,
                  progress: ProgressCallback | None = None) -> np.ndarray:
    """(p, d) raw weights of one network on the ``proxy`` mesh (the one it
    sees) for the d deform bones of ``skeleton``, rows summing to 1, before
    any pruning.

    A network that weights no fewer than ``min_deform_bones`` bones (RigNet:
    3) sees a smaller skeleton with each bone cut into equal pieces
    (:func:`split_bones`), and each bone gets the sum of its pieces' weights.
    """
    deform_count = int(np.count_nonzero(skeleton.deform))
    owner = None
    if deform_count < spec.min_deform_bones:
        skeleton, owner = split_bones(skeleton, -(-spec.min_deform_bones // deform_count))
    normalised = normalise(proxy, skeleton)
    graph = network_graph(normalised.mesh, normalised.skeleton, spec.distance, prior=spec.prior,
                          resolution=resolution, progress=sub_progress(progress, 0.0, 0.95))
    report(progress, 0.95, f"Running {spec.name}")
    weights = dense_weights(graph, network_candidate_weights(spec, graph))
    if owner is None:
        return weights
    summed = np.zeros((len(weights), deform_count))
    np.add.at(summed.T, owner, weights.T)
    return summed
