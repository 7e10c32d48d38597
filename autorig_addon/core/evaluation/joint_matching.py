"""One-to-one matching of predicted to reference joints, and the joint IoU,
precision and recall it gives (RigNet's skeleton evaluation, Xu et al. 2020).

Predicted joints are paired with reference joints by a minimum-cost
(Hungarian) assignment, keeping only pairs within a distance tolerance.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..errors import InputError

#: A predicted joint matches a reference joint within this share of the
#: character size (``eval rig``: the largest side of its bounding box).
#: RigNet uses half the local shape diameter at the reference joint; for a
#: 1.7 m human in A-pose (largest side 1.7 m) this is 4.3 cm, about half the
#: thickness of an upper arm.
JOINT_MATCH_FRACTION = 0.025


def checked_joints(joints: np.ndarray, what: str) -> np.ndarray:
    """A joint set given by a caller, checked to be an ``(n, 3)`` array.

    Parameters
    ----------
    joints : array_like
    what : str
        How a refusal names the joints (``"predicted joints"``).

    Returns
    -------
    joints : (n, 3) float64 array

    Raises
    ------
    InputError
        For any other shape.
    """
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 2 or joints.shape[1] != 3:
        raise InputError(f"The {what} must be an (n, 3) array, got shape {joints.shape}.")
    return joints


def match_joints(pred_joints: np.ndarray, ref_joints: np.ndarray, tolerance: float | None = None) -> np.ndarray:
    """One-to-one matching of predicted to reference joints (Hungarian).

    Without ``tolerance``: the assignment of ``min(p, r)`` pairs with the
    smallest total distance. With ``tolerance``: among assignments, the one
    with the most pairs at distance ``<= tolerance``, ties broken by the
    smallest total distance of those pairs; pairs farther apart are dropped.

    Parameters
    ----------
    pred_joints : (p, 3) float64 array
    ref_joints : (r, 3) float64 array
    tolerance : float, optional
        Largest distance of a matched pair, in the joints' units.

    Returns
    -------
    matching : (p,) int64 array
        Index of the matched reference joint per predicted joint, -1 if none.
    """
    pred_joints = checked_joints(pred_joints, "predicted joints")
    ref_joints = checked_joints(ref_joints, "reference joints")
    matching = np.full(len(pred_joints), -1, dtype=np.int64)
    if not len(pred_joints) or not len(ref_joints):
        return matching
    distance = np.linalg.norm(pred_joints[:, None, :] - ref_joints[None, :, :], axis=2)
    if tolerance is None:
        rows, cols = linear_sum_assignment(distance)
    else:
        within = distance <= tolerance
        # Any pair beyond tolerance costs more than all pairs within it
        # together, so maximising the count of close pairs comes first.
        beyond_cost = (min(distance.shape) + 1) * max(float(tolerance), 0.0) + 1.0
        rows, cols = linear_sum_assignment(np.where(within, distance, beyond_cost))
        keep = within[rows, cols]
        rows, cols = rows[keep], cols[keep]
    matching[rows] = cols
    return matching


def joint_iou_precision_recall(pred_joints: np.ndarray, ref_joints: np.ndarray, tolerance: float) -> dict:
    """Joint IoU, precision and recall after matching within a tolerance.

    With ``t`` the number of pairs of :func:`match_joints` (with
    ``tolerance``): ``iou = t / (p + r - t)``, ``precision = t / p``,
    ``recall = t / r``. An empty side gives 0 (1 when both are empty).

    Parameters
    ----------
    pred_joints : (p, 3) float64 array
    ref_joints : (r, 3) float64 array
    tolerance : float
        In the joints' units (see :data:`JOINT_MATCH_FRACTION`).

    Returns
    -------
    dict with float values ``iou``, ``precision`` and ``recall`` in [0, 1].
    """
    pred_joints = checked_joints(pred_joints, "predicted joints")
    ref_joints = checked_joints(ref_joints, "reference joints")
    pred_count, ref_count = len(pred_joints), len(ref_joints)
    if pred_count == 0 and ref_count == 0:
        return {"iou": 1.0, "precision": 1.0, "recall": 1.0}
    matched = int(np.count_nonzero(match_joints(pred_joints, ref_joints, tolerance) >= 0))
    return {
        "iou": matched / (pred_count + ref_count - matched),
        "precision": matched / pred_count if pred_count else 0.0,
        "recall": matched / ref_count if ref_count else 0.0,
    }
