"""How the character's orientation is found (core/rigging/orientation.py) on the cached characters.

Usage: .venv/bin/python scripts/check_orientation.py as-is|turned [SAMPLE_DIR]

``as-is``: every cached character as it stands (upright, facing -Y): each
should be taken as it is. ``turned``: the first character of each skeleton
family of ``data_split.json`` (by file name) on its back, on its front, on
its side and upside down. For each case ``stand_upright`` runs on the
prediction's proxy as ``predict_votes`` runs it, and the outcome is
``right`` (stood up right), ``kept`` (taken as it lies), ``refused`` or
``wrong`` (stood up another way). Prints a line per character, then the
counts per kind (humanoid, quadruped, the rest) and way, for the training
and validation characters apart.
"""

import collections
import os
import sys
from pathlib import Path

import numpy as np

from autorig_addon.core.dataset.cache import default_cache_dir
from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split
from autorig_addon.core.errors import InputError
from autorig_addon.core.geometry.proxy import simplified_proxy
from autorig_addon.core.rigging import predict
from autorig_addon.core.rigging.facing import half_turned
from autorig_addon.core.rigging.joint_features import PROXY_VERTICES
from autorig_addon.core.rigging.orientation import stand_upright
from autorig_addon.core.rigging.standard_skeleton import predict_landmarks, standard_confidence
from autorig_addon.core.rigging.up_features import rotation_about_x
from autorig_addon.core.types import Mesh

#: The ways a character is turned from standing (the mesh's rotation).
ON_ITS_SIDE = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # a quarter turn about +Y
WAYS = {"as-is": np.eye(3), "on its back": rotation_about_x(-1), "on its front": rotation_about_x(1),
        "upside down": rotation_about_x(2), "on its side": ON_ITS_SIDE}


def outcome(sample: CharacterSample, turn: np.ndarray) -> str:
    proxy = simplified_proxy(Mesh(sample.vertices @ turn.T, sample.triangles), PROXY_VERTICES).mesh

    def reading(rotation):
        graph = predict._read_shape(proxy, predict.framed_transform(proxy.vertices, rotation, proxy.triangles), None)[0]
        landmarks, turned = predict_landmarks(graph), predict_landmarks(half_turned(graph))
        return landmarks if standard_confidence(landmarks) >= standard_confidence(turned) else turned

    try:
        up = stand_upright(proxy.vertices, proxy.triangles, reading).rotation[2]
    except InputError:
        return "refused"
    if up @ turn @ [0.0, 0.0, 1.0] > 0.9:
        return "right"
    return "kept" if up @ [0.0, 0.0, 1.0] > 0.9 else "wrong"


def main(which: str, folder: str) -> int:
    split = read_data_split(DEFAULT_SPLIT_FILE)
    validation = {os.path.splitext(path)[0] for path in split.subset("validation")}
    families = {os.path.splitext(path)[0]: family for path, family in split.families.items()}
    seen = set()
    counts = collections.defaultdict(collections.Counter)
    for path in sorted(Path(folder).glob("*.npz")):
        try:
            sample = CharacterSample.load(path)
        except InputError:
            continue
        if which == "turned":
            family = families.get(sample.name, sample.name)
            if family in seen:
                continue
            seen.add(family)
        ways = ["as-is"] if which == "as-is" else [way for way in WAYS if way != "as-is"]
        kind = sample.category if sample.category in ("humanoid", "quadruped") else "the rest"
        subset = "validation" if sample.name in validation else "training"
        results = [outcome(sample, WAYS[way]) for way in ways]
        for way, result in zip(ways, results):
            counts[(subset, kind, way)][result] += 1
        print(sample.name, results, flush=True)
    for key in sorted(counts):
        print(*key, dict(counts[key]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else str(default_cache_dir())))
