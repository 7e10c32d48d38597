"""Which way a character faces along the axis its mirror plane leaves: -y,
as the networks learnt, or +y; and what to do when the network reads it
better the other way round.

The mirror plane (:mod:`.orientation`) puts a character's left-right axis
at x, but says nothing of which of -y and +y its front is. Two cues, in
this order (:func:`facing`):

1. **Shape cues no network reads**, so the training characters measure
   them as fairly as new ones: a biped's toes (:func:`toe_reach`: its feet
   reach farther ahead of its shins than behind) and a quadruped's head
   end (:func:`head_end_rise`: the end of the body its head is on stands
   higher than its hind end).
2. **The landmark network reading it far more surely as a biped or
   quadruped turned half a turn** (:data:`TURNED_CONFIDENCE_GAIN`): it
   learnt bodies facing -y, and a dog facing +y reads as "other".

A third cue, a biped's feet reaching 1.5 times as far behind the network's
ankles as ahead, was dropped (2026-12-06): it never decided a training
character's facing (every third, as loaded and turned: the same 216
readings without it), and on validation characters it turned `Zombie_Male`
and the cyberpunk `Character` half a turn whichever way they were given.

A biped or quadruped whose shape cue does not tell, read about as surely
either way round, is taken to face -y as it was given, and the report says
so (:attr:`Facing.untold_kind`; Quaternius' animated pack, trouser legs to
the ground, given facing +Y is rigged back to front).

A body kept facing -y by its shape that the network reads far more surely
from behind (one unlike its training characters: the network saw its back
as a front) takes that reading, turned back with its sides swapped
(:func:`from_behind`), unless that reading puts a quadruped's head at the
other end than its shape does.

Everything here is in the normalised frame (feet at z = 0, largest side 1).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..skeleton.naming import mirror_name
from ..types import Mesh
from .joint_features import VERTEX_VECTORS, JointGraph
from .standard_skeleton import BIPED, OTHER, QUADRUPED, Landmarks, standard_confidence
from .up_features import area_centroids

#: Turned half a turn, a character is taken to face the other way when the
#: landmark network is at least this much surer there that it is a biped or
#: a quadruped (it learnt bodies facing -y: a dog facing +y reads as "other").
TURNED_CONFIDENCE_GAIN = 0.25


def half_turned(graph: JointGraph) -> JointGraph:
    """The graph of the character turned half a turn about the vertical axis
    through its box centre (x = y = 0 of the normalised frame): the x and y
    of every position and direction change sign; depths and edges stay."""
    flip = np.ones(graph.vertex_features.shape[1], dtype=graph.vertex_features.dtype)
    for start in VERTEX_VECTORS:
        flip[start:start + 2] = -1
    return replace(graph, vertices=graph.vertices * np.array([-1.0, -1.0, 1.0]),
                   vertex_features=graph.vertex_features * flip)


def from_behind(turned: Landmarks) -> Landmarks:
    """The landmarks read on the character turned half a turn
    (:func:`half_turned`), brought back to it as it stands: every point
    turned back and left and right swapped. Read from behind, a character
    facing -y looks to the network like one facing it, so it took the
    character's right for its left; the positions themselves hold."""
    flip = np.array([-1.0, -1.0, 1.0])
    return Landmarks({mirror_name(name): np.asarray(point) * flip for name, point in turned.points.items()},
                     dict(turned.kind_probabilities))


#: The toes' cue of which way a biped faces (:func:`toe_reach`): its feet
#: are the lowest band of this share of its height, its shins the band
#: between these shares.
FOOT_BAND = 0.05
SHIN_BAND = (0.12, 0.25)
#: A biped whose feet reach this much farther (share of its height) ahead of
#: its shins than behind faces that way, whatever the landmark network reads;
#: nearer even, the toes do not tell. Measured on the training humanoids'
#: proxies as they are, facing -y (2026-11-26): the feet reach farther toward
#: -y on 175 of 178 (median 0.09, 5th percentile 0.027); at 0.02, 171 say -y,
#: 2 say +y, 5 do not tell. No network reads this cue, so the training
#: characters measure it as fairly as new ones.
TOE_REACH_SURE = 0.02


def toe_reach(surface: Mesh) -> float | None:
    """How much farther a biped's feet reach toward -y than toward +y from
    the middle of its shins, averaged over its two legs, as a share of its
    height (positive: it faces -y); None when a leg has no foot or shin.
    ``surface`` is upright in the normalised frame, its mirror plane across
    x; the legs are the two sides of it. Toes point forward: a foot reaches
    farther ahead of the leg above it than its heel does behind."""
    points, shares = area_centroids(surface.vertices, surface.triangles)
    heights = points[:, 2] - points[:, 2].min()
    height = float(heights.max())
    across = points[:, 0] - 0.5 * (points[:, 0].min() + points[:, 0].max())
    reaches = []
    for sign in (1.0, -1.0):
        side = sign * across > 0.01 * height
        foot = side & (heights < FOOT_BAND * height)
        shin = side & (heights > SHIN_BAND[0] * height) & (heights < SHIN_BAND[1] * height)
        if foot.sum() < 3 or shin.sum() < 3 or shares[shin].sum() <= 0.0:
            return None
        middle = float(np.average(points[shin, 1], weights=shares[shin]))
        reaches.append((middle - points[foot, 1].min()) - (points[foot, 1].max() - middle))
    return float(np.mean(reaches)) / max(height, 1e-12)


#: A quadruped's head end: the area-weighted mean height of the surface in
#: this share of the body's length at one end of y, against the same at the
#: other end (:func:`head_end_rise`).
END_SHARE = 0.15
#: A quadruped (read so either way, and a biped neither way) whose one end
#: stands this much higher (share of its height) than the other faces that
#: way. Measured on the 51 training quadrupeds as they are, facing -y
#: (2026-11-26): the front end is the higher by at least this on every one
#: (neck and head up, the rump falling to the tail). No network reads it, so
#: the training characters measure it fairly; on the 14 validation
#: quadrupeds the front end is higher on 13, by more than this on 9, and
#: the back end higher by more than this on none.
HEAD_END_SURE = 0.05


def head_end_rise(surface: Mesh) -> float | None:
    """How much higher the -y end of a body stands than its +y end: the
    difference of the area-weighted mean heights of the surface in the
    :data:`END_SHARE` of its length at each end, as a share of its height
    (positive: the -y end is the higher, where a quadruped's head is); None
    when an end holds no area (a stray zero-area face there)."""
    points, shares = area_centroids(surface.vertices, surface.triangles)
    heights = points[:, 2] - points[:, 2].min()
    along = points[:, 1]
    low, high = float(along.min()), float(along.max())
    length = high - low
    front = along <= low + END_SHARE * length
    back = along >= high - END_SHARE * length
    if shares[front].sum() <= 0.0 or shares[back].sum() <= 0.0:
        return None
    rise = np.average(heights[front], weights=shares[front]) - np.average(heights[back], weights=shares[back])
    return float(rise) / max(float(heights.max()), 1e-12)


@dataclass(frozen=True)
class Facing:
    """How a character is taken to face (:func:`facing`).

    Attributes
    ----------
    turn : bool, it faces +y: it is turned half a turn for the prediction
    read_from_behind : bool, facing -y (once turned, if it is), it is read from
        behind (:func:`from_behind`): the reading of it turned half a turn, or,
        when it is turned, the reading of it as it was given
    reason : str, what told it, for the report ("its toes point toward +Y", "its toes point that way")
    front_untold : bool, nothing told its front: read neither way as a biped or quadruped, it is taken
        to face -y as it was given (:func:`front_untold_note`)
    untold_kind : str or None, the kind it is read as (one way round or both) when neither its shape cue
        (:func:`front_cue`) nor the network's surer reading told its front: taken to face -y as it was
        given, which the report must say (a biped with stub feet given facing +Y is rigged back to front)
    """

    turn: bool
    read_from_behind: bool = False
    reason: str = ""
    front_untold: bool = False
    untold_kind: str | None = None


def front_untold_note(front: str, told_kind: str | None = None, read_as: str | None = None) -> str:
    """The report's note when nothing tells which way a body faces
    (``front``: the mesh-space axis it was taken to face, '-Y', '+X'...);
    ``told_kind``: the kind a body's nearest known body or its layout makes
    it (biped, quadruped), whose shape cue (:func:`front_cue`) does not
    tell either; ``read_as``: the kind the landmark network reads it as,
    about as surely either way round, whose shape cue does not tell
    (:attr:`Facing.untold_kind`). Its shape alone does not: a linear score of the
    front-to-back profile (area, height, width and spread per band) told the
    front of 14 of the 23 validation fish, flyers and monsters
    (``scripts/check_front_profile.py``; docs/rigging.md, *Orientation*)."""
    if read_as is not None:
        cue = "its toes do not tell" if read_as == BIPED else "neither end of it stands higher"
        return (f"Which way the character faces could not be told (the landmark network reads it as a {read_as} about "
                f"as surely either way round, and {cue}): it was taken to face {front} of its own space, so its .L "
                "bones lie on its left seen so. If it faces another way, turn it to face -Y and predict again.")
    if told_kind is not None:
        cue = "its toes do not tell" if told_kind == BIPED else "neither end of it stands higher"
        return (f"Which way the character faces could not be told (the landmark network reads it as neither a biped "
                f"nor a quadruped either way round, and {cue}): it was taken to face {front} of its "
                "own space, so its .L bones lie on its left seen so. If it faces another way, turn it to face -Y and "
                "predict again.")
    return (f"Which way the character faces could not be told (it reads as neither a biped nor a quadruped, either "
            f"way round): it was taken to face {front} of its own space, so its .L bones lie on its left seen so, and "
            "a chain running away from that end is its tail. If it faces another way, turn it to face -Y and predict "
            "again.")


@dataclass(frozen=True)
class FrontCue:
    """The shape's cue of which way a body faces (:func:`front_cue`).

    Attributes
    ----------
    reach : float or None, positive when it faces -y; None when there is no cue
    sure : float, the reach beyond which the cue tells
    toward, that_way : str, the report's words for the end it faces ("its toes point toward" +Y; "its toes
        point that way")
    """

    reach: float | None
    sure: float
    toward: str
    that_way: str

    @property
    def tells(self) -> bool:
        return self.reach is not None and abs(self.reach) > self.sure


def front_cue(surface: Mesh, kind: str) -> FrontCue:
    """The shape's cue of which way a body of ``kind`` faces: its toes
    (:func:`toe_reach`, :data:`TOE_REACH_SURE`) for a biped, its head end
    (:func:`head_end_rise`, :data:`HEAD_END_SURE`) for a quadruped."""
    if kind == BIPED:
        return FrontCue(toe_reach(surface), TOE_REACH_SURE, "its toes point toward", "its toes point that way")
    return FrontCue(head_end_rise(surface), HEAD_END_SURE, "its head end is toward", "its head end is that way")


def facing(landmarks: Landmarks, turned: Landmarks, surface: Mesh) -> Facing:
    """Which way a character faces (see the module docstring).

    Parameters
    ----------
    landmarks : the landmark network's reading of the character as it is
    turned : its reading of the character turned half a turn (:func:`half_turned`)
    surface : the proxy the readings were made on, normalised (its mirror plane across x)
    """
    kinds = (landmarks.kind, turned.kind)
    surer_turned = standard_confidence(turned) >= standard_confidence(landmarks) + TURNED_CONFIDENCE_GAIN
    surer_as_given = standard_confidence(landmarks) >= standard_confidence(turned) + TURNED_CONFIDENCE_GAIN
    shape_kind = BIPED if BIPED in kinds else QUADRUPED if QUADRUPED in kinds else None
    cue = front_cue(surface, shape_kind) if shape_kind is not None else None
    shape = (cue.reach < 0.0, cue.toward, cue.that_way) if cue is not None and cue.tells else None
    if shape is not None:
        backward, toward, that_way = shape
        if backward:
            # Turned to face -y, it is seen from behind as it was given: that reading, if far surer, is the one kept.
            return Facing(True, surer_as_given and _keeps_the_head_end(from_behind(landmarks), shape_kind),
                          f"{toward} +Y")
        behind = surer_turned and _keeps_the_head_end(from_behind(turned), shape_kind)
        return Facing(False, behind, that_way if behind else "")
    if surer_turned:
        kind = f"a {turned.kind}" if turned.kind != OTHER else "a biped or quadruped"
        return Facing(True, reason=f"turned, it reads more surely as {kind}")
    return Facing(False, front_untold=kinds == (OTHER, OTHER), untold_kind=None if surer_as_given else shape_kind)


def _keeps_the_head_end(reading: Landmarks, shape_kind: str) -> bool:
    """Whether a reading from behind (:func:`from_behind`, facing -y) keeps
    the head where the shape put it: a biped's head is above either way (the
    reading only swaps its sides); a quadruped's must lie toward -y of its
    hips, the head end its shape told (:func:`head_end_rise`). Read from
    behind, a network may take a quadruped's tail end for its head (a
    stegosaurus, whose back plates stand highest, read with its head on the
    tail tip) or find its head where it is, only more surely (an elephant)."""
    return shape_kind != QUADRUPED or bool(reading.points["head"][1] < reading.points["hips"][1])
