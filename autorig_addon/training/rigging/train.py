"""Training the skeleton networks: what ``python -m autorig_addon train rig
--model NAME`` does.

The training characters of ``data_split.json`` are read from the sample
cache; their examples with stretched variants are built once or reused
(:mod:`.training_set`); every :data:`..runs.HOLDOUT_EVERY`-th character
(sorted by name) is held out to pick the epoch and scored as it is, not on
its stretched copies. Then :func:`..nn.fit.fit`:

* ``joints``: one character per step, at most
  :data:`..runs.CHARACTERS_PER_FAMILY` of each skeleton family per epoch,
  each as itself or one of its stretched variants drawn at random
  (:func:`..runs.epoch_steps`), turned by a random angle about the up
  axis and mirrored with probability one half (:mod:`..nn.augmentation`;
  the feature columns of :data:`...core.rigging.joint_features.VERTEX_VECTORS`
  and the targets turn with it). Loss: the L1 distance between each moved
  vertex and its target joint, plus the binary cross-entropy of the
  attention against the voting vertices (weighted so voters and non-voters
  count alike, up to :data:`MAX_VOTER_WEIGHT`). The kept epoch has the
  lowest held-out CD-J2J of the joints the numpy forward pass and the mean
  shift at the default bandwidth find.
* ``bones`` and ``root``: the reference joints of every example of at most
  :data:`..runs.CHARACTERS_PER_FAMILY` characters per skeleton family (the
  first by name), jittered (:data:`JOINT_JITTER`) a few times
  (:data:`JITTER_COPIES`), give pair and joint features once; full-batch
  training; the epoch with the lowest held-out loss is kept.

Every network is scored on at most :data:`SCORED_PER_FAMILY` held-out
characters per family.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Optional

import numpy as np
import torch

from ...core.dataset.cache import default_cache_dir, training_samples
from ...core.dataset.split import PURPOSE_SKELETON
from ...core.evaluation.skeleton_metrics import chamfer_j2j
from ...core.nn.spec import NetworkSpec
from ...core.rigging.connectivity import bone_probabilities, root_scores
from ...core.rigging.joint_features import VERTEX_VECTORS, solid_depth
from ...core.rigging.networks import rig_network
from ...core.rigging.networks.landmarks import LANDMARK_NETWORK_NAMES, sample_landmarks
from ...core.rigging.predict import DEFAULT_BANDWIDTH, DEFAULT_DENSITY_THRESHOLD, cluster_joints, graph_votes
from ...core.rigging.symmetry import SYMMETRY_TOLERANCE, mirror_error, mirror_points, symmetric_joints
from ...core.rigging.tree_features import candidate_pairs, pair_features, root_features
from ..nn.augmentation import turn_and_mirror, turned_columns
from ..nn.fit import FitRecord, fit
from ..nn.modules import NetworkModule, as_tensors
from ..nn.torch_kernels import TORCH
from ..runs import (
    CHARACTERS_PER_FAMILY,
    character_families,
    epoch_step_count,
    epoch_steps,
    family_sample,
    held_out_names,
    procedural_samples,
    start_run,
    write_weights,
)
from .landmarks import train_landmark_network
from .proportions import DEFAULT_PROPORTION_VARIANTS, reshaped_variants
from .training_set import EXAMPLE_FORMAT_VERSION, RigExample, build_examples
from .upright import copies_per_character, upright_data

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
#: Held-out characters per skeleton family every skeleton network is scored
#: on after each epoch: for the joint network the mean shift takes about
#: 1.5 s a character, and the 54 held-out characters (22 of them 0 A.D.
#: humans on one skeleton) would take most of each epoch's time and weigh
#: one family most.
SCORED_PER_FAMILY = 2
#: The held-out score each network's epoch is chosen by (lower is better).
SCORE_NAMES = {"joints": "cd_j2j", "landmarks": "landmark_error", "landmarks_long": "landmark_error",
               "bones": "cross_entropy", "root": "cross_entropy", "upright": "cross_entropy"}
#: Networks trained full batch on a fixed family sample of characters.
FULL_BATCH_NETWORKS = ("bones", "root")
#: Epochs between progress lines (and history entries) of the full-batch networks.
FULL_BATCH_LOG_EVERY = 100


def default_examples_dir(seed: int) -> Path:
    return default_cache_dir().parent / "rig_examples" / f"v{EXAMPLE_FORMAT_VERSION}" / f"seed{seed}"


def clustered_joints(weights: dict, example: RigExample, bandwidth: float, density_threshold: float) -> np.ndarray:
    """The joints the predictor would find on ``example`` (normalised frame)."""
    return cluster_joints(graph_votes(weights, example.graph), bandwidth, density_threshold, True)[0]


def holdout_j2j(weights: dict, holdout: list, bandwidth: float = DEFAULT_BANDWIDTH,
                density_threshold: float = DEFAULT_DENSITY_THRESHOLD) -> float:
    """Mean CD-J2J of the clustered joints over the held-out examples (1 where none is found)."""
    scores = []
    for example in holdout:
        joints = clustered_joints(weights, example, bandwidth, density_threshold)
        scores.append(chamfer_j2j(joints, example.joints) if len(joints) else 1.0)
    return float(np.mean(scores))


def joint_loss(module: NetworkModule, tensors: tuple, matrix: torch.Tensor) -> torch.Tensor:
    """The joint network's loss on one example turned by ``matrix``."""
    graph, vertices, target, attention = tensors
    turned = replace(graph, vertex_features=turned_columns(TORCH, graph.vertex_features, VERTEX_VECTORS, matrix))
    offsets, logits = module(turned)
    moved = vertices @ matrix.T + offsets
    offset_loss = (moved - target @ matrix.T).abs().sum(dim=1).mean()
    voters = attention.sum().clamp_min(1.0)
    balance = (len(attention) - voters) / voters
    attention_loss = torch.nn.functional.binary_cross_entropy_with_logits(
        logits, attention, pos_weight=balance.clamp(1.0, MAX_VOTER_WEIGHT))
    return offset_loss + ATTENTION_LOSS_WEIGHT * attention_loss


def train_joint_network(train: list, holdout: list, record: FitRecord) -> dict:
    """Train the joint network (torch seeded by the caller); returns the kept weights."""
    rng = np.random.default_rng(record.seed)
    module = NetworkModule(rig_network("joints")).to(record.device)
    tensors = [tuple(as_tensors(value, record.device) for value in (
        example.graph, example.graph.vertices.astype(np.float32), example.target_points, example.attention))
        for example in train]
    characters = [example_character(example.name) for example in train]
    families = character_families(characters)
    steps = epoch_step_count(characters, families)
    record.details.update(train_characters=len(set(characters)), steps_per_epoch=steps)

    def epoch_losses():
        for index in epoch_steps(characters, families, rng):
            yield lambda: joint_loss(module, tensors[index], torch.as_tensor(
                turn_and_mirror(rng), dtype=torch.float32, device=record.device))

    return fit(module, epoch_losses, lambda weights: {"cd_j2j": holdout_j2j(weights, holdout)}, record=record,
               steps_per_epoch=steps)


def example_character(name: str) -> str:
    """The character an example was made from (its name is ``CHARACTER#VARIANT``)."""
    return name.rsplit("#", 1)[0]


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
    """Pair features and labels, and root features with each jittered copy's
    root, per jittered copy: ``roots`` lists ``(features, root)`` per copy;
    ``root_features``, ``root_copy`` (the copy of each row) and ``root_rows``
    (each copy's root row) hold the same stacked, for one batched loss."""
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
    counts = np.array([len(features) for features, _ in roots], dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    return {"pair_features": np.concatenate(pairs_x), "pair_labels": np.concatenate(pairs_y), "roots": roots,
            "root_features": np.concatenate([features for features, _ in roots]),
            "root_copy": np.repeat(np.arange(len(roots)), counts),
            "root_rows": starts + np.array([root for _, root in roots], dtype=np.int64)}


def connectivity_loss(spec: NetworkSpec, params: dict, data: dict, device: str) -> torch.Tensor:
    """The bone network's binary cross-entropy over every pair, or the root
    network's cross-entropy over each copy's joints (all copies at once: a
    log-sum-exp per copy)."""
    if spec.name == "bones":
        logits = spec.forward(TORCH, params, torch.as_tensor(data["pair_features"], device=device))
        return torch.nn.functional.binary_cross_entropy_with_logits(
            logits, torch.as_tensor(data["pair_labels"], device=device))
    scores = spec.forward(TORCH, params, torch.as_tensor(data["root_features"], device=device))
    copy = torch.as_tensor(data["root_copy"], device=device)
    copies = len(data["roots"])
    highest = torch.full((copies,), -torch.inf, device=device).scatter_reduce(0, copy, scores.detach(), "amax")
    sums = torch.zeros(copies, device=device).index_add(0, copy, torch.exp(scores - highest[copy]))
    log_partition = highest + torch.log(sums)
    return (log_partition - scores[torch.as_tensor(data["root_rows"], device=device)]).mean()


def connectivity_accuracy(network: str, weights: dict, data: dict) -> float:
    """Held-out accuracy of the numpy forward: bone pairs classified right, or roots picked right."""
    if network == "bones":
        predicted = bone_probabilities(data["pair_features"], weights) > 0.5
        return float(np.mean(predicted == (data["pair_labels"] > 0.5)))
    return float(np.mean([int(np.argmax(root_scores(features, weights))) == root for features, root in data["roots"]]))


def train_connectivity_network(spec: NetworkSpec, train: list, holdout: list, record: FitRecord) -> dict:
    """Train ``bones`` or ``root`` (torch seeded by the caller); returns the kept weights."""
    rng = np.random.default_rng(record.seed)
    return train_full_batch(spec, connectivity_data(train, rng), connectivity_data(holdout, rng), record)


def train_full_batch(spec: NetworkSpec, train_data: dict, held_data: dict, record: FitRecord) -> dict:
    """Train a network that scores rows (``bones``: pairs; ``root`` and
    ``upright``: candidates, one softmax per copy) full batch on data in
    :func:`connectivity_data`'s layout; returns the kept weights."""
    module = NetworkModule(spec).to(record.device)
    features = train_data["pair_features" if spec.name == "bones" else "root_features"]
    module.standardise_from(torch.as_tensor(features, device=record.device))

    def held_loss(weights: dict) -> dict:
        params = {name: torch.as_tensor(value, device=record.device) for name, value in weights.items()}
        return {"cross_entropy": float(connectivity_loss(spec, params, held_data, record.device))}

    best = fit(module, lambda: [lambda: connectivity_loss(spec, module.params(), train_data, record.device)],
               held_loss, record=record, steps_per_epoch=1, log_every=FULL_BATCH_LOG_EVERY)
    record.details["holdout_accuracy"] = connectivity_accuracy(spec.name, best, held_data)
    return best


def run_rig_training(network: str, *, sample_dir: Path, examples_dir: Optional[Path] = None,
                     epochs: Optional[int] = None, learning_rate: Optional[float] = None, seed: int = 0,
                     device: str = "auto", output: Optional[Path] = None, procedural: int = 0,
                     proportion_variants: int = DEFAULT_PROPORTION_VARIANTS) -> FitRecord:
    """Train ``network`` (any of ``core.rigging.networks.NETWORK_NAMES``) and write its weights; returns the record.

    ``procedural`` adds the procedural characters of seeds ``0 .. procedural - 1``
    (exact skeletons) as training characters; they are never held out, so
    the epoch is still chosen on artists' rigs. ``proportion_variants``: the
    landmark network also trains on that many reshaped copies
    (:mod:`.proportions`) of each training character with key joints.
    """
    spec = rig_network(network)
    record = start_run(spec, seed=seed, device=device, epochs=epochs, learning_rate=learning_rate,
                       score_name=SCORE_NAMES.get(network, "cross_entropy"))
    folder = Path(examples_dir or default_examples_dir(seed))
    samples = training_samples(Path(sample_dir), purpose=PURPOSE_SKELETON)
    if network == "upright":
        # The upright network reads the samples' shapes alone: no examples (graphs, stretched variants) needed.
        write_weights(spec, _train_upright(spec, samples, record), record, output)
        return record
    examples = build_examples(samples, folder, seed)
    names = sorted(examples)
    held_out = held_out_names(names)
    families = character_families(names)
    # Scored: at most SCORED_PER_FAMILY held-out characters of a family, as they are (not stretched).
    held_names = set(family_sample(sorted(held_out), families, SCORED_PER_FAMILY))
    trained = [name for name in names if name not in held_out]
    if network in FULL_BATCH_NETWORKS:
        # Full batch, so no epoch redraws the families: a fixed sample of each family's characters.
        trained = family_sample(trained, families, CHARACTERS_PER_FAMILY)
    procedural_made = procedural_samples(procedural)
    made = build_examples(procedural_made, folder, seed)
    train = [example for name in trained for example in examples[name]]
    train += [example for name in sorted(made) for example in made[name]]
    holdout = [examples[name][0] for name in names if name in held_names]
    record.details.update(train_examples=len(train), holdout=sorted(held_names), procedural=procedural)
    if network == "joints":
        weights = train_joint_network(train, holdout, record)
    elif network in LANDMARK_NETWORK_NAMES:
        # Other proportions (short legs, big heads) of the trained characters with key joints, as more copies of
        # each. Not of the rest: with every character reshaped, more validation bipeds were read as "other".
        trained_names = set(trained)
        with_landmarks = [sample for sample in samples
                          if sample.name in trained_names and sample_landmarks(sample)[1].any()]
        reshaped = reshaped_variants(with_landmarks, seed, proportion_variants)
        variants = build_examples(reshaped, folder / "proportions", seed, variants=0)
        train += [example for name in sorted(variants) for example in variants[name]]
        record.details.update(train_examples=len(train), proportion_variants=len(reshaped))
        by_name = {sample.name: sample for sample in list(samples) + list(procedural_made) + reshaped}
        weights = train_landmark_network(by_name, train, holdout, record)
    else:
        weights = train_connectivity_network(spec, train, holdout, record)
    write_weights(spec, weights, record, output)
    return record


def _train_upright(spec: NetworkSpec, samples: list, record: FitRecord) -> dict:
    """The upright network on every training character but the held-out
    ones (every HOLDOUT_EVERY-th), families weighed alike
    (:func:`.upright.copies_per_character`); scored on at most
    SCORED_PER_FAMILY held-out characters per family, one copy each."""
    by_name = {sample.name: sample for sample in samples}
    names = sorted(by_name)
    held_out = held_out_names(names)
    families = character_families(names)
    trained = [name for name in names if name not in held_out]
    held = family_sample(sorted(held_out), families, SCORED_PER_FAMILY)
    rng = np.random.default_rng(record.seed)
    train_data = upright_data([by_name[name] for name in trained], copies_per_character(trained, families), rng)
    held_data = upright_data([by_name[name] for name in held], [1] * len(held), rng)
    record.details.update(train_characters=len(trained), train_copies=len(train_data["roots"]), holdout=held)
    return train_full_batch(spec, train_data, held_data, record)
