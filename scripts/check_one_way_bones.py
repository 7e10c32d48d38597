"""What deriving the tails of a skeleton whose bones all point one way is worth,
measured on the held-out training characters (never the validation ones).

Usage (from the repo root, with the samples cached)::

    .venv/bin/python scripts/check_one_way_bones.py [NETWORK]

A glTF importer points each bone along its joint's local +Y axis; a file
whose exporter never turned its joint frames (Kenney's minis, three 0 A.D.
pigs) gives every bone one direction, whatever the limb does. No training
character is like that, so this builds the case from them: each held-out
training character keeps its joints, parents and bone lengths, and every
bone is turned to point up (+Z), as such an importer would leave it. Its
skin weights (NETWORK, default the shipped default) are then scored against
the artist's three ways: with the real bones, with the one-way bones as
given, and with the tails :func:`~autorig_addon.core.skeleton.tails.with_reliable_tails`
gives them (derived from the joints, since the bones point one way and not
at their children). Prints one line per character, then the means and
medians and on how many characters the derived tails beat the one-way ones.

First it prints what the rule does to the training characters as they are:
how many it catches (their loader note says the bones point one way), and
the largest share of bones pointing one way among those whose stored tails
are kept and whose directions do not point at their children.
"""

from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np

from autorig_addon.core.dataset.cache import training_samples
from autorig_addon.core.dataset.split import PURPOSE_SKELETON, PURPOSE_SKIN
from autorig_addon.core.evaluation.skin_metrics import skin_l1
from autorig_addon.core.geometry.bounding_box import bounding_box_diagonal
from autorig_addon.core.skeleton.tails import assess_stored_tails, with_reliable_tails
from autorig_addon.core.skinning.methods import DEFAULT_SKIN_METHOD, skin_weights
from autorig_addon.core.skinning.options import SkinningOptions
from autorig_addon.training.runs import held_out_names

#: The one direction every bone is given, as an importer following unturned joint frames gives it.
ONE_WAY = np.array([0.0, 0.0, 1.0])


#: The loader's note on an armature whose bones the rule caught (``core.skeleton.tails``).
CAUGHT_NOTE = "the stored bones point one way"


def report_training_characters() -> None:
    """How near the training characters, as they are, come to the rule."""
    samples = training_samples(purpose=PURPOSE_SKELETON)
    caught = [sample.name for sample in samples if any(CAUGHT_NOTE in note for note in sample.notes)]
    shares = []
    for sample in samples:
        if not any(note.startswith("stored bone tails used") for note in sample.notes):
            continue
        assessment = assess_stored_tails(sample.skeleton, bounding_box_diagonal(sample.vertices))
        if not assessment.directions_agree:
            shares.append((assessment.one_way_share, sample.name))
    print(f"{len(samples)} training characters: {len(caught)} caught by the rule {caught}")
    share, name = max(shares, default=(0.0, "none"))
    print(f"largest share of bones one way with the stored tails kept and not pointing at their children: "
          f"{100 * share:.0f} % ({name}, of {len(shares)} such characters)")


def main(method: str) -> None:
    report_training_characters()
    samples = training_samples(purpose=PURPOSE_SKIN)
    held = held_out_names([sample.name for sample in samples])
    options = SkinningOptions(method=method)
    rows = []
    for sample in samples:
        if sample.name not in held:
            continue
        real = sample.skeleton
        one_way = replace(real, tails=real.joints + real.bone_lengths[:, None] * ONE_WAY)
        derived, decision = with_reliable_tails(one_way, bounding_box_diagonal(sample.vertices))
        scores = [skin_l1(skin_weights(sample.mesh, skeleton, options).matrix, sample.weights)
                  for skeleton in (real, one_way, derived)]
        rows.append(scores)
        print(f"{sample.name:60s} real {scores[0]:.3f}  one way {scores[1]:.3f}  derived {scores[2]:.3f}"
              f"{'' if decision.whole_armature else '  (tails kept: ' + decision.reason + ')'}", flush=True)
    table = np.array(rows)
    print(f"{len(table)} held-out training characters, {method}: L1 mean real / one way / derived "
          f"{' / '.join(f'{value:.4f}' for value in table.mean(axis=0))}, median "
          f"{' / '.join(f'{value:.4f}' for value in np.median(table, axis=0))}")
    print(f"derived better than one way on {int(np.sum(table[:, 2] < table[:, 1]))}, "
          f"worse on {int(np.sum(table[:, 2] > table[:, 1]))}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else DEFAULT_SKIN_METHOD)
