"""Weights checked against the bone names before they are trusted (autorig_addon.core.dataset.weight_checks)."""

import numpy as np
import pytest

from autorig_addon.core.dataset.weight_checks import (
    MAX_CROSSED_SIDE_SHARE,
    check_named_weights,
    has_mixamo_names,
    role_bones,
)
from autorig_addon.core.types import Weights
from geometry_fixtures import arm_posed_humanoid, points_along_bones


def painted(skeleton, owners) -> Weights:
    """Weights an artist would give the points of :func:`points_along_bones`: each on its own bone."""
    return Weights(np.eye(len(skeleton.names))[owners], skeleton.names)


@pytest.fixture
def humanoid():
    skeleton = arm_posed_humanoid(30.0, 30.0)
    mesh, owners = points_along_bones(skeleton)
    return skeleton, mesh, owners


def test_mixamo_names_are_recognised():
    assert has_mixamo_names(["mixamorig:Hips", "mixamorig:Spine"])
    assert has_mixamo_names(["Root", "mixamorig1:Hips"])
    assert not has_mixamo_names(["Hips", "Spine", "hand.L"])


def test_role_bones_are_the_root_most_hand_foot_and_head(humanoid):
    skeleton, _, _ = humanoid
    assert [skeleton.names[bone] for bone in role_bones(skeleton.names)] == [
        "mixamorig:Head", "mixamorig:LeftHand", "mixamorig:LeftFoot", "mixamorig:RightHand", "mixamorig:RightFoot",
    ]


def test_weights_on_their_own_bones_are_plausible(humanoid):
    skeleton, mesh, owners = humanoid
    check = check_named_weights(mesh, skeleton, painted(skeleton, owners))
    assert check.trustworthy
    assert (check.vertex_count, check.unweighted, check.crossed_side_share) == (mesh.vertex_count, 0, 0.0)
    assert [(name, share) for name, share, _ in check.role_shares] == [
        ("mixamorig:Head", 1.0), ("mixamorig:LeftHand", 1.0), ("mixamorig:LeftFoot", 1.0),
        ("mixamorig:RightHand", 1.0), ("mixamorig:RightFoot", 1.0),
    ]
    assert check.note.startswith("weights checked against the bone names: plausible (0 of 300 vertices unweighted; "
                                 "nearest-bone vertices on their own bone: mixamorig:Head 100% of 12, ")


def test_hand_vertices_on_the_spine_are_not_trusted(humanoid):
    skeleton, mesh, owners = humanoid
    hand, spine = skeleton.names.index("mixamorig:LeftHand"), skeleton.names.index("mixamorig:Spine")
    moved = np.where(owners == hand, spine, owners)
    check = check_named_weights(mesh, skeleton, painted(skeleton, moved))
    assert dict((name, share) for name, share, _ in check.role_shares)["mixamorig:LeftHand"] == 0.0
    assert not check.trustworthy
    assert "NOT trustworthy" in check.note


def test_unweighted_vertices_and_crossed_sides_are_not_trusted(humanoid):
    skeleton, mesh, owners = humanoid
    weights = painted(skeleton, owners).matrix
    weights[0] = 0.0
    unweighted = check_named_weights(mesh, skeleton, Weights(weights, skeleton.names))
    assert unweighted.unweighted == 1 and not unweighted.trustworthy
    # The left forearm's 12 points (of 300, 25 bones) weighted to the right forearm cross sides.
    left, right = skeleton.names.index("mixamorig:LeftForeArm"), skeleton.names.index("mixamorig:RightForeArm")
    crossed = check_named_weights(mesh, skeleton, painted(skeleton, np.where(owners == left, right, owners)))
    assert crossed.crossed_side_share == pytest.approx(12 / 300)
    assert crossed.crossed_side_share > MAX_CROSSED_SIDE_SHARE and not crossed.trustworthy
    assert crossed.note.endswith("; 4.0% weighted to the other side)")
