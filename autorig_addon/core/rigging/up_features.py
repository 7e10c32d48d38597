"""The cues the upright network reads: whether +z is up for a character
whose mirror plane is x = const, from the height profile of its surface.

A standing character's lowest bands are its feet: little area touching
the ground, the midline between them empty; its top is a head, or a back.
Lying or upside down, the profile reads otherwise. :func:`candidate_features`
gives the cues of the four ways such a character can stand
(:data:`UP_CANDIDATES`), which the upright network
(:mod:`.networks.upright`) scores.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..geometry.normals import triangle_double_areas

#: Height bands the up cues are measured in (bottom to top).
UP_BANDS = 8
#: A point of a band is on its midline when its |x| is below this share of
#: the band's own half width: the feet of a standing biped or quadruped
#: leave the midline of the lowest bands empty, a head or a back fills it.
MIDLINE_SHARE = 0.25
#: The lowest and the highest this share of the height: where a standing
#: character touches the ground (small feet), and its top.
END_SHARE = 0.03
#: Cues per candidate: the three extents, the height of the area's centre,
#: the area at the bottom and at the top, then per band its area share, x
#: and y spreads, midline share and half width.
UP_FEATURE_COUNT = 6 + 5 * UP_BANDS


def area_centroids(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangle centroids (m, 3) and their share of the area (m,), summing
    to 1: the surface evenly, whatever the mesh's vertex density."""
    areas = triangle_double_areas(vertices, triangles)
    total = areas.sum()
    if total <= 0.0:
        raise InputError("The mesh has no faces with an area, so which way is up cannot be read.")
    return vertices[triangles].mean(axis=1), areas / total


def up_features(points: np.ndarray, shares: np.ndarray) -> np.ndarray:
    """(UP_FEATURE_COUNT,) cues of whether +z is up, for surface ``points``
    (m, 3) with area ``shares`` (m,), their mirror plane at x = c (the box
    centre's x); lengths in shares of the largest side. Front and back are
    not told apart here: every cue is the same for the shape turned half a
    turn about z."""
    low, high = points.min(axis=0), points.max(axis=0)
    extents = high - low
    scale = max(float(extents.max()), 1e-12)
    centred = (points - 0.5 * (low + high)) / scale
    heights = (points[:, 2] - low[2]) / max(float(extents[2]), 1e-12)
    band = np.minimum((heights * UP_BANDS).astype(np.int64), UP_BANDS - 1)
    area = np.bincount(band, shares, minlength=UP_BANDS)
    safe = np.maximum(area, 1e-12)

    def band_mean(values):
        return np.bincount(band, shares * values, minlength=UP_BANDS) / safe

    x_spread = np.sqrt(band_mean(centred[:, 0] ** 2))
    y_mean = band_mean(centred[:, 1])
    y_spread = np.sqrt(np.maximum(band_mean(centred[:, 1] ** 2) - y_mean ** 2, 0.0))
    half_width = np.zeros(UP_BANDS)
    np.maximum.at(half_width, band, np.abs(centred[:, 0]))
    midline = band_mean((np.abs(centred[:, 0]) < MIDLINE_SHARE * half_width[band]).astype(np.float64))
    ends = [shares[heights < END_SHARE].sum(), shares[heights > 1.0 - END_SHARE].sum()]
    return np.concatenate([extents / scale, [float(shares @ heights)], ends, area, x_spread, y_spread, midline,
                           half_width])


def rotation_about_x(quarter_turns: int) -> np.ndarray:
    """(3, 3) rotation by ``quarter_turns`` times 90 degrees about +x, by
    the right-hand rule (1: what was +y comes up to +z), exact."""
    cosine, sine = [(1, 0), (0, 1), (-1, 0), (0, -1)][int(quarter_turns) % 4]
    return np.array([[1.0, 0.0, 0.0], [0.0, cosine, -sine], [0.0, sine, cosine]])


#: The four ways a character whose mirror plane is x = 0 can stand, as
#: rotations about x that bring each candidate up to +z: as it is, lying on
#: its back or front (whichever way), upside down.
UP_CANDIDATES = tuple(rotation_about_x(turns) for turns in range(4))


def candidate_features(points: np.ndarray, shares: np.ndarray) -> np.ndarray:
    """(4, UP_FEATURE_COUNT) :func:`up_features` of surface ``points`` (m, 3)
    with area ``shares`` (m,) turned by each of :data:`UP_CANDIDATES`."""
    return np.stack([up_features(points @ rotation.T, shares) for rotation in UP_CANDIDATES])
