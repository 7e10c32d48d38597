"""Props held at the hands, twin or not: a sword in each hand, a staff held in both, a mug in each hand.

:mod:`.props` tells a prop by its lacking a twin across the body's mirror
plane, so a mirrored pair (a sword in each hand) or a prop lying across the
plane (a staff held centred) stays part of the body: the skeleton then runs
the hand bones along the blades and the skin bends them. The shape alone
does not tell such a pair from the body's own twinned parts (KayKit's arms
and legs are objects of their own, wings and ears are thin and stick out);
where they touch the body does. Here:

1. **candidates** (:func:`hand_candidates`; :func:`thin_candidates`): objects that are small (under
   :data:`.props.PROP_AREA_SHARE` of the rest's area), **thin** (their
   smallest extent along their principal axes under :data:`THIN_RATIO` of
   their largest: a blade, a staff, a shield, a bow; not an arm, a leg, a
   hand or a head), sticking out of the rest (over :data:`.props.OUT_SHARE`
   of their area farther than :data:`.props.NEAR_SHARE` of its largest
   side) and touching it (within that distance somewhere);
2. **held at the hands** (:func:`held_at_hands`): the landmark network reads
   the body without the thin candidates; a candidate is held when most of where
   it touches the body (:data:`AT_HAND_SHARE`) lies within
   :data:`HAND_REACH` of the body's largest side of a wrist (the standard
   biped skeleton's, read from the mesh, so a raised arm's hand holds too),
   on a body read as a biped (surely, or by its nearest known body), and most of it reaches beyond that
   (:data:`BEYOND_HAND_SHARE`). Wings and ears touch the back and the head;
   a cape the neck; a hand, a glove or a gauntlet of its own (or both hands
   in one object, which is thin across the two) lies within a hand's reach
   of its wrist.

A small object that is not thin (a mug, a lantern, a ball: **thick**,
:func:`thick_candidates`) may be a body part of its own as well (KayKit's
arms, legs and heads, a hand, a foot), so it stays in the body the network
reads, and it is held only in a hand of the body's own: the body without the
thick objects at its wrists (a hand of its own and what that hand holds
alike) goes on at least :data:`HAND_PAST` of its largest side past the wrist
along the forearm (:func:`own_hands`; a hand of its own leaves the body
ending at the wrist), and the object's surface lies on the whole at least
:data:`HELD_PAST` past the wrist (in the hand, not a cuff around the
forearm).

The caller binds what is held wholly to the bone nearest its grip, the
mean of where it touches the body near the wrist that holds most of it (a
staff held in both hands goes to the hand holding more of it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..dataset.normalise import apply_transform
from ..errors import InputError
from ..geometry.bounding_box import largest_side
from ..geometry.closest_point import TriangleMeshQuery
from ..geometry.normals import triangle_double_areas
from ..progress import ProgressCallback, report
from ..skeleton.key_joints import key_joints
from ..types import Mesh
from .nearest_character import surface_points
from .networks.landmarks import BODY_KINDS
from .predict import JointVotes, predict_votes, skeleton_from_votes, sure_standard_kind
from .props import NEAR_SHARE, OUT_SHARE, PROP_AREA_SHARE, SAMPLES_PER_OBJECT, Prop

#: Thin: the smallest of an object's extents along its principal axes is
#: under this share of the largest (a blade 1.6 cm square and 53 cm long:
#: 0.03; a round shield: about 0.1; an arm, a hand, a boot: 0.25 and more).
THIN_RATIO = 0.2
#: A point touching the body is at a hand within this share of the body's
#: largest side of a wrist (the hand head): about a hand's length.
HAND_REACH = 0.1
#: A candidate is held when at least this share of where it touches the body lies at a hand ...
AT_HAND_SHARE = 0.5
#: ... and at least this share of its surface lies farther than :data:`HAND_REACH`
#: from that wrist: a blade, a staff or a shield reaches out of the hand; a
#: hand, a glove or a short claw does not (they stay the body's).
BEYOND_HAND_SHARE = 0.5
#: The wrists and elbows, left and right (core.skeleton.key_joints).
WRISTS = ("wrist.L", "wrist.R")
ELBOWS = ("elbow.L", "elbow.R")
#: A hand of the body's own goes on at least this share of the body's largest side past its wrist (a
#: human hand: about 0.05 of the height), within :data:`HAND_RADIUS` of the forearm's line; a thick
#: candidate is held only in such a hand ...
HAND_PAST = 0.03
#: ... counting the body's vertices within this share of the body's largest side of the forearm's line
#: (elbow through wrist): a hand, not a thigh beside a hanging hand ...
HAND_RADIUS = 0.04
#: ... and only when its surface lies on the whole at least this share past the wrist: a mug in the fist
#: (0.06 on the procedural biped), not a cuff or a bracelet at the wrist.
HELD_PAST = 0.015
#: Only a body read as a biped (surely, or by its nearest known body) has hands to hold with.
HOLDING_KIND = BODY_KINDS[0]


@dataclass(frozen=True, eq=False)
class Candidate:
    """An object of the character that may be held (:func:`hand_candidates`).

    Attributes
    ----------
    object_index : int, the object in the mesh's ``object_names``
    surface : (s, 3) float array, world space: points drawn on its surface
    touching : (k, 3) float array, world space: those within :data:`.props.NEAR_SHARE`
        of the body's largest side of the body's surface, k >= 1
    gap : float, the smallest distance from those points to the body's surface, scene units
    thin : bool, thin (a blade, a staff, a shield), or not (a mug: held only in a hand of the body's own)
    """

    object_index: int
    surface: np.ndarray
    touching: np.ndarray
    gap: float
    thin: bool = True


def thinness(points: np.ndarray) -> float:
    """The smallest extent of ``points`` along their principal axes over the largest (0 for a flat or
    straight set, 1 for a cube's corners); 1 for fewer than two distinct points."""
    centred = np.asarray(points, dtype=np.float64) - np.mean(points, axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    extents = np.ptp(centred @ axes.T, axis=0)
    return float(extents.min() / extents.max()) if extents.max() > 0 else 1.0


def _small_objects(mesh: Mesh, left_out: np.ndarray | None, told) -> tuple:
    """The objects of ``mesh`` small enough to be props (under :data:`.props.PROP_AREA_SHARE` of the
    rest's area), whole (none of their vertices ``left_out``) and not ``told``: ``(triangles, owner,
    points)``, the faces with area that are not left out, the object of each, and a dict mapping each
    small object's index to points drawn on its surface."""
    objects = len(mesh.object_names)
    vertices = mesh.vertices
    kept = np.ones(mesh.vertex_count, dtype=bool) if left_out is None else ~np.asarray(left_out, dtype=bool)
    triangles = mesh.triangles[kept[mesh.triangles].all(axis=1)]
    double_areas = triangle_double_areas(vertices, triangles)
    triangles, double_areas = triangles[double_areas > 0], double_areas[double_areas > 0]
    owner = np.searchsorted(mesh.object_offsets, triangles[:, 0], side="right") - 1
    area = 0.5 * np.bincount(owner, weights=double_areas, minlength=objects)
    points = {}
    for index in range(objects):
        whole = kept[mesh.object_slice(index)].all()
        if index in told or not whole or area[index] <= 0:
            continue
        if area[index] >= PROP_AREA_SHARE * (area.sum() - area[index] - sum(area[j] for j in told)):
            continue
        points[index] = surface_points(vertices, triangles[owner == index], SAMPLES_PER_OBJECT)
    return triangles, owner, points


def _touching(points: np.ndarray, query: TriangleMeshQuery, near: float) -> tuple[np.ndarray, float] | None:
    """Where ``points`` come within ``near`` of the body (``query``) and their smallest distance to it,
    when they touch it and mostly stick out of it (over :data:`.props.OUT_SHARE` farther); else None."""
    distances = query.closest(points).distances
    touching = distances <= near
    if touching.any() and np.mean(~touching) > OUT_SHARE:
        return points[touching], float(distances.min())
    return None


def hand_candidates(mesh: Mesh, left_out: np.ndarray | None = None, told=()) -> tuple[Candidate, ...]:
    """The objects of ``mesh`` that may be props held at the hands (module docstring, step 1): small,
    sticking out of the rest and touching it; thin ones (a blade, a staff, a shield) measured against the
    body without every small thin object, thick ones (a mug; ``thin`` False) each against that body
    without it too (they stay in the body the landmark network reads). A thick object touching only a
    small thin one is no candidate.

    Parameters
    ----------
    mesh : Mesh, world space, one or more objects
    left_out : (n,) bool array or None, vertices that are not the character (a ground plane, specks):
        an object with any of them is never a candidate, and they are not the body
    told : indices of objects already told as props (:mod:`.props`): neither candidates nor the body

    Returns
    -------
    tuple of Candidate in the objects' order; empty for a mesh of one object
    """
    if len(mesh.object_names) < 2:
        return ()
    told = set(int(index) for index in told)
    triangles, owner, small = _small_objects(mesh, left_out, told)
    thin = {index: points for index, points in small.items() if thinness(points) < THIN_RATIO}
    rest = ~np.isin(owner, list(told | set(thin)))
    if not small or not rest.any():
        return ()
    near = NEAR_SHARE * largest_side(mesh.vertices[np.unique(triangles[rest])])
    candidates = []
    if thin:
        query = TriangleMeshQuery(mesh.vertices, triangles[rest])
        for index, points in thin.items():
            touching = _touching(points, query, near)
            if touching is not None:
                candidates.append(Candidate(index, points, *touching))
    for index, points in small.items():
        body = triangles[rest & (owner != index)]
        if index in thin or not len(body):
            continue
        touching = _touching(points, TriangleMeshQuery(mesh.vertices, body), near)
        if touching is not None:
            candidates.append(Candidate(index, points, *touching, thin=False))
    return tuple(sorted(candidates, key=lambda candidate: candidate.object_index))


def thin_candidates(mesh: Mesh, left_out: np.ndarray | None = None, told=()) -> tuple[Candidate, ...]:
    """The thin ones of :func:`hand_candidates`."""
    return tuple(candidate for candidate in hand_candidates(mesh, left_out, told) if candidate.thin)


def thick_candidates(mesh: Mesh, left_out: np.ndarray | None = None, told=()) -> tuple[Candidate, ...]:
    """The thick ones of :func:`hand_candidates` (a mug, a lantern, a ball, but also KayKit's arms and legs)."""
    return tuple(candidate for candidate in hand_candidates(mesh, left_out, told) if not candidate.thin)


def _nearest_wrists(candidate: Candidate, points: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """For each point where ``candidate`` touches the body: the index of its nearest wrist of ``points``
    ((w, 3)) and whether it lies within ``reach`` of it."""
    distances = np.linalg.norm(candidate.touching[:, None, :] - points[None, :, :], axis=2)
    nearest = distances.argmin(axis=1)
    return nearest, distances[np.arange(len(nearest)), nearest] <= reach


def at_a_wrist(candidate: Candidate, wrists: dict, body_size: float) -> bool:
    """Whether most of where ``candidate`` touches the body (:data:`AT_HAND_SHARE`) lies within
    :data:`HAND_REACH` of the body's largest side of one of ``wrists``."""
    if not wrists:
        return False
    points = np.array(list(wrists.values()), dtype=np.float64)
    return bool(np.mean(_nearest_wrists(candidate, points, HAND_REACH * body_size)[1]) >= AT_HAND_SHARE)


def own_hands(wrists: dict, elbows: dict, body: np.ndarray, body_size: float) -> dict:
    """The wrists past which ``body`` (world vertices, without the objects at the wrists) goes on, a hand
    of its own: some vertex within :data:`HAND_RADIUS` of the body's largest side of the forearm's line
    (elbow through wrist) and within :data:`HAND_REACH` of the wrist lies at least :data:`HAND_PAST` of
    it beyond the wrist. A body whose hands are objects of their own ends at the wrists; the line keeps a
    thigh beside a hanging hand from counting. Returns a dict mapping each such wrist's name to the
    forearm's unit direction there."""
    hands = {}
    body = np.asarray(body, dtype=np.float64)
    for name, wrist in wrists.items():
        elbow = elbows.get(name.replace("wrist", "elbow"))
        if elbow is None or np.linalg.norm(wrist - elbow) <= 0:
            continue
        pointing = (wrist - elbow) / np.linalg.norm(wrist - elbow)
        offsets = body - wrist
        along = offsets @ pointing
        across = np.linalg.norm(offsets - along[:, None] * pointing, axis=1)
        near = (np.linalg.norm(offsets, axis=1) <= HAND_REACH * body_size) & (across <= HAND_RADIUS * body_size)
        if near.any() and along[near].max() >= HAND_PAST * body_size:
            hands[name] = pointing
    return hands


def held_at_hands(candidates, wrists: dict, body_size: float, hands: dict | None = None) -> tuple[Prop, ...]:
    """The candidates held at the hands (module docstring, step 2), as held props.

    Parameters
    ----------
    candidates : Candidates (:func:`hand_candidates`)
    wrists : dict mapping ``wrist.L`` and ``wrist.R`` (those found) to (3,) world points
    body_size : float, the largest side of the body without the thin candidates, scene units
    hands : dict or None, :func:`own_hands` of the body without the thick candidates at the wrists: the
        wrists with a hand of the body's own and the forearm's direction there; a thick candidate is
        held only at one of those, its surface lying on the whole at least :data:`HELD_PAST` of the body's
        largest side past the wrist (in the hand, not a cuff around the forearm). None: no thick candidate
        is held

    Returns
    -------
    tuple of Prop (``held`` set, ``grip`` where it touches the body near the wrist holding most of it)
    """
    if not wrists:
        return ()
    names = sorted(wrists)
    points = np.array([wrists[name] for name in names], dtype=np.float64)
    reach = HAND_REACH * body_size
    held = []
    for candidate in candidates:
        nearest, at_hand = _nearest_wrists(candidate, points, reach)
        if np.mean(at_hand) < AT_HAND_SHARE:
            continue
        holding = np.bincount(nearest[at_hand], minlength=len(names)).argmax()
        if candidate.thin:
            beyond = np.linalg.norm(candidate.surface - points[holding], axis=1) > reach
            if np.mean(beyond) < BEYOND_HAND_SHARE:
                continue
        else:
            pointing = (hands or {}).get(names[holding])
            past = None if pointing is None else (candidate.surface.mean(axis=0) - points[holding]) @ pointing
            if past is None or past < HELD_PAST * body_size:
                continue
        grip = candidate.touching[at_hand & (nearest == holding)].mean(axis=0)
        held.append(Prop(candidate.object_index, grip, candidate.gap, True))
    return tuple(held)


class BodyReading(NamedTuple):
    """The body :func:`props_held_at_hands_reading` read (the mesh without what is
    not the character, the props told and the thin candidates) and the
    prediction's votes on it, which a caller rigging that same body can use
    instead of reading it again."""

    body: Mesh
    votes: JointVotes


def props_held_at_hands(mesh: Mesh, left_out: np.ndarray | None = None, told=()) -> tuple[Prop, ...]:
    """The objects of ``mesh`` held at the hands (:func:`props_held_at_hands_reading`)."""
    return props_held_at_hands_reading(mesh, left_out, told)[0]


def props_held_at_hands_reading(mesh: Mesh, left_out: np.ndarray | None = None, told=(), *,
                                progress: ProgressCallback | None = None
                                ) -> tuple[tuple[Prop, ...], BodyReading | None]:
    """The objects of ``mesh`` held at the hands (both steps of the module
    docstring), and the body read to tell them.

    The landmark network reads the body (``mesh`` without ``left_out``, the
    ``told`` props and the thin candidates) only when there is a candidate; a
    body it cannot read (too few faces), or does not read as a biped (surely,
    or by its nearest known body), holds nothing. The body read is the one
    rigged when every thin candidate is held and no thick one is (and the
    caller tells no prop piece joined into a mesh).

    Parameters
    ----------
    mesh : Mesh, world space, one or more objects
    left_out : (n,) bool array or None, vertices that are not the character
    told : indices of objects already told as props
    progress : optional ProgressCallback (may raise Cancelled)

    Returns
    -------
    props : tuple of Prop, in the objects' order
    reading : BodyReading, or None when no body was read
    """
    report(progress, 0.0, "Looking for what the hands may hold")
    candidates = hand_candidates(mesh, left_out, told)
    if not candidates:
        return (), None
    rows = np.ones(mesh.vertex_count, dtype=bool) if left_out is None else ~np.asarray(left_out, dtype=bool)
    for index in {candidate.object_index for candidate in candidates if candidate.thin} | set(map(int, told)):
        rows[mesh.object_slice(index)] = False
    body = mesh.subset(rows)
    try:
        votes = predict_votes(body, progress)
    except InputError:
        return (), None
    reading = BodyReading(body, votes)
    if sure_standard_kind(votes.landmarks) != HOLDING_KIND:
        return (), reading
    size = largest_side(body.vertices)
    # A thin candidate is looked for at the wrists of the standard biped skeleton, read from the mesh (past
    # the forearm's narrowest section), which follow a raised or bent arm where the network's fall short.
    skeleton = skeleton_from_votes(votes, template=HOLDING_KIND, fingers=False, known_rig=False)
    found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
    thin = held_at_hands([candidate for candidate in candidates if candidate.thin],
                         {name: found[name] for name in WRISTS if name in found}, size)
    # A thick one at the network's own wrists, on which HAND_PAST and HELD_PAST were chosen.
    points = votes.landmarks.points_for(HOLDING_KIND)
    to_mesh = np.linalg.inv(votes.transform)
    wrists = {name: apply_transform(points[name], to_mesh)[0] for name in WRISTS if name in points}
    elbows = {name: apply_transform(points[name], to_mesh)[0] for name in ELBOWS if name in points}
    # Has the body hands of its own? Asked without every thick object at a wrist: a hand that is an object
    # of its own and what it holds alike.
    without = rows.copy()
    thick = [candidate for candidate in candidates if not candidate.thin]
    for candidate in thick:
        if at_a_wrist(candidate, wrists, size):
            without[mesh.object_slice(candidate.object_index)] = False
    hands = own_hands(wrists, elbows, mesh.vertices[without], size)
    held = thin + held_at_hands(thick, wrists, size, hands)
    return tuple(sorted(held, key=lambda prop: prop.object_index)), reading
