"""Training the upright network: what ``train rig --model upright`` does.

Every training character of the split is in the normalised frame (upright,
facing -y, its mirror plane x = 0), so each one's four ways to stand
(:data:`...core.rigging.up_features.UP_CANDIDATES`) are known: the first is
up. Its proxy (as prediction simplifies it) is tilted by a small random
rotation (:data:`TILT_DEGREES`, as much as the mirror-plane search leaves
and an artist's pose adds) and turned half a turn about z with probability
one half; each copy gives the cues of its four candidates, and the loss is
the cross-entropy of the first among the four (the root network's loss,
:func:`.train.connectivity_loss`). Every training character takes part,
with copies shared out so each skeleton family has about
:data:`COPIES_PER_FAMILY` (a family of one character gets them all, the 0 A.D.
humans one each): a family of near-duplicates weighs as much as a lone
character, and every body shape is seen. Full batch; the epoch with the
lowest held-out loss is kept.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from scipy.spatial.transform import Rotation

from ...core.geometry.proxy import simplified_proxy
from ...core.rigging.joint_features import PROXY_VERTICES
from ...core.rigging.up_features import area_centroids, candidate_features
from ...core.types import Mesh

#: Tilted copies of each skeleton family, shared among its characters (at least one each).
COPIES_PER_FAMILY = 16
#: Largest random tilt of a copy (degrees, about a random axis).
TILT_DEGREES = 10.0


def copies_per_character(names: list, families: dict) -> list[int]:
    """Tilted copies of each of ``names``: :data:`COPIES_PER_FAMILY` shared
    out over its family's characters among ``names``, at least one each."""
    sizes = Counter(families[name] for name in names)
    return [max(1, round(COPIES_PER_FAMILY / sizes[families[name]])) for name in names]


def upright_data(samples: list, copies: list[int], rng: np.random.Generator) -> dict:
    """The candidates' cues of ``copies`` tilted copies of each of
    ``samples``, in the root network's layout: ``root_features`` (4 rows
    per copy), ``root_copy``, ``root_rows`` (each copy's first row, the
    upright one) and ``roots`` (``(features, 0)`` per copy)."""
    roots = []
    for sample, count in zip(samples, copies):
        proxy = simplified_proxy(Mesh(sample.vertices, sample.triangles), PROXY_VERTICES).mesh
        points, shares = area_centroids(proxy.vertices, proxy.triangles)
        for _ in range(count):
            axis = rng.normal(size=3)
            angle = np.radians(rng.uniform(0.0, TILT_DEGREES))
            tilt = Rotation.from_rotvec(angle * axis / np.linalg.norm(axis)).as_matrix()
            if rng.random() < 0.5:
                tilt = np.diag([-1.0, -1.0, 1.0]) @ tilt
            roots.append((candidate_features(points @ tilt.T, shares).astype(np.float32), 0))
    copies = len(roots)
    return {"roots": roots, "root_features": np.concatenate([features for features, _ in roots]),
            "root_copy": np.repeat(np.arange(copies), 4), "root_rows": 4 * np.arange(copies)}
