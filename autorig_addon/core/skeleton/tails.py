"""Bone tails derived from the joints, for armatures whose stored tails are guesses.

glTF stores joints (nodes), not bones: the tail of every bone is a guess of
the importer. Blender's glTF importer points each bone along its joint's
local +Y axis with a length measured in the armature's own units, so a file
whose armature node is scaled by 100 with joints in tiny units (every
Quaternius character) imports with bones of a few hundredths of what they
should be: the median bone of ``Trex.glb`` is 0.03 % of the character
long, a point. Everything measured along bones inherits that: distances to
a bone segment become distances to its head, our geometric skinning weights
the wrong regions and Blender's bone heat (Automatic Weights), which
diffuses heat from the bone segments, scores L1 0.33 on the T-rex instead
of about 0.05 with real bones.

A joint hierarchy says where a bone goes: toward the child that continues
it. :func:`derived_tails` builds tails from that (heads never move);
:func:`assess_stored_tails` decides per armature whether the stored tails
are usable; :func:`with_reliable_tails` returns the skeleton with the tails
to measure along, and that decision in words for reports. When the stored
bones are point-like but still point at their children (an exporter that
orients every joint along its bone, as Blender's does, and an importer
that follows the joint axis), their directions are the original bones'
and are kept for the bones the hierarchy cannot orient (leaves, branch
points); only their lengths come from the joints. A file whose exporter
never turned its joint frames imports with every bone pointing one way
(Kenney's minis: all up, the legs from the hips into the chest); those
directions say nothing of the bones, and the tails are derived too. The
caller's armature is never changed: only the arrays passed to the core.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Optional

import numpy as np

from ..errors import InputError
from ..geometry.bounding_box import bounding_box_diagonal
from ..messages import listed_names
from ..types import Skeleton
from .hierarchy import descendant_counts

#: Joints closer than this share of the skeleton's extent (bounding-box
#: diagonal of the joints) are the same point: importers often put a root
#: and the hips, or a bone and its twist helper, at one place. A child there
#: gives no direction and is skipped.
COINCIDENT_FRACTION = 1e-6
#: A leaf bone (no child to point at) continues the line from its parent's
#: head through its own head for this share of that distance, i.e. as long
#: as its parent is when the parent ends at the leaf. Blender's glTF
#: importer gives a leaf its parent's length too; half of it makes the head
#: of the T-rex (a leaf) too short, and bone heat then gives the snout to
#: the neck (L1 0.16 against 0.05 with 1.0).
LEAF_LENGTH_FRACTION = 1.0
#: At a branch the child best aligned with the incoming direction (parent
#: head to joint) continues the bone when its cosine beats the runner-up's
#: by this much (0.3 is about 17 degrees at right angles); otherwise, as at
#: hips -> spine / legs, the child with most descendants (the main chain)
#: wins.
ALIGNMENT_MARGIN = 0.3
#: Two children of one joint are mirror twins (left and right ears, legs,
#: shoulders) when their distances to the joint, and their cosines with the
#: incoming direction, agree within this share, and they have as many
#: descendants. A bone never continues into one of a pair of twins: the
#: neck goes to the head, not to the left ear.
MIRROR_TOLERANCE = 0.02
#: A stored bone direction points at a child when the cosine between them
#: is at least this (about 8 degrees).
DIRECTION_MATCH_COS = 0.99
#: The stored directions of point-like bones are kept when at least this
#: share of the bones with a child point at one of them (Quaternius files:
#: 60 to 100 %; a file whose joint axes are not along its bones, such as
#: ``assimp_bsd/X_BCN_Epileptic``: 0 %).
MIN_DIRECTION_AGREEMENT = 0.5
#: A bone with no direction at all (no parent, no child, no stored
#: direction) points up (+Z) for this share of the character size when the
#: whole armature's tails are derived.
LONE_ROOT_LENGTH_FRACTION = 0.1

#: The stored tails are unusable when the median bone is shorter than this
#: share of the character size (bounding-box diagonal): real rigs have
#: median bones of 2.5 % or more (dense face rigs stay well above 0.1 %),
#: the Quaternius animals and dinosaurs 0.03 to 0.2 %.
MIN_MEDIAN_LENGTH_FRACTION = 1e-3
#: ... or when the median bone with a child reaches less than this share of
#: the way to the child it continues: real rigs reach it (100 %, tail on
#: the child's head), the Quaternius characters 0.3 to 26 %.
MIN_MEDIAN_REACH = 0.5
#: ... or when at least this share of the bones with a direction (and no
#: fewer than :data:`MIN_ONE_WAY_BONES`) point the same way (within
#: :data:`ONE_WAY_COS`) while their directions do not point at their
#: children (:data:`MIN_DIRECTION_AGREEMENT`, over at least
#: :data:`MIN_AGREEMENT_VOTES` bones with a child): the importer followed
#: joint frames the exporter never turned, so the legs of Kenney's minis
#: start at the hips and point up into the chest. Only bones with a child
#: vote, so a mini whose root, torso and head were stacked within 8 degrees
#: would keep its upward legs. Motivated by the minis (validation), not
#: tuned: no training character is caught, and none has more than 62 % of
#: its bones one way without its directions agreeing. Deriving is worth it
#: when the bones do point one way: with every bone of the 53 held-out
#: training characters turned to +Z, HeterSkinNet's L1 was 1.066 as given
#: and 0.552 with the tails derived (0.412 with the real bones; better on
#: 50 of 53). ``scripts/check_one_way_bones.py`` prints all of these
#: (2026-11-26).
ONE_WAY_SHARE = 0.9
#: Bones pointing the same way: directions within about 2 degrees.
ONE_WAY_COS = 0.9994
#: Fewer bones than this pointing one way say nothing about the importer.
MIN_ONE_WAY_BONES = 3
#: ... nor does one bone with children: a hand-made comb of parallel teeth
#: on a bar parallel to them points beside its children by design.
MIN_AGREEMENT_VOTES = 2
#: In an armature whose tails are usable, a single bone shorter than this
#: share of the character size is point-like (0.2 mm on a 2 m character):
#: it gets a derived tail when it has a child, else a deform bone is refused.
POINT_LIKE_FRACTION = 1e-4


@dataclass(frozen=True)
class TailDecision:
    """Which tails a skeleton's bones were given, and why.

    Attributes
    ----------
    derived : tuple of str
        Names of the bones whose tails were derived from the joints
        (empty: every stored tail was kept).
    whole_armature : bool
        The stored tails were unusable and every bone was derived.
    reason : str
        Why, in words (the stored bones' median length and reach, or the
        way they all point).
    """

    derived: tuple = ()
    whole_armature: bool = False
    reason: str = ""

    @property
    def any_derived(self) -> bool:
        return bool(self.derived)

    @property
    def note(self) -> str:
        """One line for a report, e.g. "bone tails derived from the joints:
        the stored bones are point-like (median length 0.025 % of the character)"."""
        if self.whole_armature:
            return f"bone tails derived from the joints: {self.reason}"
        if self.derived:
            count = len(self.derived)
            return f"bone tails derived from the joints for {count} point-like bone{'s' * (count > 1)}: {self.reason}"
        return f"stored bone tails used: {self.reason}"


@dataclass(frozen=True)
class TailAssessment:
    """How the stored tails of a skeleton measure up (:func:`assess_stored_tails`).

    Attributes
    ----------
    usable : bool
        Whether the stored tails describe real bones.
    median_length_fraction : float
        Median stored bone length as a share of the character size.
    median_reach : float
        Median over bones with a continuing child of stored length /
        distance to that child, leaving out single point-like bones
        (:data:`POINT_LIKE_FRACTION`, handled one by one); NaN when no
        bone is left.
    direction_agreement : float
        Share of the bones with a child whose stored direction points at
        one of them (:data:`DIRECTION_MATCH_COS`; NaN when no bone has a
        child).
    one_way_share : float
        Largest share of the bones (with a length) that point the same way
        (:data:`ONE_WAY_COS`); 0 when fewer than :data:`MIN_ONE_WAY_BONES`
        have a length.
    reason : str
        The above in words.
    """

    usable: bool
    median_length_fraction: float
    median_reach: float
    direction_agreement: float
    one_way_share: float
    reason: str

    @property
    def directions_agree(self) -> bool:
        return bool(self.direction_agreement >= MIN_DIRECTION_AGREEMENT)  # False for NaN


def _percent(share: float) -> str:
    """``share`` as a percentage with two significant digits, never in exponent form."""
    return f"{float(f'{100 * share:.2g}'):g} %"


def _unit_rows(vectors: np.ndarray) -> np.ndarray:
    """Rows scaled to length 1; zero or non-finite rows become NaN."""
    lengths = np.linalg.norm(vectors, axis=1)
    good = np.isfinite(lengths) & (lengths > 0)
    out = np.full_like(vectors, np.nan)
    out[good] = vectors[good] / lengths[good, None]
    return out


def _children_apart(joints: np.ndarray, parents: np.ndarray) -> list:
    """For each joint the array of its children not at its own place."""
    tolerance = COINCIDENT_FRACTION * bounding_box_diagonal(joints)
    children = [[] for _ in range(len(joints))]
    for j, parent in enumerate(parents):
        if parent >= 0 and np.linalg.norm(joints[j] - joints[parent]) > tolerance:
            children[parent].append(j)
    return [np.array(kids, dtype=np.int64) for kids in children]


def continued_children(joints: np.ndarray, parents: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The child each bone continues toward, and the direction each joint is reached from.

    Parameters
    ----------
    joints : (j, 3) float64 array, bone heads
    parents : (j,) int64 array, parent index (-1 for roots), parents first

    Returns
    -------
    child : (j,) int64 array
        Index of the child the bone points at, -1 when none continues it:
        a leaf (children at its own head do not count) or a joint whose
        children are all mirror twins (:data:`MIRROR_TOLERANCE`). Twins
        are left out; of the others a single child is the one, else the
        child best aligned with the incoming direction when it beats the
        runner-up by :data:`ALIGNMENT_MARGIN`, else (and for roots) the
        child with most descendants, ties to the better aligned, then the
        first.
    incoming : (j, 3) float64 array
        Vector from the nearest ancestor not at the joint's place to the
        joint (zeros for a root or when every ancestor is at the joint).
    """
    joints = np.asarray(joints, dtype=np.float64).reshape(-1, 3)
    parents = np.asarray(parents, dtype=np.int64).reshape(-1)
    count = len(joints)
    tolerance = COINCIDENT_FRACTION * bounding_box_diagonal(joints)
    descendants = descendant_counts(parents)
    incoming = np.zeros((count, 3))
    for j in range(count):
        ancestor = parents[j]
        while ancestor >= 0 and np.linalg.norm(joints[j] - joints[ancestor]) <= tolerance:
            ancestor = parents[ancestor]
        if ancestor >= 0:
            incoming[j] = joints[j] - joints[ancestor]
    child = np.full(count, -1, dtype=np.int64)
    for j, kids in enumerate(_children_apart(joints, parents)):
        if not len(kids):
            continue
        offsets = joints[kids] - joints[j]
        distances = np.linalg.norm(offsets, axis=1)
        incoming_length = np.linalg.norm(incoming[j])
        cosines = offsets @ incoming[j] / (distances * incoming_length) if incoming_length > 0 else np.zeros(len(kids))
        gaps = np.abs(distances[:, None] - distances[None, :])
        same_distance = gaps <= MIRROR_TOLERANCE * np.maximum.outer(distances, distances)
        same_angle = np.abs(cosines[:, None] - cosines[None, :]) <= MIRROR_TOLERANCE
        same_subtree = descendants[kids][:, None] == descendants[kids][None, :]
        twins = same_distance & same_angle & same_subtree
        np.fill_diagonal(twins, False)
        keep = ~twins.any(axis=1)
        kids, cosines = kids[keep], cosines[keep]
        if len(kids) <= 1:
            child[j] = kids[0] if len(kids) else -1
            continue
        ranked = np.argsort(-cosines, kind="stable")
        if incoming_length > 0 and cosines[ranked[0]] - cosines[ranked[1]] >= ALIGNMENT_MARGIN:
            child[j] = kids[ranked[0]]
            continue
        # Most descendants first, then best aligned, then the first child.
        order = np.lexsort((np.arange(len(kids)), -cosines, -descendants[kids]))
        child[j] = kids[order[0]]
    return child, incoming


def derived_tails(joints: np.ndarray, parents: np.ndarray, directions: Optional[np.ndarray] = None) -> np.ndarray:
    """Tails derived from the joint hierarchy; heads stay exact.

    A bone that a child continues (:func:`continued_children`) ends at that
    child's head. A leaf continues the line from its parent's head through
    its own head for :data:`LEAF_LENGTH_FRACTION` of that distance (parents
    at the leaf's own place are skipped).

    With ``directions`` (the stored bones' directions, when they are known
    to be the original bones', see :func:`with_reliable_tails`), a bone
    whose direction points at one of its children (:data:`DIRECTION_MATCH_COS`)
    ends at that child's head; any other bone with a direction keeps it,
    with the length derived above.

    A bone with no direction (a lone root, a joint whose children are all
    twins and that has no parent, a chain whose joints all lie at one
    place) gets a NaN row, for the caller to refuse or fill.

    Parameters
    ----------
    joints : (j, 3) float64 array, bone heads
    parents : (j,) int64 array, parent index (-1 for roots), parents first
    directions : (j, 3) float64 array, optional; rows of zero length or
        NaN mean no direction for that bone

    Returns
    -------
    (j, 3) float64 array of tails, NaN rows for bones without a direction.
    """
    joints = np.asarray(joints, dtype=np.float64).reshape(-1, 3)
    parents = np.asarray(parents, dtype=np.int64).reshape(-1)
    child, incoming = continued_children(joints, parents)
    tails = np.full_like(joints, np.nan)
    has_child = child >= 0
    tails[has_child] = joints[child[has_child]]
    leaf = ~has_child & (np.linalg.norm(incoming, axis=1) > 0)
    tails[leaf] = joints[leaf] + LEAF_LENGTH_FRACTION * incoming[leaf]
    if directions is None:
        return tails
    units = _unit_rows(np.asarray(directions, dtype=np.float64).reshape(-1, 3))
    lengths = np.linalg.norm(tails - joints, axis=1)  # NaN where no direction was derived
    for j, kids in enumerate(_children_apart(joints, parents)):
        if np.isnan(units[j, 0]):
            continue
        if len(kids):
            offsets = joints[kids] - joints[j]
            cosines = offsets @ units[j] / np.linalg.norm(offsets, axis=1)
            best = int(np.argmax(cosines))
            if cosines[best] >= DIRECTION_MATCH_COS:
                tails[j] = joints[kids[best]]
                continue
        if np.isfinite(lengths[j]):
            tails[j] = joints[j] + units[j] * lengths[j]
    return tails


def assess_stored_tails(skeleton: Skeleton, size: float) -> TailAssessment:
    """Whether a skeleton's stored tails describe real bones.

    They do not when the median bone is point-like (shorter than
    :data:`MIN_MEDIAN_LENGTH_FRACTION` of ``size``), falls short of its
    child (median reach below :data:`MIN_MEDIAN_REACH`), or when nearly
    every bone points one way without pointing at its children
    (:data:`ONE_WAY_SHARE`: the directions are the importer's joint axis,
    not the bones). Bones point-like
    on their own (:data:`POINT_LIKE_FRACTION`) do not count toward the
    reach: one zero-length bone in a two-bone rig is that bone's problem
    (:func:`with_reliable_tails` mends it), not the armature's.

    Parameters
    ----------
    skeleton : Skeleton, every bone (deform or not)
    size : float, the character size (mesh bounding-box diagonal), > 0

    Returns
    -------
    TailAssessment
    """
    joints = skeleton.joints
    lengths = skeleton.bone_lengths
    child, _ = continued_children(joints, skeleton.parents)
    has_child = (child >= 0) & (lengths >= POINT_LIKE_FRACTION * size)
    median_fraction = float(np.median(lengths)) / size if len(lengths) else 0.0
    if has_child.any():
        reach = lengths[has_child] / np.linalg.norm(joints[child[has_child]] - joints[has_child], axis=1)
        median_reach = float(np.median(reach))
    else:
        median_reach = float("nan")
    units = _unit_rows(skeleton.tails - joints)
    matches = []
    for j, kids in enumerate(_children_apart(joints, skeleton.parents)):
        if len(kids):
            offsets = joints[kids] - joints[j]
            cosines = offsets @ units[j] / np.linalg.norm(offsets, axis=1)
            matches.append(bool(np.nanmax(cosines, initial=-1.0) >= DIRECTION_MATCH_COS))
    agreement = float(np.mean(matches)) if matches else float("nan")
    one_way = _one_way_share(units)
    short = median_fraction < MIN_MEDIAN_LENGTH_FRACTION
    falls_short = median_reach < MIN_MEDIAN_REACH  # False for NaN
    # Only with a measured disagreement: a lone column of parallel roots says nothing.
    along_one_axis = (one_way >= ONE_WAY_SHARE and len(matches) >= MIN_AGREEMENT_VOTES
                      and agreement < MIN_DIRECTION_AGREEMENT)
    length_words = f"median length {_percent(median_fraction)} of the character"
    reach_words = "" if np.isnan(median_reach) else f"reaching {_percent(median_reach)} of the way to their child"
    if short:
        reason = f"the stored bones are point-like ({length_words})"
    elif falls_short:
        reason = f"the stored bones stop short of their children ({reach_words}, {length_words})"
    elif along_one_axis:
        reason = (f"the stored bones point one way ({_percent(one_way)} of them), not at their children "
                  f"({_percent(agreement)} do): the importer's joint axis, not the bones")
    else:
        reason = f"the stored bones are real ({', '.join(w for w in (length_words, reach_words) if w)})"
    return TailAssessment(not (short or falls_short or along_one_axis), median_fraction, median_reach, agreement,
                          one_way, reason)


def _one_way_share(units: np.ndarray) -> float:
    """Largest share of the rows of ``units`` (unit directions, NaN rows
    for bones without one, left out) within :data:`ONE_WAY_COS` of one of
    them; 0 for fewer than :data:`MIN_ONE_WAY_BONES` directions."""
    units = units[np.isfinite(units).all(axis=1)]
    if len(units) < MIN_ONE_WAY_BONES:
        return 0.0
    # j x j cosines: an armature has at most a few hundred bones.
    return float((units @ units.T >= ONE_WAY_COS).mean(axis=1).max())


def with_reliable_tails(skeleton: Skeleton, size: float) -> tuple[Skeleton, TailDecision]:
    """The skeleton with tails fit to measure distances along.

    * Stored tails unusable (:func:`assess_stored_tails`): every bone gets
      :func:`derived_tails`, with the stored directions when they point at
      the children (:data:`MIN_DIRECTION_AGREEMENT`: then they are the
      original bones', only shrunk); a bone without any direction points up
      (+Z) for :data:`LONE_ROOT_LENGTH_FRACTION` of ``size``.
    * Usable: stored tails are kept, except point-like bones (shorter than
      :data:`POINT_LIKE_FRACTION` of ``size``) that a child continues,
      which end at that child. A point-like *deform* bone without one has
      nothing to point at and is refused; a point-like non-deform leaf (a
      control, an IK target) is kept as it is, as no weight is measured
      from it.

    Heads, names, parents and deform flags are unchanged.

    Parameters
    ----------
    skeleton : Skeleton, the full armature (not only its deform bones: the
        hierarchy through non-deform bones tells where deform bones point)
    size : float, the character size (mesh bounding-box diagonal); when not
        positive the extent of the skeleton is used

    Returns
    -------
    skeleton : Skeleton with the tails to use
    decision : TailDecision, which tails were derived and why

    Raises
    ------
    InputError when a point-like deform bone has no child to point at.
    """
    if not (np.isfinite(size) and size > 0):
        size = max(bounding_box_diagonal(np.vstack([skeleton.joints, skeleton.tails])), 1e-12)
    assessment = assess_stored_tails(skeleton, size)
    if not assessment.usable:
        stored_directions = skeleton.tails - skeleton.joints
        hint = stored_directions if assessment.directions_agree else None
        tails = derived_tails(skeleton.joints, skeleton.parents, hint)
        lone = np.isnan(tails).any(axis=1)
        fallback = _unit_rows(stored_directions[lone])
        fallback[np.isnan(fallback).any(axis=1)] = (0.0, 0.0, 1.0)
        tails[lone] = skeleton.joints[lone] + LONE_ROOT_LENGTH_FRACTION * size * fallback
        reason = assessment.reason
        if assessment.directions_agree:
            reason += "; their directions, which point at their children, are kept"
        return replace(skeleton, tails=tails), TailDecision(tuple(skeleton.names), True, reason)
    point_like = skeleton.bone_lengths < POINT_LIKE_FRACTION * size
    child, _ = continued_children(skeleton.joints, skeleton.parents)
    # A joint whose children are all mirror twins (a pelvis over the two
    # thighs) continues no child but is not a leaf: it keeps its parent's
    # line, as derived_tails gives it. Only a point-like deform leaf has no
    # direction at all.
    has_children = np.array([len(kids) > 0 for kids in _children_apart(skeleton.joints, skeleton.parents)], dtype=bool)
    between_twins = point_like & (child < 0) & has_children
    stuck = np.flatnonzero(point_like & (child < 0) & ~has_children & skeleton.deform)
    if len(stuck):
        names = [skeleton.names[j] for j in stuck]
        if len(names) == 1:
            message = f"Deform bone '{names[0]}' has zero length and no child to point at: give it a length"
        else:
            message = (f"Deform bones {listed_names(names, quoted=True)} have zero length and no child to point at: "
                       "give them a length")
        raise InputError(f"{message} in Edit Mode.")
    fixed = np.flatnonzero(point_like & ((child >= 0) | between_twins))
    if not len(fixed):
        return skeleton, TailDecision((), False, assessment.reason)
    tails = skeleton.tails.copy()
    continued = fixed[child[fixed] >= 0]
    tails[continued] = skeleton.joints[child[continued]]
    twin_parents = fixed[child[fixed] < 0]
    if len(twin_parents):
        tails[twin_parents] = derived_tails(skeleton.joints, skeleton.parents)[twin_parents]
        lone = twin_parents[np.isnan(tails[twin_parents]).any(axis=1)]
        tails[lone] = skeleton.joints[lone] + (0.0, 0.0, LONE_ROOT_LENGTH_FRACTION * size)
    names = tuple(skeleton.names[j] for j in fixed)
    one = len(names) == 1
    ending = "now end at the child they continue" if not len(twin_parents) else (
        "now end at the child they continue, or continue their parent's line between mirrored children")
    reason = (f"{listed_names(names, quoted=True)} {'is' if one else 'are'} shorter than "
              f"{100 * POINT_LIKE_FRACTION:.2g} % of the character and {ending}")
    return replace(skeleton, tails=tails), TailDecision(names, False, reason)
