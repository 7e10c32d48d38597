"""Limb joints at the middle of their limb (autorig_addon.core.rigging.limb_sections), on box limbs with known axes."""

import numpy as np
import pytest

from autorig_addon.core.rigging.limb_sections import MAX_MOVE, limb_joints_centred
from autorig_addon.core.types import Mesh
from geometry_fixtures import box_mesh

ARM_Z, LEG_X = 0.6, 0.06


def _boxes(*corners) -> Mesh:
    """Boxes of one face per side (long faces, no vertex inside a limb's length, as a low-poly arm is)."""
    return Mesh.concatenate([box_mesh(low, high, 10.0) for low, high in corners])


def _t_posed_body() -> Mesh:
    """A chest, two arms held out level along x (axis at z = ARM_Z, y = 0) and two legs (axes at x = ±LEG_X, y = 0)."""
    return _boxes(([-0.1, -0.05, 0.3], [0.1, 0.05, 0.7]),
                  ([0.1, -0.03, ARM_Z - 0.03], [0.6, 0.03, ARM_Z + 0.03]),
                  ([-0.6, -0.03, ARM_Z - 0.03], [-0.1, 0.03, ARM_Z + 0.03]),
                  ([LEG_X - 0.03, -0.03, 0.0], [LEG_X + 0.03, 0.03, 0.3]),
                  ([-LEG_X - 0.03, -0.03, 0.0], [-LEG_X + 0.03, 0.03, 0.3]))


def _landmarks(arm_lift: float, knee_forward: float) -> dict:
    """A biped's limb landmarks: the arms' joints ``arm_lift`` above the arms' axis, the knees ``knee_forward``
    toward -y off the legs' axes."""
    points = {}
    for side, sign in ((".L", 1.0), (".R", -1.0)):
        points["shoulder" + side] = np.array([sign * 0.1, 0.0, ARM_Z + arm_lift])
        points["elbow" + side] = np.array([sign * 0.3, 0.0, ARM_Z + arm_lift])
        points["wrist" + side] = np.array([sign * 0.5, 0.0, ARM_Z + arm_lift])
        points["hip" + side] = np.array([sign * LEG_X, 0.0, 0.3])
        points["knee" + side] = np.array([sign * LEG_X, -knee_forward, 0.15])
        points["ankle" + side] = np.array([sign * LEG_X, 0.0, 0.0])
    return points


def test_joints_read_above_a_low_poly_arm_and_before_a_leg_move_onto_their_axes():
    points = _landmarks(arm_lift=0.05, knee_forward=0.04)
    centred = limb_joints_centred(points, _t_posed_body())
    for side, sign in ((".L", 1.0), (".R", -1.0)):
        # Across the limb only: the elbow keeps its place along the arm, the knee its height.
        np.testing.assert_allclose(centred["elbow" + side], [sign * 0.3, 0.0, ARM_Z], atol=1e-12)
        # The wrist's cut is square to the forearm from the centred elbow, which rises 0.05 over 0.2: it crosses the
        # arm's axis 0.05 * 0.05 / 0.2 past the wrist, and the middle of that slanted cut is there.
        np.testing.assert_allclose(centred["wrist" + side], [sign * 0.5125, 0.0, ARM_Z], atol=1e-12)
        np.testing.assert_allclose(centred["knee" + side], [sign * LEG_X, 0.0, 0.15], atol=1e-12)
        for role in ("shoulder", "hip", "ankle"):
            np.testing.assert_array_equal(centred[role + side], points[role + side])


def _left_arm_hanging_by_the_chest_read_at(x: float, y: float) -> dict:
    """The left elbow of a chest with the left arm hanging beside it (the arm's axis at x 0.14, y 0), the arm's
    landmarks read straight down through (x, y)."""
    body = _boxes(([-0.1, -0.05, 0.3], [0.1, 0.05, 0.7]), ([0.11, -0.03, 0.3], [0.17, 0.03, 0.65]))
    points = _landmarks(arm_lift=0.0, knee_forward=0.0)
    points.update({f"{role}.L": np.array([x, y, z]) for role, z in (("shoulder", 0.65), ("elbow", 0.47),
                                                                   ("wrist", 0.3))})
    return limb_joints_centred(points, body)["elbow.L"]


@pytest.mark.parametrize("x, y", [(0.16, 0.02), (0.09, 0.0)], ids=["outward and behind", "inside the chest"])
def test_a_hanging_arm_is_centred_on_itself_not_on_the_chest_beside_it(x, y):
    # Read inside the chest, the chest's outline lies nearer, but it runs across the middle: no limb, so the elbow
    # goes to the arm and not deeper into the chest.
    np.testing.assert_allclose(_left_arm_hanging_by_the_chest_read_at(x, y), [0.14, 0.0, 0.47], atol=1e-12)


def test_a_skirt_round_both_legs_is_no_knee():
    skirt = _boxes(([-0.12, -0.06, 0.05], [0.12, 0.06, 0.35]))
    points = _landmarks(arm_lift=0.0, knee_forward=0.03)
    centred = limb_joints_centred(points, skirt)
    for side in (".L", ".R"):
        np.testing.assert_array_equal(centred["knee" + side], points["knee" + side])


def test_a_joint_far_from_any_limb_keeps_its_place():
    points = _landmarks(arm_lift=0.0, knee_forward=0.0)
    # An elbow further than MAX_MOVE of the upper arm's length from the arm's middle stays.
    points["elbow.L"] = np.array([0.3, 0.0, ARM_Z + 0.2])
    assert 0.2 > MAX_MOVE * np.linalg.norm(points["elbow.L"] - points["shoulder.L"])
    centred = limb_joints_centred(points, _t_posed_body())
    np.testing.assert_array_equal(centred["elbow.L"], points["elbow.L"])
    np.testing.assert_allclose(centred["elbow.R"], [-0.3, 0.0, ARM_Z], atol=1e-12)


@pytest.mark.parametrize("side, sign", [(".L", 1.0), (".R", -1.0)])
def test_a_limb_missing_from_the_mesh_leaves_its_joints(side, sign):
    chest_only = _boxes(([-0.1, -0.05, 0.3], [0.1, 0.05, 0.7]))
    points = _landmarks(arm_lift=0.05, knee_forward=0.04)
    centred = limb_joints_centred(points, chest_only)
    for role in ("elbow", "wrist", "knee"):
        np.testing.assert_array_equal(centred[role + side], points[role + side])
