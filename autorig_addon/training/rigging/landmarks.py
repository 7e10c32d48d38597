"""Training the landmark network (``train rig --model landmarks``).

Targets come from the artists' own bone names
(:func:`...core.skeleton.key_joints.key_joints`, sides read in the
normalised frame, whose +X is the character's left): every training
character whose names say its key joints gives the landmarks they say; a
landmark a rig lacks (KayKit has no neck) is left out of the loss. The kind
of body is the split's (``humanoid`` is a biped, ``quadruped`` a quadruped,
the rest other), so fish, birds and props teach the kind head too.

The examples are the joint network's (:mod:`.training_set`, the same
proxies and stretched variants); a variant's landmarks are the character's
moved by the per-axis scale and shift that take its reference joints onto
the variant's. Epochs are family-sampled as the joint network's; each step
turns the example a little about the up axis and mirrors it half the time,
swapping the left and right landmarks with it. The trunk starts from the
shipped joint network's, which already finds joints.

Loss: the mean distance from each known landmark to its target, plus
:data:`KIND_LOSS_WEIGHT` times the kind's cross-entropy. The kept epoch has
the lowest mean held-out landmark error.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import torch

from ...core.dataset.sample import CharacterSample
from ...core.nn.numpy_kernels import NUMPY
from ...core.nn.spec import shipped_weights
from ...core.rigging.joint_features import VERTEX_VECTORS
from ...core.rigging.networks import rig_network
from ...core.rigging.networks.landmarks import sample_landmarks
from ...core.skeleton.key_joints import KEY_JOINT_TWINS
from ..nn.augmentation import turn_and_mirror, turned_columns
from ..nn.fit import FitRecord, fit
from ..nn.modules import NetworkModule, as_tensors
from ..nn.torch_kernels import TORCH
from ..runs import character_families, epoch_step_count, epoch_steps
from .proportions import VARIANT_MARK, source_character
from .training_set import RigExample, reference_skeleton

#: Weight of the kind's cross-entropy beside the landmark distance (normalised units).
KIND_LOSS_WEIGHT = 0.05
#: The kind of a proportion variant: none taught. Reshaped bipeds taught as bipeds moved the kind head (validation
#: standing monsters read as "other"), so the variants teach where the landmarks lie and the kind is learnt from the
#: characters' own shapes, as before.
UNTAUGHT_KIND = -1
#: Trunk parameters taken from the joint network before training.
TRUNK_PREFIXES = ("encoder.", "gmedge", "shape.")


def variant_landmarks(sample: CharacterSample, example: RigExample, targets: np.ndarray) -> np.ndarray:
    """``targets`` moved as the variant moved the reference joints: a scale
    and shift per axis (the stretch and the normalisation), fitted by least
    squares."""
    source = reference_skeleton(sample).joints
    moved = np.empty_like(targets)
    for axis in range(3):
        design = np.stack([source[:, axis], np.ones(len(source))], axis=1)
        (scale, shift), *_ = np.linalg.lstsq(design, example.joints[:, axis], rcond=None)
        moved[:, axis] = scale * targets[:, axis] + shift
    return moved


def landmark_data(samples: dict, examples: list) -> list:
    """(graph, targets, known, kind) per example; ``kind`` is
    :data:`UNTAUGHT_KIND` for a proportion variant (:mod:`.proportions`),
    which teaches the landmarks alone."""
    data = []
    for example in examples:
        sample = samples[example.name.rsplit("#", 1)[0]]
        targets, known, kind = sample_landmarks(sample)
        if VARIANT_MARK in example.name:
            kind = UNTAUGHT_KIND
        data.append((example.graph, variant_landmarks(sample, example, targets).astype(np.float32), known, kind))
    return data


def landmark_loss(module: NetworkModule, item: tuple, matrix: np.ndarray) -> torch.Tensor:
    """The loss of one example turned (and perhaps mirrored) by ``matrix``."""
    graph, targets, known, kind = item
    turn = torch.as_tensor(matrix, dtype=torch.float32, device=targets.device)
    if np.linalg.det(matrix) < 0:
        order = torch.as_tensor(KEY_JOINT_TWINS, device=targets.device)
        targets, known = targets[order], known[order]
    turned = replace(graph, vertex_features=turned_columns(TORCH, graph.vertex_features, VERTEX_VECTORS, turn))
    landmarks, logits = module(turned)
    distances = ((landmarks - targets @ turn.T) ** 2).sum(dim=1).clamp_min(1e-12).sqrt()
    landmark_term = (distances * known).sum() / known.sum().clamp_min(1.0)
    if kind == UNTAUGHT_KIND:
        return landmark_term
    kind_term = torch.nn.functional.cross_entropy(logits, torch.as_tensor([kind], device=targets.device))
    return landmark_term + KIND_LOSS_WEIGHT * kind_term


def holdout_scores(spec, weights: dict, holdout: list) -> dict:
    """Mean error of the known landmarks (normalised units) and the kind's accuracy, numpy forward."""
    errors, right = [], []
    for graph, targets, known, kind in holdout:
        landmarks, logits = spec.forward(NUMPY, weights, graph)
        distances = np.linalg.norm(np.asarray(landmarks) - targets, axis=1)
        errors.extend(distances[known > 0].tolist())
        right.append(int(np.argmax(logits)) == kind)
    return {"landmark_error": float(np.mean(errors)) if errors else 1.0, "kind_accuracy": float(np.mean(right))}


def start_from_joint_trunk(module: NetworkModule) -> None:
    """Copy the shipped joint network's trunk into ``module``."""
    trunk = {name: value for name, value in shipped_weights(rig_network("joints")).weights.items()
             if name.startswith(TRUNK_PREFIXES)}
    state = module.state_dict()
    for name, value in trunk.items():
        if name in state and tuple(state[name].shape) == tuple(value.shape):
            state[name] = torch.from_numpy(np.array(value))
    module.load_state_dict(state)


def train_landmark_network(samples: dict, train: list, holdout: list, record: FitRecord) -> dict:
    """Train the landmark network (torch seeded by the caller); returns the kept weights."""
    rng = np.random.default_rng(record.seed)
    spec = rig_network(record.network)  # either landmark network: they differ in their runs only
    module = NetworkModule(spec).to(record.device)
    start_from_joint_trunk(module)
    train_data = landmark_data(samples, train)
    held_data = landmark_data(samples, holdout)
    tensors = [(as_tensors(graph, record.device), torch.as_tensor(targets, device=record.device),
                torch.as_tensor(known, device=record.device), kind) for graph, targets, known, kind in train_data]
    characters = [source_character(example.name) for example in train]
    families = character_families(characters)
    steps = epoch_step_count(characters, families)
    record.details.update(train_characters=len(set(characters)), steps_per_epoch=steps,
                          characters_with_landmarks=len({name for name, (_, _, known, _) in
                                                         zip(characters, train_data) if known.any()}))

    def epoch_losses():
        for index in epoch_steps(characters, families, rng):
            yield lambda index=index: landmark_loss(module, tensors[index], turn_and_mirror(rng))

    return fit(module, epoch_losses, lambda weights: holdout_scores(spec, weights, held_data), record=record,
               steps_per_epoch=steps)
