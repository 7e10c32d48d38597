"""Short legs read again: the landmark network on a biped stretched to typical leg length.

The landmark network (:mod:`.networks.landmarks`) learnt bodies whose crotch
sits mostly at 32 to 52 % of their height (the training families' medians;
0 A.D.'s humans, most of them, at 43 %; KayKit's three at 16 %). On a short-legged, big-headed character
(Quaternius' animated and monster packs, crotch at 19 to 31 %) it lays the
trunk out where those bodies have it: the hips, the hip joints, the
shoulders and the head 0.1 to 0.2 of the height too high, while the knees
and ankles, read from the legs themselves, stay in place.

The crotch tells it: the first point inside the solid straight above the
middle of the knees (:func:`crotch_height`). When the landmarks put the hip
joints more than :data:`HIP_ABOVE_CROTCH` crotch heights above it, the body
is stretched vertically, piecewise linearly, so that its crotch sits at
:data:`TYPICAL_CROTCH_SHARE` of its height (:class:`HeightMap`), read again,
and the new landmarks mapped back. The map is increasing, so every landmark
keeps its place along the limb it lies in.

Everything here is in the normalised frame (feet at z = 0, largest side 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dataset.normalise import apply_transform, normalisation_transform
from ..types import Mesh
from .joint_features import SolidDepth

#: The landmarks' hip joints lie more than this many crotch heights above
#: the crotch: the network read the legs as longer than they are. Chosen on
#: every third training character (108, 2026-11-26): at 0.6 no training
#: biped is read again (at 0.4 and 0.5, 4 are, with no change of score; at
#: 0.3, 16, and their key joints get worse: 92.7 % to 90.7 % right).
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


def crotch_height(solid: SolidDepth, knees: np.ndarray, top: float) -> float | None:
    """The height of the first point inside the solid on the vertical line
    through the middle of the knees (``knees``: (2, 3), left and right),
    above them and below ``CROTCH_SEARCH_TOP * top``; None when there is
    none (legs that meet nowhere, a long robe's open bottom)."""
    middle = np.mean(np.asarray(knees, dtype=np.float64), axis=0)
    heights = np.arange(middle[2], CROTCH_SEARCH_TOP * top, 0.5 * solid.cell_size)
    if not len(heights):
        return None
    line = np.column_stack([np.zeros_like(heights), np.full_like(heights, middle[1]), heights])
    # Half a cell deep: inside the solid, not in the interpolated fringe around it.
    inside = np.flatnonzero(solid.at(line) >= 0.5 * solid.cell_size)
    return float(heights[inside[0]]) if len(inside) else None


@dataclass(frozen=True)
class HeightMap:
    """The piecewise-linear map on heights in [0, ``top``] that sends
    ``crotch`` to ``target`` and keeps 0 and ``top``."""

    crotch: float
    target: float
    top: float

    def forward(self, heights: np.ndarray) -> np.ndarray:
        return self._map(np.asarray(heights, dtype=np.float64), self.crotch, self.target)

    def inverse(self, heights: np.ndarray) -> np.ndarray:
        return self._map(np.asarray(heights, dtype=np.float64), self.target, self.crotch)

    def _map(self, heights: np.ndarray, start: float, end: float) -> np.ndarray:
        below = heights * (end / start)
        above = end + (heights - start) * ((self.top - end) / (self.top - start))
        return np.where(heights < start, below, above)


def short_leg_map(points: dict, solid: SolidDepth, top: float) -> HeightMap | None:
    """The stretch to typical leg length for landmarks ``points`` that put
    the hip joints more than :data:`HIP_ABOVE_CROTCH` crotch heights above
    the crotch, else None."""
    crotch = crotch_height(solid, np.array([points["knee.L"], points["knee.R"]]), top)
    if crotch is None or crotch <= 0.0 or crotch >= TYPICAL_CROTCH_SHARE * top:
        return None
    hips = 0.5 * (points["hip.L"][2] + points["hip.R"][2])
    if hips - crotch <= HIP_ABOVE_CROTCH * crotch:
        return None
    return HeightMap(crotch, TYPICAL_CROTCH_SHARE * top, top)


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
