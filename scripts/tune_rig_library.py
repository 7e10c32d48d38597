"""Pick the rig library's distance limit on the held-out training characters (never the validation ones).

Usage (from the repo root, after ``train library``)::

    .venv/bin/python scripts/tune_rig_library.py

For every training character the landmark network never trained on (every
sixth by name, ``training.runs.held_out_names``) that is a biped or a
quadruped with key joints, reads its landmarks as the predictor does on the
upright proxy, and finds the closest entry of its kind in the shipped library
with the character itself and its near-duplicates (``data_split.json``)
left out, as a new character's relatives would be there and it would not.
Prints each character's share of key joints within 0.05 (the landmark
network's, the copy's) and, for a range of limits, the mean share when the
copy replaces the network's landmarks within the limit.

``--check-screen`` instead checks ``closest_rig``'s screen: on every cached
validation and held-out training character, read as a biped and as a
quadruped, with itself and its near-duplicates out of the library, the entry
it picks at the shipped limit against the one measuring every entry in full
picks.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import numpy as np

from autorig_addon.core.dataset.cache import default_cache_dir, training_samples
from autorig_addon.core.dataset.normalise import normalisation_transform
from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split
from autorig_addon.core.evaluation.key_joint_metrics import KEY_JOINT_FRACTION
from autorig_addon.core.geometry.proxy import simplified_proxy
from autorig_addon.core.rigging import rig_library
from autorig_addon.core.rigging.joint_features import PROXY_VERTICES
from autorig_addon.core.rigging.networks.landmarks import BODY_KINDS, STANDARD_KINDS, sample_landmarks
from autorig_addon.core.rigging.predict import _read_shape
from autorig_addon.core.rigging.rig_library import RigLibrary, closest_rig, shipped_library
from autorig_addon.core.skeleton.key_joints import KEY_JOINTS
from autorig_addon.core.types import Mesh
from autorig_addon.training.runs import held_out_names

LIMITS = (0.0, 0.01, 0.015, 0.02, 0.025, 0.026, 0.03, 0.035, 0.04, 0.05)


def near_duplicates(name: str) -> set:
    """``name`` and its near-duplicates (``data_split.json``)."""
    return set(read_data_split(DEFAULT_SPLIT_FILE).near_duplicate_names(name))


def held_out_samples() -> list:
    """The cached training characters the networks never trained on (every sixth by name, ``held_out_names``)."""
    samples = training_samples()
    held = held_out_names([sample.name for sample in samples])
    return [sample for sample in samples if sample.name in held]


def without(library: RigLibrary, names: set) -> RigLibrary:
    return library.subset(np.array([name not in names for name in library.names]))


def share_right(points: dict, targets: np.ndarray, known: np.ndarray) -> float:
    right = [np.linalg.norm(points[name] - targets[index]) <= KEY_JOINT_FRACTION
             for index, name in enumerate(KEY_JOINTS) if known[index] and name in points]
    return float(np.sum(right)) / float(known.sum())


def check_screen() -> None:
    split = json.load(open(DEFAULT_SPLIT_FILE))
    trained = sorted(os.path.splitext(path)[0] for path in split["train"])
    names = {os.path.splitext(path)[0] for path in split["validation"]} | held_out_names(trained)
    library = shipped_library()
    screened = (rig_library.MEASURED_IN_FULL, rig_library.SCREEN_MARGIN)
    readings, differing = 0, 0
    for path in sorted(Path(default_cache_dir()).glob("*.npz")):
        try:
            sample = CharacterSample.load(path)
        except Exception:  # noqa: BLE001 - a sample of an older format is skipped, as training does
            continue
        if sample.name not in names:
            continue
        mesh = Mesh(sample.vertices, sample.triangles)
        others = without(library, near_duplicates(sample.name) | {sample.name})
        for kind in STANDARD_KINDS:
            rig_library.MEASURED_IN_FULL, rig_library.SCREEN_MARGIN = screened
            quick = closest_rig(mesh, kind, others)
            rig_library.MEASURED_IN_FULL, rig_library.SCREEN_MARGIN = 10**9, np.inf
            full = closest_rig(mesh, kind, others)
            readings += 1
            if (quick is None) != (full is None) or (quick is not None and quick.name != full.name):
                differing += 1
                print(f"{sample.name} as {kind}: screened {quick and quick.name}, in full {full and full.name}")
    print(f"{readings} readings, {differing} picking another entry than measuring every entry in full")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check-screen", action="store_true", help="Check closest_rig's screen instead")
    if parser.parse_args().check_screen:
        check_screen()
        return
    library = shipped_library()
    rows = []
    for sample in held_out_samples():
        targets, known, kind_index = sample_landmarks(sample)
        kind = BODY_KINDS[kind_index]
        if kind not in STANDARD_KINDS or not known.any():
            continue
        proxy = simplified_proxy(Mesh(sample.vertices, sample.triangles), PROXY_VERTICES).mesh
        landmarks = _read_shape(proxy, normalisation_transform(proxy.vertices), None)[2]
        match = closest_rig(Mesh(sample.vertices, sample.triangles), kind,
                            without(library, near_duplicates(sample.name)), limit=max(LIMITS))
        network = share_right(landmarks.points, targets, known > 0)
        copied = share_right({**landmarks.points, **match.points}, targets, known > 0) if match else network
        distance = match.distance if match else np.inf
        rows.append((distance, sample.name, network, copied))
        print(f"{distance:.4f} {sample.name:60s} network {network:.2f} copy {copied:.2f} "
              f"({match.name if match else '-'})", flush=True)
    print(f"\n{len(rows)} held-out training characters")
    for limit in LIMITS:
        shares = [copied if distance <= limit else network for distance, _, network, copied in rows]
        print(f"limit {limit:.3f}: key joints within {KEY_JOINT_FRACTION} {np.mean(shares):.1%} "
              f"({sum(distance <= limit for distance, *_ in rows)} copied)")


if __name__ == "__main__":
    main()
