"""Check, on held-out training characters, that a known body's whole rig beats the predicted skeleton within the limit.

Usage (from the repo root, after ``train library``)::

    .venv/bin/python scripts/tune_known_rig.py

For every training character the networks never trained on (every sixth by
name, ``training.runs.held_out_names``), with itself and its near-duplicates
(``data_split.json``) out of the shipped rig library, as a new character's
relatives would be there and it would not: predicts the votes once and scores
(RigNet's metrics against its own artist's deform bones, in its normalised
frame) the skeleton *Auto* gives without a known rig and the one it gives with
the known rig when one lies within ``rig_library.LIBRARY_DISTANCE`` (as
``predict.checked_skeleton`` builds them: a known rig the checks find poor is
not used). Prints
each character that has a known rig within the limit, with both scores, then
the means over those and over every held-out character. Never a validation
character.
"""

from __future__ import annotations

import numpy as np

from autorig_addon.core.evaluation.skeleton_metrics import evaluate_rig
from autorig_addon.core.rigging import predict, rig_library
from autorig_addon.core.types import Mesh
from tune_rig_library import held_out_samples, near_duplicates, without

MEASURES = ("cd_j2j", "cd_j2b", "cd_b2b", "iou")


def main() -> None:
    library = rig_library.shipped_library()
    rows = []
    for sample in held_out_samples():
        others = without(library, near_duplicates(sample.name) | {sample.name})
        rig_library.shipped_library = lambda others=others: others
        votes = predict.predict_votes(Mesh(sample.vertices, sample.triangles))
        reference = sample.skeleton
        size = float(np.ptp(sample.vertices, axis=0).max())
        # As Auto-Rig builds it: a known rig the checks find poor is not used.
        scores = [evaluate_rig(predict.checked_skeleton(votes, known_rig=allowed).skeleton, reference, size)
                  for allowed in (False, True)]
        known = votes.known_rig
        rows.append((known is not None, scores))
        if known is not None:
            print(f"{sample.name:60s} from {known.name} ({known.distance:.3f}): " + ", ".join(
                f"{measure} {scores[0][measure]:.4f} -> {scores[1][measure]:.4f}" for measure in MEASURES), flush=True)
    for label, chosen in (("with a known rig within the limit", [r for r in rows if r[0]]), ("every one", rows)):
        print(f"\n{len(chosen)} held-out training characters, {label} (without -> with the known rig):")
        for measure in MEASURES:
            before = np.mean([scores[0][measure] for _, scores in chosen])
            after = np.mean([scores[1][measure] for _, scores in chosen])
            print(f"  {measure}: {before:.4f} -> {after:.4f}")


if __name__ == "__main__":
    main()
