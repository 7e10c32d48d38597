"""Whether a body's shape alone tells its front: a linear score of its front-to-back profile, tried and not used.

Usage: .venv/bin/python scripts/check_front_profile.py [SAMPLE_DIR]

Every cached character is in the normalised frame (upright, facing -Y). For
each, the prediction's proxy (``simplified_proxy``) as it is and tilted by
up to 10 degrees three times gives the cues of facing -Y and of facing +Y
(:func:`front_profile`: per eighth of the length the area, mean height,
spreads, top, bottom and half width, the way ``core/rigging/up_features``
reads height), and a logistic score of their difference (no bias, so the
two ways are told symmetrically; L2 penalty 1 on standardised cues;
characters weighed by 1 / their skeleton family's size) is fitted. Prints
the share of characters whose front it tells, per kind (humanoid,
quadruped, the rest), on the training characters held out by family
(8 folds) and on the validation characters (fitted on all training ones).
The report's note for bodies whose front nothing tells
(``core/rigging/facing.FRONT_UNTOLD_NOTE``) cites these numbers.
"""

import os
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from autorig_addon.core.dataset.cache import default_cache_dir
from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split
from autorig_addon.core.errors import InputError
from autorig_addon.core.geometry.proxy import simplified_proxy
from autorig_addon.core.rigging.joint_features import PROXY_VERTICES
from autorig_addon.core.rigging.up_features import area_centroids
from autorig_addon.core.types import Mesh
from autorig_addon.training.runs import character_families

BANDS = 8
TILTED_COPIES = 3
TILT_DEGREES = 10.0
PENALTY = 1.0
FOLDS = 8
KINDS = ("humanoid", "quadruped", "the rest")


def front_profile(points: np.ndarray, shares: np.ndarray) -> np.ndarray:
    """Cues of surface ``points`` (area ``shares``) along y, front (-y) first."""
    low, high = points.min(axis=0), points.max(axis=0)
    extents = high - low
    centred = (points - 0.5 * (low + high)) / max(float(extents.max()), 1e-12)
    along = (points[:, 1] - low[1]) / max(float(extents[1]), 1e-12)
    band = np.minimum((along * BANDS).astype(np.int64), BANDS - 1)
    area = np.bincount(band, shares, minlength=BANDS)
    safe = np.maximum(area, 1e-12)

    def band_mean(values):
        return np.bincount(band, shares * values, minlength=BANDS) / safe

    height = band_mean(centred[:, 2])
    height_spread = np.sqrt(np.maximum(band_mean(centred[:, 2] ** 2) - height ** 2, 0.0))
    width_spread = np.sqrt(band_mean(centred[:, 0] ** 2))
    top, bottom, half_width = np.full(BANDS, -1.0), np.full(BANDS, 1.0), np.zeros(BANDS)
    np.maximum.at(top, band, centred[:, 2])
    np.minimum.at(bottom, band, centred[:, 2])
    np.maximum.at(half_width, band, np.abs(centred[:, 0]))
    return np.concatenate([[float(shares @ along), float(shares @ centred[:, 2])], area, height, height_spread,
                           width_spread, top, bottom, half_width])


def profile_differences(sample: CharacterSample, rng: np.random.Generator) -> list:
    """Cues facing -y minus cues facing +y, as it is and tilted."""
    proxy = simplified_proxy(Mesh(sample.vertices, sample.triangles), PROXY_VERTICES).mesh
    points, shares = area_centroids(proxy.vertices, proxy.triangles)
    rows = []
    for copy in range(1 + TILTED_COPIES):
        tilt = np.eye(3)
        if copy:
            axis = rng.normal(size=3)
            tilt = Rotation.from_rotvec(np.radians(rng.uniform(0, TILT_DEGREES)) * axis / np.linalg.norm(axis))
            tilt = tilt.as_matrix()
        turned = points @ tilt.T
        rows.append(front_profile(turned, shares) - front_profile(turned * [-1.0, -1.0, 1.0], shares))
    return rows


def fit(rows: list, weights: list) -> np.ndarray:
    """Weights of the logistic score of ``rows`` (each: its characters' differences) saying "faces -y"."""
    x = np.array([row for character in rows for row in character])
    w = np.array([weight for character, weight in zip(rows, weights) for _ in character])
    scale = x.std(axis=0) + 1e-9
    z = x / scale

    def loss(coefficients):
        scores = z @ coefficients
        gradient = -(z * (w / (1.0 + np.exp(scores)))[:, None]).sum(axis=0)
        return (w * np.logaddexp(0.0, -scores)).sum() + PENALTY * coefficients @ coefficients, \
            gradient + 2.0 * PENALTY * coefficients

    return minimize(loss, np.zeros(z.shape[1]), jac=True, method="L-BFGS-B").x / scale


def kind_of(category: str) -> str:
    return category if category in KINDS[:2] else KINDS[2]


def main(sample_dir: Path) -> None:
    split = read_data_split(DEFAULT_SPLIT_FILE)
    validation = {os.path.splitext(path)[0] for path in split.validation}
    rng = np.random.default_rng(0)
    characters = []
    for path in sorted(sample_dir.glob("*.npz")):
        try:
            sample = CharacterSample.load(path)
        except InputError:
            continue
        characters.append((sample.name, kind_of(sample.category), sample.name in validation,
                           profile_differences(sample, rng)))
    training = [character for character in characters if not character[2]]
    families = character_families([name for name, *_ in training])
    sizes = {}
    for name, *_ in training:
        sizes[families[name]] = sizes.get(families[name], 0) + 1
    fold = {family: index % FOLDS for index, family in enumerate(sorted(sizes))}
    told = {}
    for held in range(FOLDS):
        fitted = [c for c in training if fold[families[c[0]]] != held]
        coefficients = fit([c[3] for c in fitted], [1.0 / sizes[families[c[0]]] for c in fitted])
        for name, kind, _, rows in training:
            if fold[families[name]] == held:
                told[("held-out training", name)] = (kind, float(rows[0] @ coefficients) > 0.0)
    coefficients = fit([c[3] for c in training], [1.0 / sizes[families[c[0]]] for c in training])
    for name, kind, is_validation, rows in characters:
        if is_validation:
            told[("validation", name)] = (kind, float(rows[0] @ coefficients) > 0.0)
    for part in ("held-out training", "validation"):
        for kind in KINDS:
            right = [value for (where, _), (its_kind, value) in told.items() if where == part and its_kind == kind]
            print(f"{part}, {kind}: front told on {sum(right)} of {len(right)} ({np.mean(right):.0%})")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else default_cache_dir())
