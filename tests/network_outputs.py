"""What the shipped networks give on small generated characters, recorded
once so a test can tell that a change of the code left every network's
output as it was (``test_shipped_network_outputs.py``).

Record again only when the shipped weights change on purpose (a retraining),
and say so in the commit::

    .venv/bin/python tests/network_outputs.py

When only the skeleton's construction changes on purpose (the networks'
outputs unchanged), record the predicted skeleton alone, and say why::

    .venv/bin/python tests/network_outputs.py --skeleton

It writes :data:`NETWORK_OUTPUTS_FILE` (float32 outputs, about 150 kB):

* each skinning network's candidate weights on the network graph of the
  procedural character of seed :data:`SKIN_SEED`, and its finished weights
  on that mesh;
* the joint network's offsets and attention on the joint graph of the same
  character, and the bone and root networks' outputs on the joints of the
  skeleton predicted for it;
* the skeleton predicted for the procedural biped of seed
  :data:`BIPED_SEED` (joints, tails, parents, names).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from autorig_addon.core.dataset.normalise import normalise
from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.nn.numpy_kernels import NUMPY, sigmoid
from autorig_addon.core.nn.spec import shipped_weights
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging import predict as rig_predict
from autorig_addon.core.rigging.connectivity import bone_probabilities, root_scores
from autorig_addon.core.rigging.joint_features import joint_graph, solid_depth
from autorig_addon.core.rigging.networks import joints, landmarks
from autorig_addon.core.rigging.orientation import up_probabilities
from autorig_addon.core.rigging.tree_features import candidate_pairs, pair_features, root_features
from autorig_addon.core.skinning.learned import predict as skin_predict
from autorig_addon.core.skinning.learned.networks import SKIN_NETWORKS

NETWORK_OUTPUTS_FILE = Path(__file__).resolve().parent / "data" / "network_outputs.npz"
#: The procedural character every network runs on (a 30-bone chain of 762 vertices).
SKIN_SEED = 5
#: A procedural biped (1,782 vertices, 29 bones) for a whole skeleton prediction.
BIPED_SEED = 23
#: Voxel resolution of the distances and depths (the default 96 is slower and
#: changes nothing these records check).
RESOLUTION = 32


def sample_of(seed: int) -> CharacterSample:
    character = generate_character(seed)
    return CharacterSample.from_character(f"procedural_{seed}", character.kind, character.mesh, character.skeleton,
                                          character.weights)


def skin_outputs() -> dict:
    """``skin.NAME.candidates`` (n, K) and ``skin.NAME.weights`` (n, d) per network."""
    sample = sample_of(SKIN_SEED)
    normalised = normalise(sample.mesh, sample.skeleton.deform_subset())
    arrays = {}
    for name, spec in SKIN_NETWORKS.items():
        graph = skin_predict.network_graph(normalised.mesh, normalised.skeleton, spec.distance, prior=spec.prior,
                                           resolution=RESOLUTION)
        arrays[f"skin.{name}.candidates"] = skin_predict.network_candidate_weights(spec, graph).astype(np.float32)
        weights = skin_predict.learned_weights(sample.mesh, sample.skeleton, name, resolution=RESOLUTION)
        arrays[f"skin.{name}.weights"] = weights.matrix.astype(np.float32)
    return arrays


def rig_outputs() -> dict:
    """The landmark network's ``landmarks.points`` (15, 3) and
    ``landmarks.kind_logits`` (1, 3), its longer run's ``landmarks_long.points``, the joint network's ``joints.offsets``
    (n, 3) and ``joints.attention`` (n,), the upright network's ``upright.probabilities`` (4,), then
    ``bones.probabilities`` and ``root.scores`` on the character's
    own joints (fixed inputs: joints a mean shift finds can move by more than
    the tolerance with the number of BLAS threads, which the predicted
    skeleton's record covers)."""
    sample = sample_of(SKIN_SEED)
    mesh = sample.mesh
    solid = solid_depth(mesh, RESOLUTION)
    graph = joint_graph(mesh, solid)
    weights = shipped_weights(joints.SPEC).weights
    offsets, logits = joints.SPEC.forward(NUMPY, weights, graph)
    found = sample.skeleton.joints
    mirror = np.full(len(found), -1)  # no twins: a fixed input is all this needs
    pairs = candidate_pairs(found)
    points, kind_logits = landmarks.SPEC.forward(NUMPY, shipped_weights(landmarks.SPEC).weights, graph)
    longer, _ = landmarks.LONG_SPEC.forward(NUMPY, shipped_weights(landmarks.LONG_SPEC).weights, graph)
    return {
        "landmarks.points": np.asarray(points, dtype=np.float32),
        "landmarks.kind_logits": np.asarray(kind_logits, dtype=np.float32),
        "landmarks_long.points": np.asarray(longer, dtype=np.float32),
        "joints.offsets": offsets.astype(np.float32),
        "joints.attention": sigmoid(logits).astype(np.float32),
        "bones.probabilities": bone_probabilities(pair_features(found, pairs, solid, mirror)).astype(np.float32),
        "root.scores": root_scores(root_features(found, solid)).astype(np.float32),
        "upright.probabilities": up_probabilities(mesh.vertices, mesh.triangles).astype(np.float32),
    }


def skeleton_outputs() -> dict:
    """The skeleton predicted for the biped, in its own space."""
    skeleton = rig_predict.predict_skeleton(sample_of(BIPED_SEED).mesh)
    return {"skeleton.joints": skeleton.joints.astype(np.float32),
            "skeleton.tails": skeleton.tails.astype(np.float32),
            "skeleton.parents": skeleton.parents.astype(np.int64),
            "skeleton.names": np.asarray(skeleton.names)}


def record(skeleton_only: bool = False) -> None:
    if skeleton_only:
        with np.load(NETWORK_OUTPUTS_FILE) as recorded:
            arrays = {**{name: recorded[name] for name in recorded.files}, **skeleton_outputs()}
    else:
        arrays = {**skin_outputs(), **rig_outputs(), **skeleton_outputs()}
    NETWORK_OUTPUTS_FILE.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(NETWORK_OUTPUTS_FILE, **arrays)
    print(f"{len(arrays)} arrays in {NETWORK_OUTPUTS_FILE} ({NETWORK_OUTPUTS_FILE.stat().st_size / 1e3:.0f} kB)",
          file=sys.stderr)


if __name__ == "__main__":
    if set(sys.argv[1:]) - {"--skeleton"}:
        # Anything else (a --help) must not overwrite the record.
        sys.exit(f"usage: {Path(sys.argv[0]).name} [--skeleton]  (see the module docstring)")
    record(skeleton_only="--skeleton" in sys.argv[1:])
