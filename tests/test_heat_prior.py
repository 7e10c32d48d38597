"""Bone heat as Blender computes it (the networks' prior), on shapes with known answers."""

import numpy as np

from autorig_addon.core.distances.hollow_dist import hollow_distances
from autorig_addon.core.geometry.segments import point_segment_distances
from autorig_addon.core.skinning.heat_prior import WEIGHT_LIMIT, heat_prior_weights
from geometry_fixtures import cylinder

HEADS = np.array([[0, 0, 0.0], [0, 0, 1.0]])
TAILS = np.array([[0, 0, 1.0], [0, 0, 2.0]])


def test_each_end_of_a_tube_follows_its_own_bone_and_small_weights_are_dropped():
    mesh = cylinder(radius=0.1, height=2.0, segments=16, rings=41)
    weights = heat_prior_weights(mesh, HEADS, TAILS, hollow_distances(mesh, HEADS, TAILS, resolution=64))
    z = mesh.vertices[:, 2]
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-12)
    assert (weights[z < 0.7, 0] > 0.99).all() and (weights[z > 1.3, 1] > 0.99).all()
    # The joint ring blends both bones about equally (the tube is symmetric about z = 1).
    joint = np.isclose(z, 1.0)
    np.testing.assert_allclose(weights[joint], 0.5, atol=0.02)
    assert weights[weights > 0].min() > WEIGHT_LIMIT


def test_a_bone_the_surface_faces_away_from_does_not_take_it():
    # A bone in the air beside a tube (a skirt bone): the wall facing it is
    # nearer to it (0.07) than to the tube's own bone (0.1) in a straight
    # line, but the bone lies behind that wall's surface as seen along its
    # normal, so Blender's distance (divided by 0.5 * (cos + 1.001), cos = -1)
    # makes it 2,000 times farther and the wall stays on its own bone.
    mesh = cylinder(radius=0.1, height=1.0, segments=16, rings=11)
    heads, tails = np.array([[0, 0, 0.0], [0.17, 0, 0.0]]), np.array([[0, 0, 1.0], [0.17, 0, 1.0]])
    weights = heat_prior_weights(mesh, heads, tails, hollow_distances(mesh, heads, tails, resolution=64))
    facing = mesh.vertices[:, 0] > 0.09
    assert facing.sum() == 3 * 11  # three of the 16 around each of the 11 rings
    assert (point_segment_distances(mesh.vertices[facing], heads, tails).argmin(axis=1) == 1).all()
    assert (weights[:, 0] > 0.99).all()
