"""The animator's score of a predicted skeleton: its key joints named and in place.

Of the reference's key joints (:mod:`..skeleton.key_joints`: hips, neck,
head, and per side shoulder, elbow, wrist, hip, knee, ankle), the share the
prediction names for the same role *and* places within
:data:`KEY_JOINT_FRACTION` of the character's largest side. A joint the
prediction lacks, or names for another role, counts as wrong.
"""

from __future__ import annotations

import numpy as np

from ..dataset.normalise import normalise
from ..skeleton.key_joints import LEFT, RIGHT, KeyJoints, key_joints
from ..types import Mesh, Skeleton

#: A key joint is in place within this share of the character's largest side.
KEY_JOINT_FRACTION = 0.05


def key_joint_score(predicted: KeyJoints, reference: KeyJoints, tolerance: float) -> dict:
    """How many of the reference's key joints the prediction names and places.

    A role counts as right when the prediction has a bone for it whose head
    lies within ``tolerance`` of the reference's; a missing or misnamed joint
    counts as wrong.

    Returns
    -------
    dict: ``key_joints`` (share of the reference's roles right, NaN when the
    reference has none), ``key_joints_present`` (share the prediction has at
    all), ``key_joint_count`` (roles scored), ``key_joint_errors`` (role ->
    distance, or None when the prediction lacks it)
    """
    roles = list(reference.positions)
    if not roles:
        return {"key_joints": float("nan"), "key_joints_present": float("nan"), "key_joint_count": 0,
                "key_joint_errors": {}}
    errors = {}
    for role in roles:
        position = predicted.positions.get(role)
        errors[role] = None if position is None else float(np.linalg.norm(position - reference.positions[role]))
    right = sum(1 for error in errors.values() if error is not None and error <= tolerance)
    present = sum(1 for error in errors.values() if error is not None)
    return {"key_joints": right / len(roles), "key_joints_present": present / len(roles),
            "key_joint_count": len(roles), "key_joint_errors": errors}


def score_key_joints(predicted: Skeleton, mesh: Mesh, reference: Skeleton, size: float,
                     sides_named_from_the_viewer: bool = False) -> dict:
    """The key-joint scores of a predicted skeleton (:func:`key_joint_score`),
    with tolerance :data:`KEY_JOINT_FRACTION` of ``size``; empty when the
    reference's bone names say no limb (a fish's ``Head`` alone is not scored).

    The reference's sides are the character's own: its left is +X of the
    normalised frame (:func:`~..dataset.normalise.normalise`, told when
    its artist named the sides from the viewer).
    """
    left = np.linalg.inv(normalise(mesh, reference, sides_named_from_the_viewer).transform)[:3, 0]
    truth = key_joints(reference.names, reference.joints, left_direction=left, parents=reference.parents)
    if not any(role.endswith((LEFT, RIGHT)) for role in truth.positions):
        return {}
    found = key_joints(predicted.names, predicted.joints, parents=predicted.parents)
    scores = key_joint_score(found, truth, KEY_JOINT_FRACTION * size)
    return {"key_joints": scores["key_joints"], "key_joints_present": scores["key_joints_present"],
            "key_joint_count": scores["key_joint_count"], "key_joint_errors": {
                role: (None if error is None else round(error / size, 4))
                for role, error in scores["key_joint_errors"].items()}}
