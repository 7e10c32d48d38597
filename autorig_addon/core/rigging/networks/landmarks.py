"""The landmark network: where each key joint of a standard skeleton lies, and what kind of body it is.

Make-It-Animatable (Guo et al., CVPR 2025) places a fixed template's joints
by letting every vertex vote for every template joint; we do the same on
RigNet's trunk (:mod:`.joints`, whose trained trunk it starts from). Per
vertex and per landmark of :data:`...skeleton.key_joints.KEY_JOINTS` (hips,
neck, head, and per side shoulder, elbow, wrist, hip, knee, ankle), an
*offset* from the vertex to the landmark and a *weight* logit; a landmark is
the weighted mean of its votes, the weights a softmax over the vertices. A
third head reads the shape code and says the kind of body: biped,
quadruped or other (:data:`BODY_KINDS`).

Two runs of it are shipped (:data:`SPEC`, :data:`LONG_SPEC`): the same
network trained for 70 and for 100 epochs. The standard skeletons take the
mean of their landmarks and the kind from the first
(:func:`..standard_skeleton.predict_landmarks`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...dataset.sample import CharacterSample
from ...nn.convolution import gmedge_trunk
from ...nn.layers import mlp
from ...nn.operations import Array, Operations
from ...nn.spec import Dense, NetworkSpec, TrainingSettings
from ...skeleton.key_joints import KEY_JOINTS, key_joints
from ..joint_features import JointGraph
from .joints import TRUNK, WIDTH
from .trained import TRAINED_FOLDER

#: The landmarks, in output order.
LANDMARKS = KEY_JOINTS
#: Kinds of body the network tells apart, in output order.
BODY_KINDS = ("biped", "quadruped", "other")
#: The kinds with a standard skeleton.
STANDARD_KINDS = BODY_KINDS[:2]
#: The split's kinds of character (and the procedural generator's) and the body kind each teaches.
CATEGORY_KINDS = {"humanoid": "biped", "quadruped": "quadruped", "biped": "biped"}


def landmark_network(ops: Operations, params: dict, graph: JointGraph) -> tuple[Array, Array]:
    """Landmark positions and body-kind logits.

    Returns
    -------
    landmarks : (k, 3) float array, normalised units, in :data:`LANDMARKS` order
    kind_logits : (1, 3) float array, in :data:`BODY_KINDS` order
    """
    joined = gmedge_trunk(ops, params, graph.vertex_features, graph.mesh_edges, graph.ball_edges, TRUNK.blocks,
                          activation=SPEC.activation)
    count = len(LANDMARKS)
    offsets = mlp(ops, params, joined, "offset.", activation=SPEC.activation, activate_last=False)
    weights = ops.column_softmax(mlp(ops, params, joined, "weight.", activation=SPEC.activation,
                                     activate_last=False))
    vertices = graph.vertex_features[:, :3]  # the position columns: float32, turned with the features in training
    votes = vertices[:, None, :] + offsets.reshape(offsets.shape[0], count, 3)
    landmarks = (weights[:, :, None] * votes).sum(0)
    kind_logits = mlp(ops, params, joined[:1, -TRUNK.shape_width:], "kind.", activation=SPEC.activation,
                      activate_last=False)
    return landmarks, kind_logits


def sample_landmarks(sample: CharacterSample) -> tuple[np.ndarray, np.ndarray, int]:
    """(k, 3) landmark targets (normalised frame), (k,) which are known, and the body kind's index."""
    found = key_joints(sample.names, sample.joints, left_direction=np.array([1.0, 0.0, 0.0]),
                       parents=sample.parents).positions
    targets = np.zeros((len(LANDMARKS), 3), dtype=np.float32)
    known = np.zeros(len(LANDMARKS), dtype=np.float32)
    for index, name in enumerate(LANDMARKS):
        if name in found:
            targets[index], known[index] = found[name], 1.0
    return targets, known, BODY_KINDS.index(CATEGORY_KINDS.get(sample.category, "other"))


SPEC = NetworkSpec(
    name="landmarks",
    label="Landmarks",
    description="Places the key joints of a standard biped or quadruped skeleton and tells the kind of body",
    inputs="JointGraph",
    layers=(TRUNK, Dense("offset", (TRUNK.out_width, 2 * WIDTH, WIDTH, 3 * len(LANDMARKS))),
            Dense("weight", (TRUNK.out_width, WIDTH, len(LANDMARKS))),
            Dense("kind", (TRUNK.shape_width, WIDTH, len(BODY_KINDS)))),
    forward=landmark_network,
    # About 40 s an epoch of 138 family-sampled steps on one CPU thread; the held-out error still fell
    # from epoch 50 to 60 of a 60-epoch run (docs/models.md).
    training=TrainingSettings(epochs=70, learning_rate=2e-3),
    weights_file=TRAINED_FOLDER / "landmarks.npz",
)

#: The same network trained longer (100 epochs, the same seed and data). Alone it places the held-out training
#: characters' landmarks better than :data:`SPEC` and the validation characters' worse; the mean of the two places
#: both better than either (docs/models.md, *Landmark network*).
LONG_SPEC = replace(
    SPEC,
    name="landmarks_long",
    label="Landmarks (long run)",
    description="The landmark network trained longer; its landmarks are averaged with the landmark network's",
    training=TrainingSettings(epochs=100, learning_rate=2e-3),
    weights_file=TRAINED_FOLDER / "landmarks_long.npz",
)
#: The landmark networks' names (``train rig --model``).
LANDMARK_NETWORK_NAMES = (SPEC.name, LONG_SPEC.name)
