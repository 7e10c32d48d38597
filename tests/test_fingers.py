"""Fingers found by cutting the hand across, and the standard biped's finger bones."""

import numpy as np
import pytest

from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.fingers import FINGER_NAMES, HAND_LENGTH_SHARE, NOT_SEPARABLE_NOTE, hand_fingers
from autorig_addon.core.rigging.metarig import FINGER_RIG, PALM_RIG, PALM_START, finger_bones
from autorig_addon.core.rigging.predict import predict_votes, skeleton_from_votes, template_notes
from autorig_addon.core.skeleton.name_presets import PRESETS, preset_names
from autorig_addon.core.types import Mesh

ELBOW, WRIST = np.array([-0.25, 0.0, 0.0]), np.zeros(3)


def box(start, direction, length, width, thickness):
    """A box from the centre of one end face, ``length`` along ``direction``: (8, 3) vertices, (12, 3) triangles."""
    along = np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    side = np.cross([0.0, 0.0, 1.0], along)
    side /= np.linalg.norm(side)
    up = np.cross(along, side)
    corners = [np.asarray(start) + a * along + b * side + c * up
               for a in (0.0, length) for b in (-width / 2, width / 2) for c in (-thickness / 2, thickness / 2)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return np.array(corners), np.array([(q[0], q[1], q[2]) for q in quads] + [(q[0], q[2], q[3]) for q in quads])


def joined(parts) -> Mesh:
    offsets = np.cumsum([0] + [len(vertices) for vertices, _ in parts[:-1]])
    return Mesh(np.vstack([vertices for vertices, _ in parts]),
                np.vstack([triangles + offset for (_, triangles), offset in zip(parts, offsets)]))


def box_hand(with_fingers: bool = True):
    """A forearm along +x to the wrist at 0, a palm to x = 0.1, four finger
    boxes 6 mm apart and a thumb slanting forward (-y); and each finger's
    known (knuckle, tip)."""
    parts = [box((-0.25, 0, 0), (1, 0, 0), 0.25, 0.06, 0.04), box((-0.005, 0, 0), (1, 0, 0), 0.105, 0.09, 0.03)]
    known = {}
    if with_fingers:
        for name, y, length in (("f_index", -0.036, 0.07), ("f_middle", -0.012, 0.08), ("f_ring", 0.012, 0.075),
                                ("f_pinky", 0.036, 0.06)):
            parts.append(box((0.1, y, 0), (1, 0, 0), length, 0.018, 0.018))
            known[name] = (np.array([0.1, y, 0.0]), np.array([0.1 + length, y, 0.0]))
        direction = np.array([1.0, -0.5, 0.0]) / np.sqrt(1.25)
        base = np.array([0.02, -0.035, 0.0])
        parts.append(box(base, direction, 0.11, 0.02, 0.018))
        # The thumb's back edge leaves the palm's side (y = -0.045) 0.047 along it.
        known["thumb"] = (base + 0.047 * direction, base + 0.11 * direction)
    return joined(parts), known


def test_a_hand_of_boxes_gives_five_fingers_of_three_bones_with_their_tips_and_knuckles():
    hand, known = box_hand()
    fingers = hand_fingers(hand.vertices, hand.triangles, ELBOW, WRIST)
    assert [finger.name for finger in fingers] == ["thumb", "f_index", "f_middle", "f_ring", "f_pinky"]
    for finger in fingers:
        knuckle, tip = known[finger.name]
        assert finger.points.shape == (4, 3)
        assert np.linalg.norm(finger.points[-1] - tip) < 0.002
        assert np.linalg.norm(finger.points[0] - knuckle) < (0.01 if finger.name == "thumb" else 0.002)
        # Joints evenly spaced: the three bones are equally long on a straight finger.
        lengths = np.linalg.norm(np.diff(finger.points, axis=0), axis=1)
        assert np.ptp(lengths) < 0.003


def test_long_fingers_past_a_forearm_read_short_are_found_to_their_tips():
    """The landmarks may read a forearm short (here 0.13 of the box hand's 0.25): its hand, 0.18 long, then
    reaches 1.4 forearm lengths past the wrist. The cuts go up to HAND_LENGTH_SHARE (1.5) forearm lengths, so
    they pass the fingertips; cut at one forearm's length they ended 0.05 inside every finger."""
    hand, known = box_hand()
    short_elbow = np.array([-0.13, 0.0, 0.0])
    assert 1.0 < 0.18 / 0.13 < HAND_LENGTH_SHARE
    fingers = {finger.name: finger for finger in hand_fingers(hand.vertices, hand.triangles, short_elbow, WRIST)}
    for name in ("f_index", "f_middle", "f_ring", "f_pinky"):
        knuckle, tip = known[name]
        assert np.linalg.norm(fingers[name].points[-1] - tip) < 0.002
        assert np.linalg.norm(fingers[name].points[0] - knuckle) < 0.002


def test_a_mitten_hand_has_no_separable_fingers():
    mitten, _ = box_hand(with_fingers=False)
    assert hand_fingers(mitten.vertices, mitten.triangles, ELBOW, WRIST) == ()


def procedural_biped_with_box_fingers():
    """The procedural biped (its hands are mittens) with four box fingers and a thumb on each hand."""
    character = generate_character(0, "biped")
    names = list(character.skeleton.names)
    parts = [(character.mesh.vertices, character.mesh.triangles)]
    for side in (".L", ".R"):
        head = character.skeleton.joints[names.index("hand" + side)]
        tail = character.skeleton.tails[names.index("hand" + side)]
        size = float(np.linalg.norm(tail - head))
        along = (tail - head) / size
        across = np.cross([0.0, 0.0, 1.0], along)
        across /= np.linalg.norm(across)
        for offset, length in ((-0.3, 1.0), (-0.1, 1.2), (0.1, 1.1), (0.3, 0.9)):
            parts.append(box(tail - 0.1 * size * along + offset * size * across, along, (length + 0.1) * size,
                             0.14 * size, 0.14 * size))
        parts.append(box(head + 0.6 * size * along, along + np.array([0.0, -0.5, 0.0]), 1.6 * size, 0.15 * size,
                         0.15 * size))
    return joined(parts)


@pytest.fixture(scope="module")
def fingered_votes():
    return predict_votes(procedural_biped_with_box_fingers())


def test_a_biped_with_fingers_gets_fifteen_finger_bones_a_hand_and_without_the_switch_the_22(fingered_votes):
    skeleton = skeleton_from_votes(fingered_votes, template="biped")
    assert skeleton.bone_count == 22 + 30
    index = {name: k for k, name in enumerate(skeleton.names)}
    for side in (".L", ".R"):
        for finger in ("thumb", "f_index", "f_middle", "f_ring", "f_pinky"):
            first, second, third = (f"{finger}.{joint:02d}{side}" for joint in (1, 2, 3))
            assert skeleton.parents[index[first]] == index["hand" + side]
            assert skeleton.parents[index[second]] == index[first]
            assert skeleton.parents[index[third]] == index[second]
            np.testing.assert_allclose(skeleton.tails[index[first]], skeleton.joints[index[second]])
    # The procedural biped is symmetric: the right hand's fingers mirror the left's about the hands.
    for name, k in index.items():
        if name.endswith(".L") and name.startswith(("thumb", "f_")):
            left = (skeleton.joints[k] - skeleton.joints[index["hand.L"]]) * [-1, 1, 1]
            right = skeleton.joints[index[name[:-2] + ".R"]] - skeleton.joints[index["hand.R"]]
            np.testing.assert_allclose(left, right, atol=1e-6)
    assert NOT_SEPARABLE_NOTE not in template_notes(fingered_votes, "biped", skeleton)
    plain = skeleton_from_votes(fingered_votes, template="biped", fingers=False)
    assert plain.bone_count == 22
    assert not any(name.startswith(("thumb", "f_")) for name in plain.names)


def test_the_finger_switch_moves_no_other_joint(fingered_votes):
    # Fingers are detail: with or without them the arms are read on the same mesh, so no key joint moves.
    fingered = skeleton_from_votes(fingered_votes, template="biped")
    plain = skeleton_from_votes(fingered_votes, template="biped", fingers=False)
    index = {name: k for k, name in enumerate(fingered.names)}
    for k, name in enumerate(plain.names):
        np.testing.assert_allclose(fingered.joints[index[name]], plain.joints[k], atol=1e-12, err_msg=name)


def test_the_procedural_biped_has_mitten_hands_so_no_fingers_and_a_note():
    votes = predict_votes(generate_character(0, "biped").mesh)
    skeleton = skeleton_from_votes(votes, template="biped")
    assert skeleton.bone_count == 22
    assert NOT_SEPARABLE_NOTE in template_notes(votes, "biped", skeleton)
    assert NOT_SEPARABLE_NOTE not in template_notes(votes, "biped", skeleton, fingers=False)


def test_finger_names_go_through_every_preset_and_back(fingered_votes):
    names = skeleton_from_votes(fingered_votes, template="biped").names
    for preset in PRESETS:
        renamed, given = preset_names(names, preset)
        assert given and len(set(renamed)) == len(names)
        assert preset_names(renamed, "rigify")[0] == names
    mixamo = preset_names(names, "mixamo")[0]
    assert {"mixamorig:LeftHandIndex1", "mixamorig:RightHandPinky3", "mixamorig:LeftHandThumb2"} <= set(mixamo)
    assert {"leftIndexProximal", "leftThumbMetacarpal"} <= set(preset_names(names, "vrm")[0])
    assert "index_01_l" in preset_names(names, "unreal")[0]


def test_rigify_palm_and_finger_bones_sit_on_the_knuckles_and_none_without_fingers(fingered_votes):
    skeleton = skeleton_from_votes(fingered_votes, template="biped")
    added = {bone.name: bone for bone in finger_bones(skeleton)}
    index = {name: k for k, name in enumerate(skeleton.names)}
    assert len(added) == 2 * (4 + 15)
    for side, sign in ((".L", 1.0), (".R", -1.0)):
        wrist = skeleton.joints[index["hand" + side]]
        for palm, finger in zip(("palm.01", "palm.02", "palm.03", "palm.04"), FINGER_NAMES[1:]):
            bone, knuckle = added[palm + side], skeleton.joints[index[f"{finger}.01{side}"]]
            assert bone.parent == "hand" + side and bone.up == ("x", sign)
            np.testing.assert_allclose(bone.tail, knuckle)
            np.testing.assert_allclose(bone.head, wrist + PALM_START * (knuckle - wrist))
            assert added[f"{finger}.01{side}"].parent == palm + side
        assert added["palm.01" + side].rig_type == PALM_RIG and added["palm.02" + side].rig_type == ""
        assert added["thumb.01" + side].parent == "palm.01" + side and added["thumb.01" + side].up == ("z", -1.0)
        assert added["f_index.01" + side].rig_type == FINGER_RIG and not added["f_index.01" + side].connected
        assert added["f_index.02" + side].parent == "f_index.01" + side and added["f_index.03" + side].connected
    assert finger_bones(skeleton_from_votes(fingered_votes, template="biped", fingers=False)) == ()
