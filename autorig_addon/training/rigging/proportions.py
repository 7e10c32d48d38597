"""Characters with other proportions, for the landmark network.

The validation humanoids the landmark network placed worst were short-legged,
big-headed ones (Quaternius' animated pack and monsters, Kenney's minis): it
put their hips, shoulders and head where a realistically proportioned body
has them, 0.1 to 0.2 of the height too high, because the per-axis stretches
of :mod:`.training_set` scale a body as a whole and never change how its
height divides between legs, trunk and head. A proportion variant does: the
character's height is cut into :data:`SEGMENTS` equal bands, each band
stretched or squashed vertically by its own factor, and its width and depth
scaled by a factor that runs smoothly with the height (a big head, thin legs),
then normalised again. The map is continuous and increasing in height, so a
joint inside a limb stays inside it at the same place, and every joint of the
rig (the key joints the landmarks learn, the bone tails) moves with the mesh
exactly.

A variant is a :class:`~...core.dataset.sample.CharacterSample` named
``CHARACTER~proportionsN``; :func:`source_character` gives back the
character, so epochs draw a variant as one more copy of its character, not
as a character of its own.
"""

from __future__ import annotations

import zlib
from dataclasses import replace

import numpy as np

from ...core.dataset.normalise import apply_transform, normalisation_transform
from ...core.dataset.sample import CharacterSample

#: Bands of equal height the character is cut into.
SEGMENTS = 4
#: Range of each band's vertical factor (log-uniform): a band can become
#: up to three times as tall as its neighbour (a chibi head over short legs).
HEIGHT_FACTOR_RANGE = (0.55, 1.8)
#: Range of the width and depth factor at each band's edge (log-uniform).
WIDTH_FACTOR_RANGE = (0.75, 1.35)
#: Proportion variants per training character that ``train rig --model landmarks`` makes by default.
DEFAULT_PROPORTION_VARIANTS = 0
#: Marks a variant's name: ``CHARACTER~proportionsN``.
VARIANT_MARK = "~proportions"


def proportion_map(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A random map on heights in [0, 1]: ``(heights, widths)``, each
    (SEGMENTS + 1,): the new height of each band edge (increasing from 0)
    and the width factor there.

    Draws ``rng.uniform`` twice (the bands' height factors, then the edges' width factors).
    """
    low, high = np.log(HEIGHT_FACTOR_RANGE)
    factors = np.exp(rng.uniform(low, high, size=SEGMENTS))
    heights = np.concatenate([[0.0], np.cumsum(factors / SEGMENTS)])
    low, high = np.log(WIDTH_FACTOR_RANGE)
    widths = np.exp(rng.uniform(low, high, size=SEGMENTS + 1))
    return heights, widths


def reproportioned(points: np.ndarray, height: float, heights: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """``points`` (normalised frame: feet at z = 0, midline at x = y = 0) under
    the map (:func:`proportion_map`) of a body ``height`` tall: z through
    the piecewise-linear height map, x and y scaled about the vertical axis
    by the width factor at their height. Points above or below the body
    follow the nearest band's line."""
    points = np.asarray(points, dtype=np.float64)
    edges = np.linspace(0.0, 1.0, SEGMENTS + 1)
    share = points[:, 2] / height
    band = np.clip(np.searchsorted(edges, share, side="right") - 1, 0, SEGMENTS - 1)
    slope = (heights[band + 1] - heights[band]) / (edges[band + 1] - edges[band])
    new_share = heights[band] + slope * (share - edges[band])
    width = np.interp(share, edges, widths)
    moved = points.copy()
    moved[:, :2] *= width[:, None]
    moved[:, 2] = new_share * height
    return moved


def proportion_variant(sample: CharacterSample, number: int, seed: int) -> CharacterSample:
    """Variant ``number`` of ``sample`` (normalised): mesh, joints and tails
    under one random :func:`proportion_map`, normalised again. The generator
    is seeded by ``seed``, the character's name and ``number``, so variants
    do not change when characters are added."""
    rng = np.random.default_rng([seed, zlib.crc32(sample.name.encode()), number])
    heights, widths = proportion_map(rng)
    height = float(sample.vertices[:, 2].max())
    vertices, joints, tails = (reproportioned(points, height, heights, widths)
                               for points in (sample.vertices, sample.joints, sample.tails))
    transform = normalisation_transform(vertices)
    # The reshaping is no similarity: ``transform`` then maps the source file's space to the variant only roughly,
    # kept for the normalisation's scale and shift; training reads the variant's own arrays.
    return replace(sample, name=f"{sample.name}{VARIANT_MARK}{number}", vertices=apply_transform(vertices, transform),
                   joints=apply_transform(joints, transform), tails=apply_transform(tails, transform),
                   transform=transform @ sample.transform)


def reshaped_variants(samples: list[CharacterSample], seed: int, count: int) -> list[CharacterSample]:
    """``count`` proportion variants of every sample."""
    return [proportion_variant(sample, number, seed) for sample in samples for number in range(1, count + 1)]


def source_character(name: str) -> str:
    """The character a sample or example name was made from: ``X~proportions2#0`` -> ``X``."""
    return name.rsplit("#", 1)[0].split(VARIANT_MARK, 1)[0]
