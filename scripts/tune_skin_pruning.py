"""Pick the skinning networks' pruning threshold and sharpening power on the
held-out training characters (never the validation ones).

Usage (from the repo root, after ``train skin``)::

    .venv/bin/python scripts/tune_skin_pruning.py [NETWORK ...]

Runs each shipped network once on the held-out training characters (the
ones ``train skin`` holds out to pick its epoch, as they are: the ``rest``
examples) and prints, for a grid of :data:`PRUNE_BELOW` thresholds and
:data:`SHARPEN_POWER` powers, the mean L1, influence precision and recall,
over all of them and over at most two per skeleton family (the 0 A.D.
humans, one skeleton, are 22 of the 53).
"""

from __future__ import annotations

import sys

import numpy as np

from autorig_addon.core.dataset.cache import training_samples
from autorig_addon.core.dataset.split import PURPOSE_SKIN
from autorig_addon.core.evaluation.skin_metrics import influence_precision_recall, skin_l1
from autorig_addon.core.skinning.geometric import DEFAULT_MAX_INFLUENCES
from autorig_addon.core.skinning.learned.networks import NETWORK_NAMES, skin_network
from autorig_addon.core.skinning.learned.predict import dense_weights, network_candidate_weights
from autorig_addon.core.weights import limit_influences, prune_small, sharpened
from autorig_addon.training.runs import character_families, family_sample, held_out_names
from autorig_addon.training.skinning.learned.training_set import build_examples, load_example

THRESHOLDS = (0.03, 0.05, 0.08, 0.1, 0.15, 0.2, 0.25)
POWERS = (1.0, 1.25, 1.5, 2.0)
#: Held-out characters per family in the balanced mean.
PER_FAMILY = 2


def main(networks) -> None:
    samples = training_samples(purpose=PURPOSE_SKIN)
    held = held_out_names([sample.name for sample in samples])
    balanced = set(family_sample(sorted(held), character_families(held), PER_FAMILY))
    for network in networks:
        spec = skin_network(network)
        rows = []
        for sample in samples:
            if sample.name not in held:
                continue
            (path,) = build_examples([sample], spec.distance, prior=spec.prior, augment=False)
            graph, _, reference, _ = load_example(path)
            limited = limit_influences(dense_weights(graph, network_candidate_weights(spec, graph)),
                                       DEFAULT_MAX_INFLUENCES)
            scores = []
            for threshold in THRESHOLDS:
                for power in POWERS:
                    predicted = sharpened(prune_small(limited, threshold), power)
                    found = influence_precision_recall(predicted, reference)
                    scores.append((skin_l1(predicted, reference), found["precision"], found["recall"]))
            rows.append((sample.name in balanced, np.array(scores)))
        every = np.mean([scores for _, scores in rows], axis=0)
        even = np.mean([scores for chosen, scores in rows if chosen], axis=0)
        print(f"{network}: {len(rows)} held-out characters ({len(balanced)} in the per-family mean)")
        print("threshold | power | L1 all | precision all | recall all | L1 per family | precision | recall")
        grid = [(threshold, power) for threshold in THRESHOLDS for power in POWERS]
        for (threshold, power), a, b in zip(grid, every, even):
            print(f"{threshold:.2f} | {power:.2f} | {a[0]:.4f} | {a[1]:.3f} | {a[2]:.3f} | {b[0]:.4f} | {b[1]:.3f} | "
                  f"{b[2]:.3f}")


if __name__ == "__main__":
    main(sys.argv[1:] or NETWORK_NAMES)
