"""Cards hanging from a body (``core.geometry.cards``) and the skin rule that
makes those hanging from the head follow it (``core.skinning.rigid_parts``)."""

from __future__ import annotations

import numpy as np

from autorig_addon.core.geometry.cards import hanging_cards
from autorig_addon.core.skinning.rigid_parts import cards_following_the_head, head_columns
from autorig_addon.core.types import Mesh, Skeleton
from geometry_fixtures import box_mesh, card_strip, grid

#: A body 0.4 wide, 0.2 deep and 1 tall, its back at y = 0.1; area 1.36.
BODY = box_mesh([-0.2, -0.1, 0.0], [0.2, 0.1, 1.0], 0.05)
#: Cards hang 5 mm behind the back from its top edge down to z = 0.6.
CARD_Y, CARD_TOP, CARD_BOTTOM = 0.105, 0.99, 0.6
CARD_XS = (-0.15, -0.09, -0.03, 0.03, 0.09, 0.15)


def back_cards(**kwargs) -> list:
    return [card_strip([x, CARD_Y, CARD_TOP], [x, CARD_Y, CARD_BOTTOM], 0.02, **kwargs) for x in CARD_XS]


def test_thin_strips_hanging_from_the_body_are_cards_hanging_from_their_top():
    mesh = Mesh.concatenate([BODY, *back_cards()])
    cards = hanging_cards(mesh)
    assert cards.count == 6
    body_count = BODY.vertex_count
    assert not cards.mask[:body_count].any() and cards.mask[body_count:].all()
    # Each hangs from the body's vertex nearest a corner of its top (the card is near the back all the way
    # down): on the back's top edge, within half the body's grid spacing (0.025) of that corner (0.01 off).
    np.testing.assert_allclose(mesh.vertices[cards.hangs_from][:, 1:], [[0.1, 1.0]] * 6, atol=1e-9)
    np.testing.assert_allclose(np.sort(mesh.vertices[cards.hangs_from][:, 0]), CARD_XS, atol=0.035)
    assert np.all(cards.hangs_from < body_count)


def test_a_two_sided_card_is_a_card():
    """Closed (each face twice, wound both ways) but with no volume."""
    cards = hanging_cards(Mesh.concatenate([BODY, *back_cards(two_sided=True)]))
    assert cards.count == 6


def test_what_is_not_a_card_stays_the_body():
    tail = box_mesh([-0.02, 0.1, 0.3], [0.02, 0.4, 0.34], 0.02)  # closed, with volume
    cape = grid(5, 9, 1.0)  # an open sheet 0.4 by 0.8: 23 % of the body's area
    cape = Mesh(cape.vertices[:, [0, 2, 1]] * [0.4, 1.0, 0.8] + [-0.2, 0.105, 0.15], cape.triangles)
    patch = card_strip([0.0, -0.105, 0.9], [0.0, -0.105, 0.86], 0.04)  # an eye decal: not long
    afar = card_strip([0.6, 0.105, 0.99], [0.6, 0.105, 0.6], 0.02)  # 0.4 from the body: hangs from nothing
    cards = hanging_cards(Mesh.concatenate([BODY, tail, cape, patch, afar]))
    assert cards.count == 0 and not cards.mask.any()


def test_a_mesh_of_one_piece_has_no_cards():
    assert hanging_cards(BODY).count == 0


def body_weights(mesh: Mesh) -> np.ndarray:
    """Columns (chest, head, ear): the head above z = 0.8, the chest below,
    the cards spread over both as a smooth method does; no weight on the ear."""
    z = mesh.vertices[:, 2]
    head = np.clip((z - 0.7) / 0.2, 0.0, 1.0)
    return np.stack([1.0 - head, head, np.zeros_like(z)], axis=1)


def test_cards_hanging_from_the_head_are_bound_wholly_to_it():
    chest_card = card_strip([0.0, -0.105, 0.5], [0.0, -0.105, 0.2], 0.02)  # hangs from the front of the chest
    mesh = Mesh.concatenate([BODY, *back_cards(), chest_card])
    weights = body_weights(mesh)
    cards = hanging_cards(mesh)
    assert cards.count == 7
    result, bound = cards_following_the_head(mesh, weights, head=1, below_head=np.array([2]))
    assert bound == 6
    on_back = cards.mask & (mesh.vertices[:, 1] > 0.1)
    # Every back card vertex on the head alone, down to z = 0.6 where the body is all chest.
    np.testing.assert_array_equal(result[on_back], [[0.0, 1.0, 0.0]] * int(on_back.sum()))
    np.testing.assert_array_equal(result[~on_back], weights[~on_back])
    # A vertex left unweighted stays so.
    unweighted = weights.copy()
    first_card = np.flatnonzero(on_back)[0]
    unweighted[first_card] = 0.0
    assert not cards_following_the_head(mesh, unweighted, head=1, below_head=np.array([2]))[0][first_card].any()
    # No head known: nothing changes.
    same, none = cards_following_the_head(mesh, weights, head=None)
    assert none == 0 and np.array_equal(same, weights)


def test_a_card_the_armature_has_bones_of_its_own_for_keeps_its_weights():
    """A rabbit's ear with ear bones below the head: the weights on them stay."""
    mesh = Mesh.concatenate([BODY, *back_cards()])
    weights = body_weights(mesh)
    cards = hanging_cards(mesh)
    ear = cards.card_of_vertex == 0
    weights[ear] = [0.0, 0.4, 0.6]  # the ear bone holds 60 % of this card's weight
    result, bound = cards_following_the_head(mesh, weights, head=1, below_head=np.array([2]))
    assert bound == 5
    np.testing.assert_array_equal(result[ear], weights[ear])


def test_the_head_column_is_read_among_the_deform_bones_rigify_prefix_dropped():
    """Rigify's generated rig has a control bone called ``head`` (not
    deforming) and deforms with ``DEF-spine.006``, its human metarig's head;
    ``DEF-ear.L`` hangs below it."""
    names = ("root", "head", "DEF-spine", "DEF-spine.004", "DEF-spine.006", "DEF-upper_arm.L", "DEF-upper_arm.R",
             "DEF-thigh.L", "DEF-thigh.R", "DEF-ear.L")
    joints = np.array([[0, 0, 0], [0, 0, 1.7], [0, 0, 1], [0, 0, 1.5], [0, 0, 1.65], [0.2, 0, 1.45],
                       [-0.2, 0, 1.45], [0.1, 0, 0.95], [-0.1, 0, 0.95], [0.05, 0, 1.8]], dtype=float)
    deform = np.array([False, False, True, True, True, True, True, True, True, True])
    skeleton = Skeleton(joints, np.array([-1, 0, 0, 2, 3, 3, 3, 2, 2, 4]), names, joints + [0, 0, 0.1], deform)
    head, below = head_columns(skeleton)
    assert head == 2 and below.tolist() == [7]
    # As Rigify generates it: DEF-ear.L follows ORG-ear.L, which hangs from ORG-spine.006, not from DEF-spine.006.
    rigify_names = names[:9] + ("ORG-spine.006", "ORG-ear.L", "DEF-ear.L")
    rigify_joints = np.vstack([joints[:9], joints[[4, 9, 9]]])
    rigify_parents = np.array([-1, 0, 0, 2, 3, 3, 3, 2, 2, 0, 9, 10])
    rigify = Skeleton(rigify_joints, rigify_parents, rigify_names, rigify_joints + [0, 0, 0.1],
                      np.concatenate([deform[:9], [False, False, True]]))
    assert head_columns(rigify)[0] == 2 and head_columns(rigify)[1].tolist() == [7]
    plain = Skeleton(joints[2:9], np.array([-1, 0, 1, 1, 1, 0, 0]), ("hips", "neck", "head", "upper_arm.L",
                                                                       "upper_arm.R", "thigh.L", "thigh.R"))
    assert head_columns(plain)[0] == 2 and head_columns(plain)[1].size == 0
    assert head_columns(Skeleton(joints[:2], np.array([-1, 0]), ("a", "b")))[0] is None
