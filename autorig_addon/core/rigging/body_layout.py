"""A body the landmark network reads as no biped or quadruped surely that is laid out as one.

The network's kind head knows the kinds of its training bodies. Kenney's
blocky minis (a head half their height over two stubs of legs) are like
none of them: it reads some as "other", up to 98 % sure, and no known biped
lies near enough to tell their kind (:func:`.rig_library.nearest_known_body`).
OpenClonk's wipf, a round rodent on four short legs, it reads as "other" too
(71 % sure). Its landmarks on such bodies still describe the body a person
sees. This module reads that layout: a second opinion on the kind, asked
only when the network reads no kind surely and no known biped lies near.

* :func:`biped_layout`: four limbs and a trunk inside the solid, two legs
  apart, a head on top.
* :func:`quadruped_layout` (the front legs are the landmarks' arms, the hind
  legs its legs): four legs inside the solid, each pair apart, the front feet
  ahead of the hind feet and level with them, the trunk above the feet and
  along the body's length, the neck at its front.

Each test is a property of such a body, not a tuned score; its numbers were
checked on the training characters (each read with itself and its
near-duplicates left out of the rig library).

Biped (2026-12-07, :data:`MIN_INSIDE_SHARE`, :data:`MIN_TRUNK_RISE`): no
training fish, bird, quadruped or other body passes (their best: Quaternius'
mechs, legs apart and upright, with a limb 0.36 inside; 26 of the 51
quadrupeds pass all but the trunk, which lies along y), while 122 of the 177
training humanoids do (the others fail on a limb mostly outside, a wrist
read past the fingertips: the test is strict, since a false biped is worse
than a free-form skeleton).

Quadruped (2026-12-07, later; :data:`MIN_LEG_INSIDE_SHARE`,
:data:`MAX_FEET_LEVEL_GAP`): 41 of the 51 training quadrupeds pass, and none
of the 177 humanoids, 42 fish, 4 birds or 49 other bodies. Of these, only
three pass all tests but one: the shark and the T. rex fail the legs' share
inside (0 and 0.09), the velociraptor the feet's level: its "front feet" are
its hands, held 0.83 of the trunk's height above its feet (the quadrupeds'
front and hind feet: 0.21 apart at the median, 0.41 at most).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..skeleton.naming import LEFT_SUFFIX, RIGHT_SUFFIX
from .joint_features import SolidDepth
from .networks.landmarks import BODY_KINDS

BIPED, QUADRUPED = BODY_KINDS[:2]

#: Each side's two arm bones and two leg bones (a quadruped's front and hind legs).
LIMB_SEGMENTS = tuple(
    (start + side, end + side) for side in (LEFT_SUFFIX, RIGHT_SUFFIX)
    for start, end in (("shoulder", "elbow"), ("elbow", "wrist"), ("hip", "knee"), ("knee", "ankle"))
)
#: The trunk, from the hips to the neck.
TRUNK = ("hips", "neck")
#: The segments between landmarks that lie inside an upright biped's solid:
#: each arm's and leg's two bones, the trunk and the neck.
INSIDE_SEGMENTS = LIMB_SEGMENTS + (TRUNK, ("neck", "head"))
#: The segments that lie inside a quadruped's solid: each leg's two bones and
#: the trunk (the head may reach out past the neck: a snout, a beak).
QUADRUPED_INSIDE_SEGMENTS = LIMB_SEGMENTS + (TRUNK,)
#: Points read along each segment, its ends included.
SEGMENT_SAMPLES = 11
#: Least share of a segment's points inside the solid: most of each bone,
#: its ends allowed out (a wrist read at the knuckles, a head at the crown).
MIN_INSIDE_SHARE = 0.6
#: An upright trunk rises at least this many times as much as it runs front to back.
MIN_TRUNK_RISE = 2.0
#: Least share of a quadruped's leg bones and trunk inside the solid: half,
#: looser than a biped's limbs. Animals' legs are thin, a few cells of the
#: solid across, so a bone read a little off the leg's axis leaves it sooner
#: (the rat of Quaternius' enemies, read as no kind, has a leg only 0.45
#: inside and is still refused); the training bodies that are not quadrupeds
#: and pass every other test have legs at most 0.09 inside.
MIN_LEG_INSIDE_SHARE = 0.5
#: A quadruped's trunk runs along its length (y) at least this many times as
#: much as it rises or falls.
MIN_TRUNK_RUN = 1.0
#: A quadruped's front and hind feet (the wrists' and the ankles' middles)
#: lie at most this share of the trunk's height (above the lower pair) apart
#: in height: all four stand on the ground.
MAX_FEET_LEVEL_GAP = 0.5


@dataclass(frozen=True)
class BodyLayout:
    """A body's landmarks found laid out as a ``kind`` (:func:`biped_layout`, :func:`quadruped_layout`).

    Attributes
    ----------
    kind : str, ``"biped"`` or ``"quadruped"``
    inside_share : float, the least share of any of the kind's segments inside the solid
    """

    kind: str
    inside_share: float

    @property
    def note(self) -> str:
        inside = "inside it" if self.inside_share >= 1.0 else f"at least {self.inside_share:.0%} inside it"
        if self.kind == BIPED:
            return (f"its biped landmarks make an upright body (every limb, the trunk and the neck {inside}, the legs "
                    "apart, the head on top), so it is taken for a biped")
        return (f"its quadruped landmarks make a four-legged body (every leg and the trunk {inside}, each pair of "
                "feet apart, the front and hind feet level, the trunk above them along the body's length), so it is "
                "taken for a quadruped")


def _least_inside(points: dict, solid: SolidDepth, segments: tuple) -> float:
    """The least share, over ``segments``, of the :data:`SEGMENT_SAMPLES` points along each inside ``solid``."""
    along = np.linspace(0.0, 1.0, SEGMENT_SAMPLES)[:, None]
    return min(float(np.mean(solid.at(points[start] * (1.0 - along) + points[end] * along) >= solid.inside_depth))
               for start, end in segments)


def _apart(solid: SolidDepth, *pairs) -> bool:
    """Whether the middle of each pair of points lies outside ``solid`` (two limbs, not one column)."""
    middles = np.array([(first + second) / 2.0 for first, second in pairs])
    return bool(np.all(solid.at(middles) < solid.inside_depth))


def biped_layout(points: dict, solid: SolidDepth) -> BodyLayout | None:
    """The layout of a body's biped landmarks (``points`` by role, the
    normalised frame: up +z, facing -y) in its ``solid`` when they make an
    upright biped; else None. They do when

    - at least :data:`MIN_INSIDE_SHARE` of each segment of :data:`INSIDE_SEGMENTS` lies inside the solid;
    - the middle between the knees and the middle between the ankles lie outside it (two legs, not one column);
    - head, neck, hips, knees and ankles come in that order from the top;
    - the trunk (hips to neck) rises at least :data:`MIN_TRUNK_RISE` times as much as it runs along y
      (a quadruped's lies along its length).
    """
    points = {name: np.asarray(point, dtype=np.float64) for name, point in points.items()}
    knees, ankles = (points["knee.L"], points["knee.R"]), (points["ankle.L"], points["ankle.R"])
    heights = [points["head"][2], points["neck"][2], points["hips"][2]]
    if not (heights[0] > heights[1] > heights[2] > max(k[2] for k in knees)
            and min(k[2] for k in knees) > max(a[2] for a in ankles)):
        return None
    trunk = points["neck"] - points["hips"]
    if trunk[2] < MIN_TRUNK_RISE * abs(trunk[1]):
        return None
    if not _apart(solid, knees, ankles):
        return None
    least = _least_inside(points, solid, INSIDE_SEGMENTS)
    return BodyLayout(BIPED, least) if least >= MIN_INSIDE_SHARE else None


def quadruped_layout(points: dict, solid: SolidDepth) -> BodyLayout | None:
    """The layout of a body's landmarks (as :func:`biped_layout` takes them;
    the arms' landmarks are the front legs') when they make a quadruped
    facing -y; else None. They do when

    - at least :data:`MIN_LEG_INSIDE_SHARE` of each segment of :data:`QUADRUPED_INSIDE_SEGMENTS` lies inside;
    - each leg's joints come in order from the top (shoulder, elbow, wrist; hip, knee, ankle);
    - the middle between the front feet and the middle between the hind feet lie outside the solid;
    - the front feet lie ahead of (toward -y) the hind feet, and the two pairs' middles at most
      :data:`MAX_FEET_LEVEL_GAP` of the trunk's height above the lower pair apart in height;
    - the trunk (hips to neck) lies above every foot and runs toward -y at least :data:`MIN_TRUNK_RUN`
      times as much as it rises or falls (the neck at the front).
    """
    points = {name: np.asarray(point, dtype=np.float64) for name, point in points.items()}
    for side in (LEFT_SUFFIX, RIGHT_SUFFIX):
        if not (points["shoulder" + side][2] > points["elbow" + side][2] > points["wrist" + side][2]
                and points["hip" + side][2] > points["knee" + side][2] > points["ankle" + side][2]):
            return None
    front_feet, hind_feet = (points["wrist.L"], points["wrist.R"]), (points["ankle.L"], points["ankle.R"])
    front, hind = (front_feet[0] + front_feet[1]) / 2.0, (hind_feet[0] + hind_feet[1]) / 2.0
    trunk = points["neck"] - points["hips"]
    if not (trunk[1] < 0.0 and -trunk[1] >= MIN_TRUNK_RUN * abs(trunk[2]) and front[1] < hind[1]):
        return None
    trunk_low = min(points["hips"][2], points["neck"][2])
    if trunk_low <= max(foot[2] for foot in front_feet + hind_feet):
        return None
    if abs(front[2] - hind[2]) > MAX_FEET_LEVEL_GAP * (trunk_low - min(front[2], hind[2])):
        return None
    if not _apart(solid, front_feet, hind_feet):
        return None
    least = _least_inside(points, solid, QUADRUPED_INSIDE_SEGMENTS)
    return BodyLayout(QUADRUPED, least) if least >= MIN_LEG_INSIDE_SHARE else None
