"""Pick the mean-shift defaults of the skeleton predictor on the held-out
training characters (never the validation ones).

Usage (from the repo root, after ``train rig --model joints``)::

    .venv/bin/python scripts/tune_rig_clustering.py

Runs the shipped joint network once per held-out character that ``train
rig`` scores (at most two per skeleton family of those it holds out) and
prints, for a grid of bandwidths and density thresholds (``--thresholds``
to change the latter; density thresholds only raised CD-J2J so far), the mean CD-J2J of the clustered joints
and the mean joint IoU against the artists' joints (units of the largest
side; RigNet's metrics, ``core.evaluation``).
"""

from __future__ import annotations

import argparse

import numpy as np

from autorig_addon.core.dataset.cache import training_samples
from autorig_addon.core.evaluation.joint_matching import JOINT_MATCH_FRACTION, joint_iou_precision_recall
from autorig_addon.core.evaluation.skeleton_metrics import chamfer_j2j
from autorig_addon.core.nn.spec import shipped_weights
from autorig_addon.core.rigging.networks import joints as joint_network
from autorig_addon.core.rigging.predict import cluster_joints, graph_votes
from autorig_addon.training.rigging.train import SCORED_PER_FAMILY, default_examples_dir
from autorig_addon.training.rigging.training_set import load_example
from autorig_addon.training.runs import character_families, family_sample, held_out_names

BANDWIDTHS = (0.01, 0.0125, 0.015, 0.0175, 0.02, 0.0225, 0.025, 0.03, 0.035, 0.04, 0.05)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--thresholds", type=float, nargs="+", default=[0.0], help="Density thresholds (default 0)")
    thresholds = parser.parse_args().thresholds
    held_out = held_out_names([sample.name for sample in training_samples()])
    held = family_sample(sorted(held_out), character_families(held_out), SCORED_PER_FAMILY)
    folder = default_examples_dir(0)
    weights = shipped_weights(joint_network.SPEC).weights
    votes = []
    for name in held:
        example = load_example(folder / f"{name.replace('/', '__')}#0.npz")
        votes.append((graph_votes(weights, example.graph), example))
    print("| bandwidth | threshold | CD-J2J | IoU | joints predicted / artist's |")
    print("|---|---|---|---|---|")
    for bandwidth in BANDWIDTHS:
        for threshold in thresholds:
            scores, ious, counts = [], [], []
            for vote, example in votes:
                joints, _ = cluster_joints(vote, bandwidth, threshold, True)
                scores.append(chamfer_j2j(joints, example.joints))
                ious.append(joint_iou_precision_recall(joints, example.joints, JOINT_MATCH_FRACTION)["iou"])
                counts.append(len(joints) / len(example.joints))
            print(f"| {bandwidth} | {threshold} | {np.mean(scores):.4f} | {np.mean(ious):.3f} | "
                  f"{np.mean(counts):.2f} |")


if __name__ == "__main__":
    main()
