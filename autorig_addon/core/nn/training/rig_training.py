"""Training the skeleton networks from their examples (torch; never in Blender).

Each run: fixed seed, Adam with a cosine learning-rate schedule
(:class:`.optimisation.CosineAdam`).

* ``joints``: one character per step, turned by a random angle about the up
  axis and mirrored with probability one half (:mod:`.augmentation`; the
  feature columns of :data:`...rigging.joint_features.VERTEX_VECTORS`
  and the targets turn with it). Loss: the L1 distance between each moved
  vertex and its target joint, plus the binary cross-entropy of the
  attention against the voting vertices (weighted so voters and non-voters
  count alike, up to :data:`MAX_VOTER_WEIGHT`). After each epoch the numpy
  forward pass and the mean shift at the default bandwidth run on the
  held-out training characters; the epoch with the lowest CD-J2J of the
  clustered joints is kept.
* ``bones`` and ``root``: the reference joints of every example, jittered
  (:data:`JOINT_JITTER`) a few times (:data:`JITTER_COPIES`), give pair and
  joint features once; full-batch training; the epoch with the lowest
  held-out loss is kept.
"""

from __future__ import annotations

import sys
import time
from typing import Callable

import numpy as np
import torch

from ...evaluation.skeleton_metrics import chamfer_j2j
from ...rigging.connectivity import bone_probabilities, candidate_pairs, pair_features, root_features, root_scores
from ...rigging.joint_features import VERTEX_VECTORS, solid_depth
from ...rigging.predict import cluster_joints, graph_votes
from ...rigging.symmetry import SYMMETRY_TOLERANCE, mirror_error, mirror_points, symmetric_joints
from ...rigging.training_set import RigExample
from .augmentation import turn_and_mirror, turned_columns
from .export import module_weights
from .optimisation import CosineAdam
from .rig_networks import NETWORKS

#: Weight of the attention loss beside the offset loss.
ATTENTION_LOSS_WEIGHT = 0.5
#: Most a voting vertex's attention loss is weighted over a non-voter's
#: (the weight is the ratio of non-voters to voters, clamped to [1, this]).
MAX_VOTER_WEIGHT = 20.0
#: Standard deviation of the noise added to reference joints when training
#: the bone and root networks (share of the largest side): predicted joints
#: are about this far off.
JOINT_JITTER = 0.01
#: Jittered copies of each example's joints.
JITTER_COPIES = 4

Log = Callable[[str], None]


def _stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def clustered_joints(weights: dict, example: RigExample, bandwidth: float, density_threshold: float) -> np.ndarray:
    """The joints the predictor would find on ``example`` (normalised frame)."""
    return cluster_joints(graph_votes(weights, example.graph), bandwidth, density_threshold, True)[0]


def holdout_j2j(weights: dict, holdout: list, bandwidth: float, density_threshold: float) -> float:
    scores = []
    for example in holdout:
        joints = clustered_joints(weights, example, bandwidth, density_threshold)
        scores.append(chamfer_j2j(joints, example.joints) if len(joints) else 1.0)
    return float(np.mean(scores))


def train_joint_network(train: list, holdout: list, *, epochs: int, learning_rate: float, seed: int = 0,
                        device: str = "cpu", bandwidth: float, density_threshold: float,
                        log: Log = _stderr) -> tuple[dict, dict]:
    """Train the joint network; returns the kept weights and the run's record."""
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    model = NETWORKS["joints"]().to(device)
    tensors = []
    for example in train:
        graph = example.graph
        tensors.append(tuple(torch.as_tensor(np.asarray(value)).to(device) for value in (
            graph.vertex_features, graph.mesh_edges, graph.ball_edges, graph.vertices.astype(np.float32),
            example.target_points, example.attention)))
    optimiser = CosineAdam(model.parameters(), learning_rate, epochs * len(tensors))
    record = {"network": "joints", "seed": seed, "epochs": epochs, "learning_rate": learning_rate, "device": device,
              "train_examples": len(train), "holdout": sorted({e.name.split("#")[0] for e in holdout}),
              "parameters": sum(p.numel() for p in model.parameters()), "history": []}
    best, best_epoch = module_weights(model), 0
    best_score = holdout_j2j(best, holdout, bandwidth, density_threshold)
    record["history"].append({"epoch": 0, "loss": None, "holdout_cd_j2j": best_score})
    log(f"joints: {record['parameters']} parameters, {len(train)} examples, untrained CD-J2J {best_score:.4f}")
    started = time.perf_counter()
    for epoch in range(1, epochs + 1):
        model.train()
        losses = []
        for index in rng.permutation(len(tensors)):
            features, mesh_edges, ball_edges, vertices, target, attention = tensors[index]
            matrix = torch.as_tensor(turn_and_mirror(rng), dtype=torch.float32, device=device)
            offsets, logits = model(turned_columns(features, VERTEX_VECTORS, matrix), mesh_edges, ball_edges)
            moved = vertices @ matrix.T + offsets
            offset_loss = (moved - target @ matrix.T).abs().sum(dim=1).mean()
            voters = attention.sum().clamp_min(1.0)
            balance = (len(attention) - voters) / voters
            attention_loss = torch.nn.functional.binary_cross_entropy_with_logits(
                logits, attention, pos_weight=balance.clamp(1.0, MAX_VOTER_WEIGHT))
            loss = offset_loss + ATTENTION_LOSS_WEIGHT * attention_loss
            optimiser.step(loss)
            losses.append(loss.item())
        model.eval()
        weights = module_weights(model)
        score = holdout_j2j(weights, holdout, bandwidth, density_threshold)
        record["history"].append({"epoch": epoch, "loss": float(np.mean(losses)), "holdout_cd_j2j": score})
        kept = score < best_score
        if kept:
            best, best_epoch, best_score = weights, epoch, score
        elapsed = time.perf_counter() - started
        log(f"joints epoch {epoch}/{epochs} loss {np.mean(losses):.4f} holdout CD-J2J {score:.4f}"
            f"{' (kept)' if kept else ''} {elapsed:.0f} s, ~{elapsed / epoch * (epochs - epoch):.0f} s left")
    record.update(best_epoch=best_epoch, best_score=best_score, seconds=time.perf_counter() - started)
    return best, record


def _jittered_joints(example: RigExample, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Jittered reference joints, symmetric again on a symmetric character,
    and each joint's twin (-1: none)."""
    joints = example.joints + rng.normal(0.0, JOINT_JITTER, example.joints.shape)
    if mirror_error(example.graph.vertices, 0) > SYMMETRY_TOLERANCE:
        return joints, np.full(len(joints), -1, dtype=np.int64)
    # Jitter each twin pair alike (mirrored), as the predictor's symmetric joints are.
    _, twins = symmetric_joints(example.joints, 2 * JOINT_JITTER)
    twins = twins[:len(example.joints)]
    for joint, twin in enumerate(twins):
        if twin > joint and twin < len(joints):
            joints[twin] = mirror_points(joints[joint][None])[0]
        elif twin < 0 and abs(example.joints[joint, 0]) <= 2 * JOINT_JITTER:
            joints[joint, 0] = 0.0
    return joints, np.where(twins < len(joints), twins, -1)


def connectivity_data(examples: list, rng: np.random.Generator) -> dict:
    """Pair features and labels, root features and root index, per jittered copy."""
    pairs_x, pairs_y, roots = [], [], []
    for example in examples:
        solid = solid_depth(example.mesh)
        bones = {(min(a, b), max(a, b)) for b, a in enumerate(example.parents.tolist()) if a >= 0}
        root = int(np.flatnonzero(example.parents < 0)[0])
        for _ in range(JITTER_COPIES):
            joints, twins = _jittered_joints(example, rng)
            pairs = candidate_pairs(joints)
            pairs_x.append(pair_features(joints, pairs, solid, twins))
            pairs_y.append(np.array([(a, b) in bones for a, b in pairs.tolist()], dtype=np.float32))
            roots.append((root_features(joints, solid), root))
    return {"pair_features": np.concatenate(pairs_x), "pair_labels": np.concatenate(pairs_y), "roots": roots}


def _root_loss(model, roots: list, device: str) -> torch.Tensor:
    losses = []
    for features, root in roots:
        scores = model(torch.as_tensor(features, device=device))
        losses.append(torch.nn.functional.cross_entropy(scores[None], torch.tensor([root], device=device)))
    return torch.stack(losses).mean()


def _bone_loss(model, data: dict, device: str) -> torch.Tensor:
    labels = torch.as_tensor(data["pair_labels"], device=device)
    logits = model(torch.as_tensor(data["pair_features"], device=device))
    return torch.nn.functional.binary_cross_entropy_with_logits(logits, labels)


def train_connectivity_network(network: str, train: list, holdout: list, *, epochs: int, learning_rate: float,
                               seed: int = 0, device: str = "cpu", log: Log = _stderr) -> tuple[dict, dict]:
    """Train ``bones`` or ``root``; returns the kept weights and the run's record."""
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    model = NETWORKS[network]().to(device)
    train_data, held_data = connectivity_data(train, rng), connectivity_data(holdout, rng)
    loss_of = _bone_loss if network == "bones" else (lambda m, d, dev: _root_loss(m, d["roots"], dev))
    every = train_data["pair_features"] if network == "bones" else np.concatenate([f for f, _ in train_data["roots"]])
    model.standardise_from(torch.as_tensor(every, device=device))
    optimiser = CosineAdam(model.parameters(), learning_rate, epochs)
    record = {"network": network, "seed": seed, "epochs": epochs, "learning_rate": learning_rate, "device": device,
              "train_examples": len(train), "holdout": sorted({e.name.split("#")[0] for e in holdout}),
              "parameters": sum(p.numel() for p in model.parameters()), "history": []}
    best, best_epoch, best_loss = module_weights(model), 0, float("inf")
    started = time.perf_counter()
    for epoch in range(1, epochs + 1):
        model.train()
        loss = loss_of(model, train_data, device)
        optimiser.step(loss)
        model.eval()
        with torch.no_grad():
            held = float(loss_of(model, held_data, device))
        if held < best_loss:
            best, best_epoch, best_loss = module_weights(model), epoch, held
        if epoch % 100 == 0 or epoch == epochs:
            record["history"].append({"epoch": epoch, "loss": float(loss), "holdout_loss": held})
            log(f"{network} epoch {epoch}/{epochs} loss {float(loss):.4f} holdout {held:.4f}")
    record.update(best_epoch=best_epoch, best_score=best_loss, seconds=time.perf_counter() - started)
    record.update(connectivity_accuracy(network, best, held_data))
    return best, record


def connectivity_accuracy(network: str, weights: dict, data: dict) -> dict:
    """Held-out accuracy: bone pairs classified right, roots picked right."""
    if network == "bones":
        predicted = bone_probabilities(weights, data["pair_features"]) > 0.5
        return {"holdout_accuracy": float(np.mean(predicted == (data["pair_labels"] > 0.5)))}
    right = [int(np.argmax(root_scores(weights, features))) == root for features, root in data["roots"]]
    return {"holdout_accuracy": float(np.mean(right))}
