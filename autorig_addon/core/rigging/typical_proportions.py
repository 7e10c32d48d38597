"""Short legs and big heads read again: the landmark network on a biped
stretched to typical proportions.

The landmark network (:mod:`.networks.landmarks`) learnt bodies whose crotch
sits mostly at 32 to 52 % of their height (the training families' medians;
0 A.D.'s humans, most of them, at 43 %; KayKit's three at 16 %) and whose
neck is narrowest at about 84 %. On a body far from that it lays the trunk
out where those bodies have it:

* **short legs** (Quaternius' animated and monster packs, crotch at 19 to
  31 %): the hips, the hip joints, the shoulders and the head 0.1 to 0.2 of
  the height too high, while the knees and ankles, read from the legs
  themselves, stay in place. The crotch tells it: the first point inside
  the body straight above the middle of the knees (:func:`crotch_height`);
  the landmarks put the hip joints more than :data:`HIP_ABOVE_CROTCH`
  crotch heights above it.
* **big heads** (Quaternius' animated characters: the head a third of the
  height, the neck at 58 to 67 %): the neck, the head, the shoulders and the
  hips 0.1 to 0.17 too high, even once the legs are stretched. The neck
  tells it: the section of the trunk that is much narrower than both the
  head above it and the chest or shoulders below (:func:`neck_pinch`); the
  landmarks put the neck more than :data:`NECK_ABOVE_PINCH` of the height
  above it.

The body is then mapped vertically, piecewise linearly
(:class:`HeightMap`), so that its crotch sits at :data:`TYPICAL_CROTCH_SHARE`
of its height and, for a big head, its neck at :data:`TYPICAL_NECK_SHARE`;
read again; and the new landmarks mapped back. The map is increasing, so
every landmark keeps its place along the limb it lies in.

Everything here is in the normalised frame (feet at z = 0, largest side 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..dataset.normalise import apply_transform, normalisation_transform
from ..types import Mesh
from .joint_features import SolidDepth

#: The landmarks' hip joints lie more than this many crotch heights above
#: the crotch: the network read the legs as longer than they are. Chosen on
#: every third training character (108, 2026-11-26): at 0.6 no training
#: biped is read again (at 0.4 and 0.5, 4 are, with no change of score; at
#: 0.3, 16, and their key joints get worse: 92.7 % to 90.7 %).
HIP_ABOVE_CROTCH = 0.6
#: The crotch height, as a share of the body's height, the body is
#: stretched to: the median of the training families' median crotch shares
#: (0.443; 0 A.D.'s humans 0.426, Quaternius' 0.479, Nexuiz 0.518, Red
#: Eclipse 0.46, OpenClonk 0.32, SuperTuxKart 0.32, KayKit 0.16).
TYPICAL_CROTCH_SHARE = 0.44
#: The crotch is looked for between the knees and this share of the height:
#: above it the line meets the chest or the head of a character whose legs
#: the landmarks did not find.
CROTCH_SEARCH_TOP = 0.8

#: The neck is looked for above this share of the way from the crotch to
#: the top (below it lie the waist and the belly) ...
NECK_SEARCH_FROM = 0.3
#: ... and below this share of the height (the crown tapers to nothing).
NECK_SEARCH_TO = 0.95
#: A pinch is a neck when its section is at most this share of the widest
#: section both above it (the head) and between it and the crotch (the chest,
#: or the shoulders and arms). Chosen on the training humanoids' own rigs
#: (154, 2026-12-06): of the 29 pinches this sharp, the pinch lies a median
#: 0.036 of the height from the artist's neck joint (above it: artists start
#: the neck at its base), 0.088 at most (Quaternius' mech `Stan`); softer
#: ones include waists below the chest (`Medieval`, 0.40: 0.143 below).
NECK_PINCH = 0.35
#: The landmarks' neck lies more than this share of the height above the
#: pinch: the network read the head as smaller than it is. No held-out
#: training character is read again at 0.05 (54, the rig library left
#: out).
NECK_ABOVE_PINCH = 0.05
#: The pinch's height, as a share of the body's height, a big head's body is
#: mapped to: the median over the 29 training humanoids with a pinch that
#: sharp (0.839; their artists' neck joints: 0.815).
TYPICAL_NECK_SHARE = 0.84


def crotch_height(solid: SolidDepth, knees: np.ndarray, top: float, enclosed=None) -> float | None:
    """The height of the first point inside the body on the vertical line
    through the middle of the knees (``knees``: (2, 3), left and right),
    above them and below ``CROTCH_SEARCH_TOP * top``; None when there is
    none (legs that meet nowhere, a long robe's open bottom).

    Inside is at least half a cell deep in the solid or, given ``enclosed``
    (``(k, 3) points -> (k,) bool``, :func:`.quality.enclosed_by` of the
    normalised proxy), a point the solid reads nothing at (depth 0) that the
    surface encloses: the solid of a trunk with a hole in it (a low-poly body
    whose legs are objects of their own) leaks to a shell, and the line would
    meet it only at the shoulders. Not when the line starts enclosed: legs
    standing inside a robe or a skirt open at the bottom are enclosed from
    the hem up, and that is no crotch."""
    middle = np.mean(np.asarray(knees, dtype=np.float64), axis=0)
    heights = np.arange(middle[2], CROTCH_SEARCH_TOP * top, 0.5 * solid.cell_size)
    if not len(heights):
        return None
    line = np.column_stack([np.zeros_like(heights), np.full_like(heights, middle[1]), heights])
    depth = solid.at(line)
    inside = depth >= solid.inside_depth
    first = int(np.argmax(inside)) if inside.any() else len(heights)
    if enclosed is not None and first > 0:
        # Only the points below the solid's first one can come first; the winding number costs per point.
        hollow = np.asarray(enclosed(line[:first]), dtype=bool) & (depth[:first] <= 0.0)
        if hollow.any() and not hollow[0]:
            first = int(np.argmax(hollow))
    return float(heights[first]) if first < len(heights) else None


def hip_joints_raised_to_crotch(points: dict, solid: SolidDepth, top: float, enclosed=None) -> tuple[dict, float]:
    """A biped's landmarks with the hip joints, and the hips with them,
    raised together until the middle of the hip joints is at the crotch
    (:func:`crotch_height`) when the network put it below; also how far they
    were raised (0 when not). A thigh's head
    lies in the pelvis, above the fork of the legs: of the 163 training
    bipeds (of 177) whose crotch is found, the artists put the hip joints below it on
    6 (four of them Nexuiz's, 0.012 to 0.125 of the height below). Raised so,
    4 training bipeds change, 2 of them with more key joints right and none
    with fewer (2026-12-07); on chibi bodies unlike the training ones (a big
    head on a short trunk and short legs, Kenney's minis) the network read
    the pelvis 0.03 to 0.08 too low, under the trunk."""
    crotch = crotch_height(solid, np.array([points["knee.L"], points["knee.R"]]), top, enclosed)
    if crotch is None:
        return points, 0.0
    lift = crotch - 0.5 * (points["hip.L"][2] + points["hip.R"][2])
    if not lift > 0.0:
        return points, 0.0
    points = dict(points)
    for name in ("hip.L", "hip.R", "hips"):
        points[name] = points[name] + np.array([0.0, 0.0, lift])
    return points, float(lift)


def trunk_sections(solid: SolidDepth) -> tuple[np.ndarray, np.ndarray]:
    """The heights of the solid's voxel layers (k,) and, in each, the area
    of the largest piece crossing the midline x = 0 (k,): the trunk, the
    neck or the head, with the arms where they join it (0 where nothing
    crosses the midline)."""
    occupied = solid.depth > 0
    # Pieces are connected within a layer only, so each layer's pieces are labelled apart.
    within_layer = np.zeros((3, 3, 3), dtype=bool)
    within_layer[:, :, 1] = True
    labels, _ = ndimage.label(occupied, structure=within_layer)
    cells = np.bincount(labels.ravel())
    cells[0] = 0
    heights = solid.origin[2] + (np.arange(occupied.shape[2]) + 0.5) * solid.cell_size
    midline = int(np.floor(-solid.origin[0] / solid.cell_size))
    if not 0 <= midline < occupied.shape[0]:
        return heights, np.zeros_like(heights)  # the solid lies wholly on one side of the midline
    return heights, cells[labels[midline]].max(axis=0) * solid.cell_size ** 2


def neck_pinch(solid: SolidDepth, crotch: float, top: float) -> float | None:
    """The height of the neck: the narrowest trunk section
    (:func:`trunk_sections`) between :data:`NECK_SEARCH_FROM` of the way
    from the ``crotch`` to the ``top`` and :data:`NECK_SEARCH_TO` of the
    height, when it is a pinch (:data:`NECK_PINCH`) between a head and a
    chest; else None (a monster whose head runs into its body). Only
    layers the trunk crosses count, up to the highest: above the crown,
    ears, horns or raised arms leave the midline empty, which is no neck."""
    heights, areas = trunk_sections(solid)
    crossed = np.flatnonzero(areas > 0.0)
    if not len(crossed):
        return None
    searched = np.flatnonzero((heights > crotch + NECK_SEARCH_FROM * (top - crotch)) & (heights < NECK_SEARCH_TO * top)
                              & (areas > 0.0) & (heights < heights[crossed[-1]]))
    if not len(searched):
        return None
    neck = searched[np.argmin(areas[searched])]
    below = areas[(heights > crotch) & (heights < heights[neck])]
    if not len(below):
        return None
    head, chest = areas[neck:].max(), below.max()
    return float(heights[neck]) if areas[neck] <= NECK_PINCH * min(head, chest) else None


@dataclass(frozen=True)
class HeightMap:
    """The increasing piecewise-linear map on heights that sends each of
    ``heights`` to the matching one of ``targets`` (both strictly
    increasing, from 0 to the top, which they keep); beyond them it goes on
    along its end pieces (a landmark read a little below the floor maps
    back below it)."""

    heights: tuple
    targets: tuple

    def __post_init__(self):
        for knots in (self.heights, self.targets):
            if len(knots) < 2 or not np.all(np.diff(knots) > 0.0):
                raise ValueError(f"height map knots must strictly increase, got {knots}")
        if len(self.heights) != len(self.targets):
            raise ValueError("a height map needs as many targets as heights")

    def forward(self, heights: np.ndarray) -> np.ndarray:
        return _piecewise_linear(heights, self.heights, self.targets)

    def inverse(self, heights: np.ndarray) -> np.ndarray:
        return _piecewise_linear(heights, self.targets, self.heights)


def _piecewise_linear(values, knots: tuple, images: tuple) -> np.ndarray:
    """``values`` through the piecewise-linear map sending ``knots`` to ``images``, extended along its end pieces."""
    values = np.asarray(values, dtype=np.float64)
    mapped = np.interp(values, knots, images)
    below, above = values < knots[0], values > knots[-1]
    mapped[below] = images[0] + (values[below] - knots[0]) * (images[1] - images[0]) / (knots[1] - knots[0])
    mapped[above] = images[-1] + (values[above] - knots[-1]) * (images[-1] - images[-2]) / (knots[-1] - knots[-2])
    return mapped


@dataclass(frozen=True)
class Proportions:
    """Why a biped is read again and how: ``crotch`` and ``neck`` as found
    (None where not found), whether its legs are short and its head big,
    and the :class:`HeightMap` to typical proportions."""

    crotch: float | None
    neck: float | None
    short_legs: bool
    big_head: bool
    height_map: HeightMap


def typical_proportions(points: dict, solid: SolidDepth, top: float, enclosed=None) -> Proportions | None:
    """The map to typical proportions for landmarks ``points`` that put the
    hip joints more than :data:`HIP_ABOVE_CROTCH` crotch heights above the
    crotch (short legs: the crotch is stretched to
    :data:`TYPICAL_CROTCH_SHARE`) or the neck more than
    :data:`NECK_ABOVE_PINCH` above the body's neck pinch (a big head: the
    crotch, when lower, to :data:`TYPICAL_CROTCH_SHARE` too, and the pinch
    to :data:`TYPICAL_NECK_SHARE`); None when neither holds. The neck is
    looked for only where the crotch is found (a long robe's open bottom
    hides both) and counts only below :data:`TYPICAL_NECK_SHARE` (a neck
    already that high is no big head's). ``enclosed``: see
    :func:`crotch_height`."""
    crotch = crotch_height(solid, np.array([points["knee.L"], points["knee.R"]]), top, enclosed)
    if crotch is not None and crotch <= 0.0:
        crotch = None
    hips = 0.5 * (points["hip.L"][2] + points["hip.R"][2])
    short_legs = (crotch is not None and crotch < TYPICAL_CROTCH_SHARE * top
                  and hips - crotch > HIP_ABOVE_CROTCH * crotch)
    neck = None if crotch is None else neck_pinch(solid, crotch, top)
    big_head = (neck is not None and neck < TYPICAL_NECK_SHARE * top
                and points["neck"][2] - neck > NECK_ABOVE_PINCH * top)
    if not (short_legs or big_head):
        return None
    heights, targets = [0.0], [0.0]
    if crotch is not None and crotch < TYPICAL_CROTCH_SHARE * top:
        heights.append(crotch)
        targets.append(TYPICAL_CROTCH_SHARE * top)
    if big_head:
        heights.append(neck)
        targets.append(TYPICAL_NECK_SHARE * top)
    heights.append(top)
    targets.append(top)
    return Proportions(crotch, neck, short_legs, big_head, HeightMap(tuple(heights), tuple(targets)))


def stretched(proxy: Mesh, height_map: HeightMap) -> tuple[Mesh, np.ndarray]:
    """``proxy`` (normalised) under ``height_map``, normalised again, and
    the (4, 4) transform of that normalisation."""
    vertices = proxy.vertices.copy()
    vertices[:, 2] = height_map.forward(vertices[:, 2])
    transform = normalisation_transform(vertices)
    return Mesh(apply_transform(vertices, transform), proxy.triangles), transform


def points_back(points: dict, transform: np.ndarray, height_map: HeightMap) -> dict:
    """Landmarks read on :func:`stretched` mapped back to the body as it is."""
    names = list(points)
    moved = apply_transform(np.array([points[name] for name in names], dtype=np.float64), np.linalg.inv(transform))
    moved[:, 2] = height_map.inverse(moved[:, 2])
    return dict(zip(names, moved))
