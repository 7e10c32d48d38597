"""Metrics comparing predicted skin weights with reference weights.

Follows the skinning evaluation of RigNet (Xu et al. 2020): per-vertex L1
distance of the weight vectors, precision and recall of the bones that
influence each vertex, and the deformation error over random poses. For a
weight transfer without reference weights, :func:`evaluate_transfer` reports
how much the mesh's edges stretch under the same poses instead.

:func:`evaluate_skin` is the one scoring of skin weights: the ``eval skin``
command prints what it returns.

Weights are ``(n, d)`` arrays whose columns are the deform bones of the
skeleton in :meth:`Skeleton.deform_subset` order, or :class:`Weights`,
which are matched to those bones by name.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..geometry.bounding_box import character_size
from ..skeleton.posing import random_poses
from ..types import Skeleton
from ..weights import INFLUENCE_EPSILON, normalize_rows
from .deform_weights import deform_weight_matrix
from .deformation import deformation_error
from .stretch import posed_edge_stretch


def skin_l1(pred: np.ndarray, ref: np.ndarray) -> float:
    """Mean over vertices of the L1 distance between weight vectors.

    ``mean_v sum_k |pred[v, k] - ref[v, k]|``; 0 for equal weights, 2 for
    normalised rows with no bone in common.

    Parameters
    ----------
    pred, ref : (n, b) float64 array

    Returns
    -------
    l1 : float (0 for no vertices)
    """
    pred, ref = _same_shape(pred, ref)
    if not len(pred):
        return 0.0
    return float(np.abs(pred - ref).sum(axis=1).mean())


def influence_precision_recall(pred: np.ndarray, ref: np.ndarray, threshold: float = INFLUENCE_EPSILON) -> dict:
    """Precision and recall of the bones influencing each vertex.

    Bone ``k`` influences vertex ``v`` when its weight is strictly above
    ``threshold``. With ``P_v`` and ``R_v`` the predicted and reference
    influence sets of vertex ``v``, the counts are pooled over all vertices
    (micro-average, so a vertex with many influences counts more)::

        precision = sum_v |P_v & R_v| / sum_v |P_v|
        recall    = sum_v |P_v & R_v| / sum_v |R_v|

    A zero denominator gives 1 when both sides are empty everywhere and 0
    otherwise.

    Parameters
    ----------
    pred, ref : (n, b) float64 array
    threshold : float
        Influence threshold in weight units (RigNet: 1e-4).

    Returns
    -------
    dict with float values ``precision`` and ``recall`` in [0, 1].
    """
    pred, ref = _same_shape(pred, ref)
    pred_influences = pred > threshold
    ref_influences = ref > threshold
    common = int(np.count_nonzero(pred_influences & ref_influences))
    pred_count = int(np.count_nonzero(pred_influences))
    ref_count = int(np.count_nonzero(ref_influences))
    return {
        "precision": _ratio(common, pred_count, ref_count == 0),
        "recall": _ratio(common, ref_count, pred_count == 0),
    }


def evaluate_skin(
    vertices: np.ndarray,
    weights_pred,
    weights_ref,
    skeleton: Skeleton,
    poses: np.ndarray | None = None,
    threshold: float = INFLUENCE_EPSILON,
) -> dict:
    """All skin metrics of predicted weights against reference weights.

    Rows of both weight sets are normalised first
    (:func:`~..weights.normalize_rows`: negative entries clamped to zero,
    rows scaled to sum to one, empty rows kept empty). Vertices the
    *reference* leaves without weight (no entry above ``threshold``) are
    left out of every metric: nothing says how they should move. A vertex
    the *prediction* leaves without weight is counted in ``unweighted`` and
    stays at rest in every pose, as Blender's Armature modifier leaves it,
    so the deformation error compares it unmoved with the reference.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions of the character's mesh.
    weights_pred, weights_ref : (n, d) float64 array or Weights
        Columns are the deform bones of ``skeleton`` (see module docstring).
    skeleton : Skeleton
        The reference skeleton both weight sets belong to.
    poses : (p, d, 3, 3) float64 array, optional
        Local rotations for the deformation error; default
        :func:`~..skeleton.posing.random_poses` (10 seeded poses, 30 % of the
        bones, angles from N(0, 25 degrees)).
    threshold : float
        Weight above which a bone influences a vertex, in weight units
        (RigNet: 1e-4); see :func:`influence_precision_recall`.

    Returns
    -------
    dict
        Floats ``l1`` (:func:`skin_l1`), ``precision`` and ``recall``
        (:func:`influence_precision_recall`), ``deform_mean`` and
        ``deform_max`` (:func:`~.deformation.deformation_error`, in units of
        the bounding-box diagonal of the whole rest mesh), and the int
        ``unweighted``, the number of vertices the prediction leaves without
        weight.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    pred = normalize_rows(deform_weight_matrix(weights_pred, skeleton, len(vertices), "predicted weights"))
    ref = normalize_rows(deform_weight_matrix(weights_ref, skeleton, len(vertices), "reference weights"))
    unweighted = ~(pred > threshold).any(axis=1)
    scored = (ref > threshold).any(axis=1)
    influence = influence_precision_recall(pred[scored], ref[scored], threshold)
    deformation = deformation_error(
        vertices[scored], pred[scored], ref[scored], skeleton, poses, character_size(vertices)
    )
    return {
        "l1": skin_l1(pred[scored], ref[scored]),
        "precision": influence["precision"],
        "recall": influence["recall"],
        "deform_mean": deformation["mean"],
        "deform_max": deformation["max"],
        "unweighted": int(np.count_nonzero(unweighted)),
    }


def evaluate_transfer(
    vertices: np.ndarray,
    edges: np.ndarray,
    weights_pred,
    skeleton: Skeleton,
    weights_ref=None,
    poses: np.ndarray | None = None,
) -> dict:
    """Metrics of transferred weights, with or without reference weights.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions of the mesh that received the weights.
    edges : (e, 2) int64 array
        Its edges, e.g. :func:`~..geometry.topology.edges` of its triangles.
    weights_pred : (n, d) float64 array or Weights
        The transferred weights (columns: deform bones of ``skeleton``).
    skeleton : Skeleton
    weights_ref : (n, d) float64 array or Weights, optional
        Reference weights of the same mesh, when they exist.
    poses : (p, d, 3, 3) float64 array, optional
        Default :func:`~..skeleton.posing.random_poses` with its defaults.

    Returns
    -------
    dict with float values
        Always ``stretch_p99`` and ``stretch_max`` (relative edge-length
        change, :func:`~.stretch.edge_stretch`); with a reference also
        ``deform_mean`` and ``deform_max`` (in units of the bounding-box
        diagonal of ``vertices``).
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    pred = deform_weight_matrix(weights_pred, skeleton, len(vertices), "transferred weights")
    if poses is None:
        poses = random_poses(skeleton)
    stretch = posed_edge_stretch(vertices, edges, pred, skeleton, poses)
    result = {"stretch_p99": stretch["p99"], "stretch_max": stretch["max"]}
    if weights_ref is not None:
        deformation = deformation_error(vertices, pred, weights_ref, skeleton, poses)
        result["deform_mean"] = deformation["mean"]
        result["deform_max"] = deformation["max"]
    return result


def _same_shape(pred: np.ndarray, ref: np.ndarray) -> tuple:
    pred = np.asarray(pred, dtype=np.float64)
    ref = np.asarray(ref, dtype=np.float64)
    if pred.ndim != 2 or pred.shape != ref.shape:
        raise InputError(
            f"Predicted weights {pred.shape} and reference weights {ref.shape} must both be "
            "(vertices, bones) with the same bones in the same order."
        )
    return pred, ref


def _ratio(numerator: int, denominator: int, other_side_empty: bool) -> float:
    if denominator == 0:
        return 1.0 if other_side_empty else 0.0
    return numerator / denominator
