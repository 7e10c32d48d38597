"""A standard biped or quadruped skeleton from the landmark network.

The landmark network (:mod:`.networks.landmarks`) places the key joints
(hips, neck, head, and per side shoulder, elbow, wrist, hip, knee, ankle)
and says the kind of body. Around them this module lays out the bones of
Rigify's metarigs, named as :mod:`.role_names` names a recognised body:

* **biped** (``basic_human``): ``spine`` to ``spine.003`` from the hips to
  the neck, ``neck``, ``head`` up to the top of the head; per side
  ``shoulder`` (the clavicle, from near the midline), ``upper_arm``,
  ``forearm``, ``hand``; ``thigh``, ``shin``, ``foot`` (ankle to the ball of
  the foot), ``toe``; when both hands have separable fingers
  (:mod:`.fingers`), per finger ``thumb``, ``f_index``, ``f_middle``,
  ``f_ring``, ``f_pinky`` ``.01`` to ``.03`` parented to the hand, the hand
  then ending at the knuckles.
* **quadruped** (``basic_quadruped``): ``spine`` to ``spine.003`` from the
  hips to the neck, ``neck``, ``head`` to the snout; ``tail``,
  ``tail.001``, ``tail.002`` when the body runs on behind the hips; per side
  ``shoulder`` (the scapula), ``front_thigh``, ``front_shin``,
  ``front_foot``, ``front_toe``; ``thigh``, ``shin``, ``foot``, ``toe``.

Ends the landmarks do not give (top of the head, snout, feet and toes on
the ground, hand, tail) are read from the mesh. A biped's landmarks are
first set where artists put them, from their conventions on the training
rigs: the hips no higher than the hip joints, the head joint near the neck,
each shoulder on its arm's axis and each wrist just past its forearm's
narrowest section, both read from the mesh. On a nearly symmetric shape
(:data:`NEAR_SYMMETRIC_ERROR`) left and right landmarks are made mirror
images of each other (averaged across x = 0) and midline ones put on x = 0,
so a character a little off symmetric (a held prop, one arm raised a few
degrees) still gets a symmetric skeleton; on another, only pairs that
nearly are mirror images are.

Everything here is in the normalised frame (feet at z = 0, largest side 1,
facing -y, left at +x).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..nn.numpy_kernels import NUMPY
from ..nn.spec import shipped_weights
from ..skeleton.key_joints import LEFT, RIGHT
from ..skeleton.naming import chain_names
from ..types import Mesh, Skeleton
from .body_layout import BodyLayout
from .fingers import FINGER_NAMES, Finger, finger_bone_names, hand_extent, hand_fingers
from .joint_features import JointGraph, SolidDepth
from .limb_sections import limb_joints_centred
from .networks import landmarks as landmark_network
from .networks.landmarks import BODY_KINDS, LANDMARKS, STANDARD_KINDS
from .rig_library import ClosestRig, KnownRelative
from .trunk_depth import trunk_joints_in_depth

BIPED, QUADRUPED, OTHER = BODY_KINDS
#: Template choices: the network's guess, one kind forced, or the free-form skeleton.
AUTO, FREE_FORM = "auto", "free-form"
TEMPLATES = (AUTO, BIPED, QUADRUPED, FREE_FORM)
#: With ``auto``, a standard skeleton is built when the network gives its
#: kind at least this probability; below it the free-form skeleton is kept.
KIND_CONFIDENCE = 0.6
#: On a shape that is not nearly symmetric, twin landmarks closer than this
#: to each other's mirror image (share of the largest side) are made exactly
#: symmetric.
SYMMETRIC_PAIR_DISTANCE = 0.08
#: A shape whose mirror error (``symmetry.mirror_error``, share of the
#: largest side) is at most this is nearly symmetric: every landmark pair is
#: mirrored. Looser than the free-form skeleton's 0.02, so that a held prop
#: or a weapon (Quaternius' Orc: 0.0245) still gives a symmetric skeleton.
NEAR_SYMMETRIC_ERROR = 0.05
#: Bones of the spine from the hips to the neck.
SPINE_BONES = 4
#: Bones of a tail.
TAIL_BONES = 3
#: The body runs on behind the hips by at least this much (share of the
#: largest side) for a quadruped to get a tail.
MIN_TAIL_LENGTH = 0.08
#: A hand is this share of its forearm's length when the mesh does not say.
HAND_SHARE = 0.4


@dataclass(frozen=True)
class Landmarks:
    """The landmark network's answer for one character (normalised frame).

    Attributes
    ----------
    points : dict mapping each name of :data:`LANDMARKS` to its (3,) position
    kind_probabilities : dict mapping each kind of :data:`BODY_KINDS` to its probability
    closest_rig : ClosestRig, the known rig of the :attr:`standard_kind` whose key joints
        stand in for the network's (:mod:`.rig_library`); None when none lies near
    relative : KnownRelative, the nearest known body when it tells the kind the
        network does not read surely (:func:`.rig_library.nearest_known_body`); else None
    layout : BodyLayout, the body's landmarks laid out as a biped's or a quadruped's when neither the
        network nor a known body tells the kind (:mod:`.body_layout`); else None
    """

    points: dict
    kind_probabilities: dict
    closest_rig: ClosestRig | None = None
    relative: KnownRelative | None = None
    layout: BodyLayout | None = None

    @property
    def kind(self) -> str:
        """The kind the network reads likeliest."""
        return max(self.kind_probabilities, key=self.kind_probabilities.get)

    @property
    def confidence(self) -> float:
        return float(self.kind_probabilities[self.kind])

    @property
    def read_surely(self) -> bool:
        """Whether the network reads a biped or quadruped with at least :data:`KIND_CONFIDENCE`."""
        return self.kind in STANDARD_KINDS and self.confidence >= KIND_CONFIDENCE

    @property
    def standard_kind(self) -> str | None:
        """The kind of standard skeleton the body gets by default: the
        network's, when it reads one surely (:attr:`read_surely`); else its
        known relative's; else its :attr:`layout`'s kind; else None."""
        if self.read_surely:
            return self.kind
        return self.kind_told_by.kind if self.kind_told_by is not None else None

    @property
    def kind_told_by(self) -> KnownRelative | BodyLayout | None:
        """What tells the kind the network does not read surely: the known
        :attr:`relative`, else the :attr:`layout`; None when neither does (or
        the network reads it surely, which needs neither)."""
        if self.read_surely:
            return None
        return self.relative if self.relative is not None else self.layout

    def copied_for(self, kind: str) -> ClosestRig | None:
        """The known rig whose key joints a standard skeleton of ``kind`` takes:
        the closest rig only for the kind it was found for (a biped forced
        on a body read as a quadruped keeps the network's points)."""
        return self.closest_rig if kind == self.standard_kind else None

    def points_for(self, kind: str) -> dict:
        """The key joints a standard skeleton of ``kind`` is built on: the
        network's, with those of :meth:`copied_for` in their place."""
        copied = self.copied_for(kind)
        return self.points if copied is None else {**self.points, **copied.points}


def predict_landmarks(graph: JointGraph) -> Landmarks:
    """Run the landmark networks on a normalised proxy's graph: the
    landmarks are the mean of the two shipped runs'
    (:data:`.networks.landmarks.SPEC` and ``LONG_SPEC``), the kind of body
    the first's, on whose readings the kind's thresholds and the facing cues
    were chosen."""
    points, logits = landmark_network.SPEC.forward(NUMPY, shipped_weights(landmark_network.SPEC).weights, graph)
    longer, _ = landmark_network.LONG_SPEC.forward(NUMPY, shipped_weights(landmark_network.LONG_SPEC).weights, graph)
    points = 0.5 * (np.asarray(points, dtype=np.float64) + np.asarray(longer, dtype=np.float64))
    logits = np.asarray(logits, dtype=np.float64).reshape(-1)
    probabilities = np.exp(logits - logits.max())
    probabilities /= probabilities.sum()
    return Landmarks({name: np.asarray(points[index], dtype=np.float64) for index, name in enumerate(LANDMARKS)},
                     {kind: float(probabilities[index]) for index, kind in enumerate(BODY_KINDS)})


def symmetrised(points: dict, symmetric_shape: bool, vertices: np.ndarray | None = None) -> dict:
    """Landmarks made mirror images: on a (nearly) symmetric shape every
    left-right pair, and the midline ones put on x = 0; on another, only the
    pairs already within :data:`SYMMETRIC_PAIR_DISTANCE` of each other's
    mirror image (an arm raised on purpose keeps its place).

    Given ``vertices`` (the normalised proxy's), a nearly symmetric shape's
    pair farther apart than that is mirrored only where the shape itself is
    symmetric around it (:func:`limb_mirror_error` at most
    :data:`LIMB_MIRROR_ERROR`): one arm of a body raised 60 degrees moves
    few of its vertices, so the shape as a whole is nearly symmetric, but
    the arm is not, and mirrored with its twin it would lie between both."""
    points = {name: np.array(point, dtype=np.float64) for name, point in points.items()}
    flip = np.array([-1.0, 1.0, 1.0])
    tree = cKDTree(vertices) if vertices is not None and symmetric_shape else None
    for name in points:
        if not name.endswith(LEFT):
            if symmetric_shape and not name.endswith(RIGHT):
                points[name][0] = 0.0
            continue
        twin = name[: -len(LEFT)] + RIGHT
        left, right = points[name], points[twin]
        near_twins = np.linalg.norm(left - right * flip) <= SYMMETRIC_PAIR_DISTANCE
        if near_twins or (symmetric_shape and (tree is None or limb_mirror_error(tree, left, right)
                                                <= LIMB_MIRROR_ERROR)):
            mean = (left + right * flip) / 2.0
            mean[0] = abs(mean[0])
            points[name], points[twin] = mean, mean * flip
    return points


#: The shape around a pair of landmarks is read within this share of the
#: largest side of each (:func:`limb_mirror_error`): a hand's length ...
LIMB_RADIUS = 0.08
#: ... and is symmetric there when its vertices, mirrored, lie a mean of at
#: most this far from the shape. Chosen on the artists' key joints of the
#: training bipeds and quadrupeds with nearly symmetric shapes (2026-12-07):
#: of their 1,338 pairs, the 1,310 within :data:`SYMMETRIC_PAIR_DISTANCE` of
#: mirror images read a median 0.003 (18 above 0.02); 22 of the 28 farther
#: apart (Nexuiz's soldiers posed in their files, a SuperTuxKart beach woman
#: in mid-stride) read above 0.02, up to 0.13.
LIMB_MIRROR_ERROR = 0.02


def limb_mirror_error(tree: cKDTree, left: np.ndarray, right: np.ndarray) -> float:
    """Mean distance from the shape's vertices (``tree``: their cKDTree, the
    normalised frame, mirror plane x = 0) within :data:`LIMB_RADIUS` of either
    landmark, mirrored, to the nearest vertex; 0 when none lies there."""
    near = sorted(set(tree.query_ball_point(left, LIMB_RADIUS)) | set(tree.query_ball_point(right, LIMB_RADIUS)))
    if not near:
        return 0.0
    return float(tree.query(tree.data[near] * np.array([-1.0, 1.0, 1.0]))[0].mean())


def hips_at_most_at_hip_joints(points: dict) -> dict:
    """A biped's landmarks with the hips no higher than the middle of the
    hip joints. Artists put a biped's hips (the joint the legs hang from)
    at or below the hip joints in every training family but OpenClonk's and
    SuperTuxKart's (median height above them, share of the height: 0 A.D.
    -0.028, Quaternius -0.036, KayKit -0.05, Nexuiz 0, OpenClonk +0.022,
    SuperTuxKart +0.021); on bodies unlike the training ones the network put
    them 0.05 to 0.1 above. Held there, no training character's key joint
    changes (every third: hips right on 90 % either way)."""
    points = dict(points)
    ceiling = 0.5 * (points["hip" + LEFT][2] + points["hip" + RIGHT][2])
    if points["hips"][2] > ceiling:
        points["hips"] = np.array([points["hips"][0], points["hips"][1], ceiling])
    return points


def hip_joints_over_knees(points: dict) -> dict:
    """A biped's landmarks with each hip joint drawn across toward the
    midline (the middle of the two hip joints), x only, until it lies no
    farther from it than its knee: a thigh does not splay outward going up.
    Artists' never do by more than 0.0075 of the largest side (the 177
    training humanoids' 354 hip
    joints, from the middle of the two: a median 0.78 of their knee's
    distance; SuperTuxKart's beach woman's right one the widest); on
    short-legged bodies unlike the training ones the network put the hip
    joints 1.05 to 1.67 times as far apart as the knees (Quaternius'
    monsters a median 1.26), 0.03 to 0.06 too wide.
    Run after the knees are centred in their legs (when the mesh is given,
    :func:`.limb_sections.limb_joints_centred`). A hip joint and its knee on
    opposite sides of the midline (legs crossed), or either on it, are left
    as they are: the knee bounds nothing there."""
    points = dict(points)
    midline = 0.5 * float(points["hip" + LEFT][0] + points["hip" + RIGHT][0])
    for side in (LEFT, RIGHT):
        hip_joint, knee = points["hip" + side], points["knee" + side]
        if (hip_joint[0] - midline) * (knee[0] - midline) <= 0.0:
            continue  # on opposite sides of the midline, or on it: no bound
        reach = abs(float(knee[0]) - midline)
        if abs(float(hip_joint[0]) - midline) > reach:
            points["hip" + side] = np.array([midline + np.sign(hip_joint[0] - midline) * reach, hip_joint[1],
                                             hip_joint[2]])
    return points


#: A biped's head joint (the head bone's head) lies at most this far from
#: its neck joint (share of the largest side). Artists' necks are at most
#: 0.047 long in every training family but SuperTuxKart's (0.091; median
#: 0.043); on big-headed bodies unlike the training ones the network put the
#: head joint 0.05 to 0.1 above the neck, up in the skull. The tightest cap
#: at which the training characters' head joints are placed best (every
#: third: 91.5 % right uncapped, 93.2 % at 0.045 to 0.05, 94.9 % from 0.0525
#: to 0.075, steps of 0.0025).
MAX_NECK_LENGTH = 0.0525


def head_near_neck(points: dict) -> dict:
    """A biped's landmarks with the head joint drawn toward the neck joint,
    along the line between them, to at most :data:`MAX_NECK_LENGTH`."""
    points = dict(points)
    neck = points["head"] - points["neck"]
    length = float(np.linalg.norm(neck))
    if length > MAX_NECK_LENGTH:
        points["head"] = points["neck"] + neck * (MAX_NECK_LENGTH / length)
    return points


#: The upper arm's axis is read from the slice of the mesh across it this
#: share of the way from the shoulder joint to the elbow joint, this thick
#: (each side, share of the upper arm's length) and out to this radius from
#: the line between them (:func:`shoulders_on_arm_axes`). Chosen on the
#: training characters' own rigs (every third humanoid, 2026-11-26): the
#: axis so read through the artist's elbow passes a median 0.006 from the
#: artist's shoulder joint, 4 % of them farther than 0.025, the closest of
#: the settings tried (shares 0.3 to 0.5, thickness 0.1 and 0.2, radius 0.35
#: and 0.5; at 0.5 of the way the slice reaches the elbow's bulge, at radius
#: 0.5 the chest).
ARM_SLICE_AT = 0.3
ARM_SLICE_HALF_THICKNESS = 0.2
ARM_SLICE_RADIUS = 0.35


def shoulders_on_arm_axes(points: dict, vertices: np.ndarray) -> dict:
    """A biped's landmarks with each shoulder joint (the upper arm's head)
    moved onto its arm's axis: the line through the elbow joint and the
    centre of the upper arm's cross-section (:data:`ARM_SLICE_AT`), the
    shoulder taken to the closest point of that line. Artists start the
    upper arm on the arm's axis; on bodies unlike the training ones the
    network put it 0.03 above it (median over the validation humanoids),
    on the top of the shoulder. An arm whose slice holds fewer than three
    of ``vertices`` (the normalised proxy's) keeps its shoulder."""
    points = dict(points)
    for side, sign in ((LEFT, 1.0), (RIGHT, -1.0)):
        shoulder, elbow = points["shoulder" + side], points["elbow" + side]
        upper_arm = elbow - shoulder
        length = float(np.linalg.norm(upper_arm))
        if length <= 1e-9:
            continue
        direction = upper_arm / length
        offsets = vertices - (shoulder + ARM_SLICE_AT * upper_arm)
        along = offsets @ direction
        across = np.linalg.norm(offsets - along[:, None] * direction, axis=1)
        # The arm's own side only: an arm hanging by the body has the chest within reach.
        slice_ = vertices[(np.abs(along) <= ARM_SLICE_HALF_THICKNESS * length)
                          & (across <= ARM_SLICE_RADIUS * length) & (sign * vertices[:, 0] > 0)]
        if len(slice_) < 3:
            continue
        axis = slice_.mean(axis=0) - elbow
        if np.linalg.norm(axis) <= 1e-9:
            continue
        axis /= np.linalg.norm(axis)
        points["shoulder" + side] = elbow + float((shoulder - elbow) @ axis) * axis
    return points


#: The wrist joint (the hand's head) is read from the mesh where the forearm
#: is narrowest (:func:`wrists_past_narrowest_forearm`): sections across the
#: line from the elbow joint through the network's wrist joint are measured
#: from this to this share of the way between them (0.8 to 1.4: up to 40 %
#: past the network's wrist, which it put 0.046 short of the artists' on the
#: validation humanoids), each this thick (each side, share of the forearm)
#: and out to this radius from the line, in :data:`WRIST_SECTION_STEPS`
#: steps; a section's width is this percentile of its vertices' distances
#: from the line (its outline: a flat palm is wide, though most of it lies
#: near the line), and one needs :data:`MIN_SECTION_VERTICES` to count.
WRIST_SEARCH_FROM, WRIST_SEARCH_TO = 0.8, 1.4
WRIST_SECTION_HALF_THICKNESS = 0.05
WRIST_SECTION_RADIUS = 0.6
WRIST_SECTION_STEPS = 61
WRIST_SECTION_PERCENTILE = 90
MIN_SECTION_VERTICES = 5
#: Artists put the wrist joint just past the forearm's narrowest section,
#: toward the hand: this share of the forearm. Chosen on every third
#: training humanoid's own rig (2026-11-26): read from the artist's own
#: elbow and wrist, the wrist so placed lies a median 0.006 from the
#: artist's (2 of 28 farther than 0.05, at most 0.062), the closest of the
#: offsets tried from 0 to 0.15 (0: 0.010; 0.1: 0.011; 0.15: 0.017). With
#: the median distance instead of the outline, 0.023; searched from 0.6 to
#: 1.6, the hand's own narrow places come in reach.
WRIST_PAST_NARROWEST = 0.05
#: A forearm pointing more than this below the horizontal hangs by the body,
#: whose side (or a dress, a sleeve) its sections run into: its wrist is
#: kept. On the predicted skeletons of every third training humanoid, the
#: 0 A.D. humans' forearms hang about 70 degrees down, and read so their
#: wrists would fall from 95.7 % right to 92.2 %; from 30 to 50 degrees the
#: other 28 wrists are read and none is lost.
HANGING_FOREARM_DEGREES = 45.0


def wrists_past_narrowest_forearm(points: dict, vertices: np.ndarray) -> dict:
    """A biped's landmarks with each wrist joint moved along its forearm to
    :data:`WRIST_PAST_NARROWEST` past the forearm's narrowest section
    (sections of ``vertices``, the normalised mesh, on the arm's side; see
    :data:`WRIST_SEARCH_FROM`), unless the forearm hangs
    (:data:`HANGING_FOREARM_DEGREES`) or no section holds enough vertices."""
    points = dict(points)
    steps = np.linspace(WRIST_SEARCH_FROM, WRIST_SEARCH_TO, WRIST_SECTION_STEPS)
    for side, sign in ((LEFT, 1.0), (RIGHT, -1.0)):
        elbow, wrist = points["elbow" + side], points["wrist" + side]
        forearm = wrist - elbow
        length = float(np.linalg.norm(forearm))
        if length <= 1e-9 or forearm[2] < -length * np.sin(np.radians(HANGING_FOREARM_DEGREES)):
            continue
        direction = forearm / length
        offsets = vertices - elbow
        along = offsets @ direction
        across = np.linalg.norm(offsets - along[:, None] * direction, axis=1)
        near = ((across <= WRIST_SECTION_RADIUS * length) & (sign * vertices[:, 0] > 0)
                & (along >= (WRIST_SEARCH_FROM - WRIST_SECTION_HALF_THICKNESS) * length)
                & (along <= (WRIST_SEARCH_TO + WRIST_SECTION_HALF_THICKNESS) * length))
        along, across = along[near] / length, across[near]
        widths = np.full(len(steps), np.inf)
        for index, step in enumerate(steps):
            section = across[np.abs(along - step) <= WRIST_SECTION_HALF_THICKNESS]
            if len(section) >= MIN_SECTION_VERTICES:
                widths[index] = np.percentile(section, WRIST_SECTION_PERCENTILE)
        if np.isfinite(widths).any():
            narrowest = steps[int(np.argmin(widths))]
            points["wrist" + side] = elbow + (narrowest + WRIST_PAST_NARROWEST) * forearm
    return points


#: A quadruped's hind foot stands on the ground: the normalised proxy's vertices lower than this share of its height,
#: on the foot's side and nearer along the body to its ankle than to its wrist, are where it stands
#: (:func:`hind_legs_over_their_feet`) ...
HIND_FOOT_GROUND_BAND = 0.03
#: ... and when their middle (the median along the body) lies more than this share of the largest side behind the
#: network's ankle, the network put the hind leg in front of its foot. Chosen on the training quadrupeds (51, their
#: cached samples, 2026-12-07): there the middle lies at most 0.013 behind the network's ankle, usually 0.01 to 0.08
#: ahead of it (the toes and hooves reach forward), so the rule moves none of them.
HIND_FOOT_BEHIND = 0.05
#: Ground contact spread along the body over more than this (10th to 90th percentile, share of the largest side) is
#: no foot: a body lying on the ground. The training quadrupeds' hind feet spread over 0.03 to 0.10, but for a rat's
#: and a fox's long tails on the ground (0.35 and more).
HIND_FOOT_SPREAD = 0.1


def hind_legs_over_their_feet(points: dict, vertices: np.ndarray) -> dict:
    """A quadruped's landmarks with each hind leg (its hip, knee and ankle joints) moved back along the body
    onto where its foot stands when the network put that leg in front of its foot (:data:`HIND_FOOT_BEHIND`),
    and the hips back by the legs' mean move, so the legs still hang from them. Behind is toward the tail:
    the way from the front foot to the hind one along y. ``vertices``: the normalised proxy's (feet at
    z = 0). The 0 A.D. pig and piglet, whose hind legs the network put 0.07 to 0.24 in front of their
    feet, are what it was written for."""
    points = dict(points)
    ground = vertices[vertices[:, 2] < HIND_FOOT_GROUND_BAND * vertices[:, 2].max()]
    moves = []
    for side, sign in ((LEFT, 1.0), (RIGHT, -1.0)):
        ankle, wrist = points["ankle" + side], points["wrist" + side]
        # Behind is toward the tail, the way from the front foot to the hind one (a body kept facing +y as
        # given, whose front the shape did not tell, has its tail at -y).
        tailward = np.sign(ankle[1] - wrist[1])
        own = ground[sign * ground[:, 0] > 0]
        foot = own[np.abs(own[:, 1] - ankle[1]) < np.abs(own[:, 1] - wrist[1]), 1]
        if not tailward or not len(foot) or np.percentile(foot, 90) - np.percentile(foot, 10) > HIND_FOOT_SPREAD:
            continue
        move = float(np.median(foot)) - ankle[1]
        if tailward * move > HIND_FOOT_BEHIND:
            for role in ("hip", "knee", "ankle"):
                points[role + side] = points[role + side] + np.array([0.0, move, 0.0])
            moves.append(move)
    if moves:
        # The mean of both sides' moves (a side not moved counts as 0): where symmetrising leaves the hip joints.
        points["hips"] = points["hips"] + np.array([0.0, sum(moves) / 2.0, 0.0])
    return points


def standard_confidence(landmarks: Landmarks) -> float:
    """The probability of the likelier of the kinds with a standard skeleton."""
    return max(landmarks.kind_probabilities[BIPED], landmarks.kind_probabilities[QUADRUPED])


class _Builder:
    """Bones added one at a time: head, tail, parent name."""

    def __init__(self):
        self.names, self.heads, self.tails, self.parents = [], [], [], []

    def add(self, name: str, head, tail, parent: str | None) -> None:
        self.names.append(name)
        self.heads.append(np.asarray(head, dtype=np.float64))
        self.tails.append(np.asarray(tail, dtype=np.float64))
        self.parents.append(-1 if parent is None else self.names.index(parent))

    def chain(self, names: list, points: list, parent: str | None) -> None:
        for name, head, tail in zip(names, points[:-1], points[1:]):
            self.add(name, head, tail, parent)
            parent = name

    def skeleton(self) -> Skeleton:
        return Skeleton(np.array(self.heads), np.array(self.parents, dtype=np.int64), tuple(self.names),
                        np.array(self.tails))


def _spine_points(hips: np.ndarray, neck: np.ndarray, count: int) -> list:
    return [hips + (neck - hips) * step / count for step in range(count + 1)]


def _near(vertices: np.ndarray, point: np.ndarray, radius: float) -> np.ndarray:
    return vertices[np.linalg.norm(vertices[:, :2] - point[:2], axis=1) <= radius]


def _top_above(vertices: np.ndarray, point: np.ndarray, radius: float, fallback: np.ndarray) -> np.ndarray:
    """The top of the mesh straight above ``point`` (the crown of a head)."""
    column = _near(vertices, point, radius)
    column = column[column[:, 2] > point[2]]
    if not len(column):
        return fallback
    return np.array([point[0], point[1], column[:, 2].max()])


def _foot_points(vertices: np.ndarray, ankle: np.ndarray, radius: float) -> tuple:
    """Ball and tip of the foot below ``ankle``: the most forward (-y) part
    of the mesh under the ankle within ``radius``, near the ground."""
    around = vertices[(np.abs(vertices[:, 0] - ankle[0]) <= radius) & (vertices[:, 2] <= ankle[2])
                      & (np.abs(vertices[:, 1] - ankle[1]) <= 3.0 * radius)]
    ground = float(around[:, 2].min()) if len(around) else 0.0
    front = float(around[:, 1].min()) if len(around) else ankle[1] - radius
    front = min(front, ankle[1] - 0.25 * radius)
    height = ground + 0.25 * max(ankle[2] - ground, 0.0)
    tip = np.array([ankle[0], front, height])
    ball = np.array([ankle[0], ankle[1] + 0.7 * (front - ankle[1]), height])
    return ball, tip


def _hand_tail(vertices: np.ndarray, elbow: np.ndarray, wrist: np.ndarray) -> np.ndarray:
    """Where the hand ends: 0.85 of the way to the farthest mesh point past
    the wrist along the forearm (:func:`.fingers.hand_extent`)."""
    direction = wrist - elbow
    length = float(np.linalg.norm(direction))
    if length <= 1e-9:
        return wrist + np.array([0.0, 0.0, 0.02])
    direction /= length
    extent = hand_extent(vertices, wrist, direction, length)
    extent = HAND_SHARE * length if extent is None else extent
    return wrist + direction * max(0.85 * extent, 0.2 * length)


def both_hands_fingers(points: dict, surface: Mesh, symmetric_shape: bool) -> dict:
    """Each side's fingers (:func:`.fingers.hand_fingers` on the full-resolution
    ``surface``, normalised frame), or ``{}`` unless both hands have separable
    fingers. On a (nearly) symmetric shape the hands are made mirror images:
    the mean of the left and the mirrored right when they found the same
    fingers, else the hand with more fingers mirrored."""
    found = {}
    for side in (LEFT, RIGHT):
        found[side] = hand_fingers(surface.vertices, surface.triangles, points["elbow" + side], points["wrist" + side])
        if not found[side]:
            return {}  # one mitten hand is enough to leave both as one bone: the other is not cut
    if not symmetric_shape:
        return found
    flip = np.array([-1.0, 1.0, 1.0])
    left, right = found[LEFT], found[RIGHT]
    if [finger.name for finger in left] == [finger.name for finger in right]:
        left = tuple(Finger(a.name, (a.points + b.points * flip) / 2.0) for a, b in zip(left, right))
    elif len(right) > len(left):
        left = tuple(Finger(finger.name, finger.points * flip) for finger in right)
    return {LEFT: left, RIGHT: tuple(Finger(finger.name, finger.points * flip) for finger in left)}


def biped_skeleton(points: dict, vertices: np.ndarray, fingers: dict | None = None) -> Skeleton:
    """Rigify's human layout around the landmarks (see the module docstring);
    with ``fingers`` (:func:`both_hands_fingers`) each hand ends at the mean
    of its fingers' knuckles (the thumb's aside) and carries
    :data:`.fingers.FINGER_BONES` bones per finger, parented to it."""
    build = _Builder()
    hips, neck, head = points["hips"], points["neck"], points["head"]
    spine = _spine_points(hips, neck, SPINE_BONES)
    build.chain(chain_names("spine", SPINE_BONES), spine, None)
    neck_length = float(np.linalg.norm(head - neck))
    crown = _top_above(vertices, head, max(neck_length, 0.03), head + (head - neck) * 2.0)
    build.chain(["neck", "head"], [neck, head, crown], "spine.003")
    for side in (LEFT, RIGHT):
        shoulder, elbow, wrist = points["shoulder" + side], points["elbow" + side], points["wrist" + side]
        clavicle = np.array([0.25 * shoulder[0], shoulder[1], 0.5 * (shoulder[2] + neck[2])])
        build.add("shoulder" + side, clavicle, shoulder, "spine.003")
        hand_fingers_here = (fingers or {}).get(side, ())
        if hand_fingers_here:
            knuckles = [finger.points[0] for finger in hand_fingers_here if finger.name != FINGER_NAMES[0]]
            hand_end = np.mean(knuckles, axis=0)
        else:
            hand_end = _hand_tail(vertices, elbow, wrist)
        build.chain(["upper_arm" + side, "forearm" + side, "hand" + side], [shoulder, elbow, wrist, hand_end],
                    "shoulder" + side)
        for finger in hand_fingers_here:
            build.chain(finger_bone_names(finger.name, side), list(finger.points), "hand" + side)
        hip, knee, ankle = points["hip" + side], points["knee" + side], points["ankle" + side]
        ball, tip = _foot_points(vertices, ankle, max(0.5 * abs(hip[0]), 0.03))
        build.chain(["thigh" + side, "shin" + side, "foot" + side, "toe" + side], [hip, knee, ankle, ball, tip],
                    "spine")
    return build.skeleton()


def quadruped_skeleton(points: dict, vertices: np.ndarray) -> Skeleton:
    """Rigify's quadruped layout around the landmarks (see the module docstring)."""
    build = _Builder()
    hips, neck, head = points["hips"], points["neck"], points["head"]
    spine = _spine_points(hips, neck, SPINE_BONES)
    build.chain(chain_names("spine", SPINE_BONES), spine, None)
    midline = vertices[np.abs(vertices[:, 0]) <= 0.05]
    ahead = midline[(midline[:, 1] < head[1]) & (np.abs(midline[:, 2] - head[2]) <= 0.15)]
    snout = np.array([0.0, float(ahead[:, 1].min()), head[2]]) if len(ahead) else head + (head - neck)
    build.chain(["neck", "head"], [neck, head, snout], "spine.003")
    behind = midline[(midline[:, 1] > hips[1]) & (midline[:, 2] >= 0.5 * hips[2])]
    if len(behind) and float(behind[:, 1].max()) - hips[1] >= MIN_TAIL_LENGTH:
        end = behind[np.argmax(behind[:, 1])]
        tail = [hips + (end - hips) * step / TAIL_BONES for step in range(TAIL_BONES + 1)]
        build.chain(chain_names("tail", TAIL_BONES), tail, "spine")
    for side in (LEFT, RIGHT):
        shoulder, elbow, wrist = points["shoulder" + side], points["elbow" + side], points["wrist" + side]
        withers = np.array([0.5 * shoulder[0], shoulder[1], shoulder[2] + 0.5 * max(neck[2] - shoulder[2], 0.02)])
        build.add("shoulder" + side, withers, shoulder, "spine.003")
        front_ball, front_tip = _foot_points(vertices, wrist, max(0.5 * abs(shoulder[0]), 0.02))
        build.chain(["front_thigh" + side, "front_shin" + side, "front_foot" + side, "front_toe" + side],
                    [shoulder, elbow, wrist, front_ball, front_tip], "shoulder" + side)
        hip, knee, ankle = points["hip" + side], points["knee" + side], points["ankle" + side]
        ball, tip = _foot_points(vertices, ankle, max(0.5 * abs(hip[0]), 0.02))
        build.chain(["thigh" + side, "shin" + side, "foot" + side, "toe" + side], [hip, knee, ankle, ball, tip],
                    "spine")
    return build.skeleton()


#: How the checks of :func:`landmark_warnings` name each key joint.
SPOKEN_NAMES = {"hips": "hips", "neck": "neck", "head": "head", "shoulder": "shoulder", "elbow": "elbow",
                "wrist": "wrist", "hip": "hip joint", "knee": "knee", "ankle": "ankle"}


def _spoken(landmark: str, kind: str) -> str:
    base, _, side = landmark.partition(".")
    side = {"L": "left ", "R": "right "}.get(side, "")
    if kind == QUADRUPED and base in ("shoulder", "elbow", "wrist"):
        base = {"shoulder": "front hip joint", "elbow": "front knee", "wrist": "front ankle"}[base]
    return side + SPOKEN_NAMES.get(base, base)


def landmark_warnings(landmarks: Landmarks, kind: str, inside) -> tuple:
    """What looks wrong with the landmarks of a standard skeleton, as notes.

    Parameters
    ----------
    landmarks : Landmarks
    kind : ``biped`` or ``quadruped``
    inside : callable, ``(k, 3) points -> (k,) depth`` of the character's
        solid (``SolidDepth.at``); a key joint at depth 0 lies outside the body

    Returns
    -------
    tuple of str: key joints outside the body, then what
    :func:`landmark_disorder` finds.
    """
    placed = landmarks.points_for(kind)
    names = list(placed)
    points = np.array([placed[name] for name in names])
    depth = np.asarray(inside(points)).reshape(-1)
    notes = []
    outside = [_spoken(name, kind) for name, value in zip(names, depth) if value <= 0.0]
    if outside:
        notes.append(f"check the skeleton: the {', '.join(outside)} could not be placed inside the body")
    return (*notes, *(f"check the skeleton: {problem}" for problem in landmark_disorder(landmarks, kind)))


def landmark_disorder(landmarks: Landmarks, kind: str) -> tuple:
    """The landmarks of ``kind`` out of the order a standing body has them,
    as phrases: a leg (a quadruped's front legs too) whose joints do not go
    down from the hip to the ankle, and a biped's hips below a knee; empty
    when none is."""
    placed = landmarks.points_for(kind)
    problems = []
    legs = [("hip", "knee", "ankle")] + ([("shoulder", "elbow", "wrist")] if kind == QUADRUPED else [])
    for chain in legs:
        for side in (LEFT, RIGHT):
            heights = [placed[role + side][2] for role in chain]
            if not heights[0] > heights[1] > heights[2]:
                problems.append(f"the {_spoken(chain[0] + side, kind)}, {_spoken(chain[1] + side, kind)} and "
                                f"{_spoken(chain[2] + side, kind)} do not go down the leg in order")
    if kind == BIPED and placed["hips"][2] <= max(placed["knee" + LEFT][2], placed["knee" + RIGHT][2]):
        # Of the 177 training humanoids' artists one put the hips below a knee (SuperTuxKart's Sara, a knee raised);
        # read so on a body standing, the trunk hangs from below the knees (the posed GDQuest mannequin).
        problems.append("the hips lie below a knee")
    return tuple(problems)


def standard_skeleton(landmarks: Landmarks, kind: str, vertices: np.ndarray, symmetric_shape: bool,
                      surface: Mesh | None = None, fingers: bool = False, solid: SolidDepth | None = None) -> Skeleton:
    """The standard skeleton of ``kind`` (biped or quadruped) around the
    landmarks, in the normalised frame. A biped's limbs are read on
    ``surface`` (the full-resolution mesh, normalised; the proxy's
    ``vertices`` alone without it), whether or not it gets ``fingers``: it
    gets them when asked and both hands have separable ones
    (:func:`both_hands_fingers`); its trunk joints are held between its
    front and back in ``solid`` (the proxy's, :mod:`.trunk_depth`) when
    given."""
    points = symmetrised(landmarks.points_for(kind), symmetric_shape, vertices)
    if kind == BIPED and landmarks.copied_for(kind) is None:
        # These correct where the network puts a biped's joints; an artist's rig copied whole is left as it is.
        if solid is not None:
            points = trunk_joints_in_depth(points, solid)
        points = head_near_neck(hips_at_most_at_hip_joints(points))
        # Each limb is read on its own side; a symmetric shape's limbs stay mirror images.
        arms_from = vertices if surface is None else surface.vertices
        points = shoulders_on_arm_axes(points, vertices)
        if solid is not None:
            # The arm's axis may lie in front of the trunk's middle (arms held forward): the band holds there too.
            points = trunk_joints_in_depth(points, solid, ("shoulder" + LEFT, "shoulder" + RIGHT))
        points = wrists_past_narrowest_forearm(points, arms_from)
        if surface is not None:
            points = limb_joints_centred(points, surface)
        points = symmetrised(hip_joints_over_knees(points), symmetric_shape, vertices)
    if kind == BIPED:
        found = both_hands_fingers(points, surface, symmetric_shape) if fingers and surface is not None else None
        return biped_skeleton(points, vertices, found)
    if kind == QUADRUPED:
        if landmarks.copied_for(kind) is None:
            points = symmetrised(hind_legs_over_their_feet(points, vertices), symmetric_shape, vertices)
        return quadruped_skeleton(points, vertices)
    raise ValueError(f"No standard skeleton for '{kind}'.")
