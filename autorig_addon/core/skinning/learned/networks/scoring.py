"""What the three skinning networks share: the facts a skinning network's
spec adds (:class:`SkinNetworkSpec`), the valid (vertex, bone) candidate
pairs, and how scores become weights.

Each network scores every vertex's :data:`..features.CANDIDATE_BONES`
candidate bones; the scores are *added to* ``prior_scale * log(prior)``,
the logarithm of a prior's weight (our geometric method's, or bone heat as
Blender computes it), so an untrained network, whose score head starts at
zero, reproduces the prior and training learns the correction (predicting a
residual on a geometric prior is what lets these generalise from a few
dozen characters). A softmax over each vertex's valid candidates gives
weights (:func:`candidate_weights`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ....nn.operations import Array, Operations
from ....nn.spec import NetworkSpec, Scalar
from ..features import PRIOR_FLOOR, SkinGraph

#: Folder of the shipped weights, one ``NAME.npz`` per network.
TRAINED_FOLDER = Path(__file__).resolve().parent.parent / "trained"
#: The distances a network may see (:mod:`....distances`): RigNet's
#: volumetric geodesic distance, or HeterSkinNet's HollowDist (which also
#: reaches bones outside the body).
DISTANCE_KINDS = ("geodesic", "hollow")
#: The priors a network may correct: our geometric method's weights, or
#: bone heat as Blender computes it (:mod:`...heat_prior`).
PRIOR_KINDS = ("geometric", "heat")
#: The learned number the prior's logarithm is multiplied by.
PRIOR_SCALE = "prior_scale"


@dataclass(frozen=True, kw_only=True)
class SkinNetworkSpec(NetworkSpec):
    """A skinning network: a :class:`....nn.spec.NetworkSpec` whose forward
    gives (n, K) candidate scores of a :class:`..features.SkinGraph`, plus

    Attributes
    ----------
    distance : one of :data:`DISTANCE_KINDS`, the distance through the shape it sees
    prior : one of :data:`PRIOR_KINDS`, the weights it corrects
    min_deform_bones : int, fewest deform bones it weights correctly

    Every skinning network also learns the :data:`PRIOR_SCALE` its prior's
    logarithm is multiplied by (:func:`candidate_weights`), created before
    its layers.
    """

    inputs: str = "SkinGraph"
    distance: str
    prior: str
    min_deform_bones: int = 1

    def __post_init__(self):
        if self.distance not in DISTANCE_KINDS or self.prior not in PRIOR_KINDS:
            raise ValueError(f"{self.name}: distance {self.distance!r} or prior {self.prior!r} unknown.")

    def parts(self) -> tuple:
        return (Scalar(PRIOR_SCALE, 1.0),) + super().parts()


def candidate_weights(ops: Operations, params: dict, graph: SkinGraph, scores: Array) -> Array:
    """(n, K) weights: softmax over each vertex's valid candidates of the
    network ``scores`` plus ``prior_scale * log(prior)``."""
    logits = scores + params[PRIOR_SCALE] * ops.log(graph.prior + PRIOR_FLOOR)
    return ops.masked_row_softmax(logits, graph.valid)


def candidate_pairs(ops: Operations, graph: SkinGraph) -> tuple[Array, Array, Array]:
    """The valid (vertex, bone) candidate pairs: the vertex and the bone of
    each, and each pair's row in the flattened (n * K) candidate table."""
    rows = ops.nonzero(graph.valid.reshape(-1))
    return rows // graph.valid.shape[1], graph.candidates.reshape(-1)[rows], rows


def scattered_scores(ops: Operations, pair_scores: Array, graph: SkinGraph, pair_rows: Array) -> Array:
    """(n, K) table of per-pair scores (p, 1); 0 in the invalid slots."""
    n, k = graph.valid.shape
    return ops.scatter(pair_scores[:, 0], pair_rows, n * k).reshape(n, k)
