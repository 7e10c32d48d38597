"""A body the landmark network reads as no biped or quadruped surely that is laid out as a biped.

The network's kind head knows the kinds of its training bodies. Kenney's
blocky minis (a head half their height over two stubs of legs) are like
none of them: it reads some as "other", up to 98 % sure, and no known biped
lies near enough to tell their kind (:func:`.rig_library.nearest_known_body`).
Its biped landmarks on them still describe the body a person sees: four
limbs and a trunk inside the solid, two legs apart, a head on top. This
module reads that layout (:func:`biped_layout`): a second opinion on the
kind, asked only when the network reads no kind surely and no known biped
lies near.

Each test is a property of an upright two-legged body, not a tuned score;
its numbers (:data:`MIN_INSIDE_SHARE`, :data:`MIN_TRUNK_RISE`) were checked on the training
characters (2026-12-07, each read with itself and its near-duplicates left
out of the rig library): no training fish, bird, quadruped or other body
passes (their best: Quaternius' mechs, legs apart and upright, with a limb
0.36 inside; 26 of the 51 quadrupeds pass all but the trunk, which lies
along y), while 122 of the 177
training humanoids do (the others fail on a limb mostly outside, a wrist
read past the fingertips: the test is strict, since a false biped is worse
than a free-form skeleton).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .joint_features import SolidDepth
from .networks.landmarks import BODY_KINDS

BIPED = BODY_KINDS[0]

#: The segments between landmarks that lie inside an upright biped's solid:
#: each arm's and leg's two bones, the trunk and the neck.
INSIDE_SEGMENTS = tuple(
    (start + side, end + side) for side in (".L", ".R")
    for start, end in (("shoulder", "elbow"), ("elbow", "wrist"), ("hip", "knee"), ("knee", "ankle"))
) + (("hips", "neck"), ("neck", "head"))
#: Points read along each segment, its ends included.
SEGMENT_SAMPLES = 11
#: Least share of a segment's points inside the solid: most of each bone,
#: its ends allowed out (a wrist read at the knuckles, a head at the crown).
MIN_INSIDE_SHARE = 0.6
#: An upright trunk rises at least this many times as much as it runs front to back.
MIN_TRUNK_RISE = 2.0


@dataclass(frozen=True)
class BipedLayout:
    """A body's biped landmarks found laid out as a biped (:func:`biped_layout`).

    Attributes
    ----------
    inside_share : float, the least share of any segment of
        :data:`INSIDE_SEGMENTS` inside the solid
    """

    inside_share: float
    kind: ClassVar[str] = BIPED

    @property
    def note(self) -> str:
        inside = "inside it" if self.inside_share >= 1.0 else f"at least {self.inside_share:.0%} inside it"
        return (f"its biped landmarks make an upright body (every limb, the trunk and the neck {inside}, the legs "
                "apart, the head on top), so it is taken for a biped")


def biped_layout(points: dict, solid: SolidDepth) -> BipedLayout | None:
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
    gaps = np.array([(knees[0] + knees[1]) / 2.0, (ankles[0] + ankles[1]) / 2.0])
    if np.any(solid.at(gaps) >= solid.inside_depth):
        return None
    along = np.linspace(0.0, 1.0, SEGMENT_SAMPLES)[:, None]
    shares = [float(np.mean(solid.at(points[start] * (1.0 - along) + points[end] * along) >= solid.inside_depth))
              for start, end in INSIDE_SEGMENTS]
    least = min(shares)
    return BipedLayout(least) if least >= MIN_INSIDE_SHARE else None
