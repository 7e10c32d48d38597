"""Training examples of the skeleton networks, built from cached samples.

One :class:`RigExample` per character and variant: the joint network's
input graph on the proxy the predictor would build, the per-vertex targets,
and the reference joints the bone and root networks learn to connect.

* **Reference joints**: the artist's deform bones with coincident joints
  merged (what ``eval rig`` scores against).
* **Offset target**: each vertex moves to the nearer end of its closest bone
  (a bone is parent joint to child joint, RigNet's definition); taking the
  closest *bone* first keeps a vertex of one finger from voting for the
  next finger's joint.
* **Attention target**: a vertex votes when its closest bone is about as
  near as that joint, ``d_bone / d_joint >= ATTENTION_RATIO``: the rings of
  vertices around each joint and the caps beyond leaf joints, not the
  vertices halfway along a limb whose nearest joint is far.
* **Augmentation**: :data:`STRETCHED_VARIANTS` copies per character
  stretched along each axis by factors drawn log-uniformly in
  :data:`..nn.augmentation.STRETCH_RANGE` (thin and stout,
  tall and short characters), normalised again; turns and mirroring come
  at training time.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...core.dataset.normalise import apply_transform, normalisation_transform
from ...core.dataset.sample import CharacterSample
from ...core.evaluation.skeleton_metrics import COINCIDENT_JOINT_FRACTION, bone_segments, merge_coincident_joints
from ...core.geometry.proxy import simplified_proxy
from ...core.geometry.segments import closest_segments
from ...core.rigging.joint_features import PROXY_VERTICES, JointGraph, joint_graph
from ...core.types import Mesh, Skeleton
from ..nn.augmentation import STRETCH_RANGE

#: A vertex votes when its closest bone is at least this share as far as
#: the joint it moves to (1: on the joint's cross-section).
ATTENTION_RATIO = 0.95
#: Stretched copies per character, besides the character itself.
STRETCHED_VARIANTS = 4
#: Bumped whenever examples change, so old cached ones are rebuilt.
EXAMPLE_FORMAT_VERSION = 3

@dataclass(frozen=True)
class RigExample:
    """One training example (normalised frame).

    Attributes
    ----------
    name : str, character name and variant
    graph : JointGraph on the proxy
    triangles : (m, 3) int64, the proxy's triangles (the bone network's
        features measure the solid again)
    target_points : (n, 3) float32, where each proxy vertex should move
    attention : (n,) float32 in {0, 1}, whether it should vote
    joints : (j, 3) float64, reference joints
    parents : (j,) int64, reference parents (-1 root)
    """

    name: str
    graph: JointGraph
    triangles: np.ndarray
    target_points: np.ndarray
    attention: np.ndarray
    joints: np.ndarray
    parents: np.ndarray

    @property
    def mesh(self) -> Mesh:
        return Mesh(self.graph.vertices, self.triangles)


def reference_skeleton(sample: CharacterSample) -> Skeleton:
    """The sample's deform bones with coincident joints merged (normalised)."""
    return merge_coincident_joints(sample.skeleton.deform_subset(), COINCIDENT_JOINT_FRACTION)


def joint_targets(vertices: np.ndarray, skeleton: Skeleton) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) point each vertex should move to and (n,) whether it votes."""
    segments = bone_segments(skeleton)
    closest, bone_distance = closest_segments(vertices, segments[:, 0], segments[:, 1])
    ends = segments[closest]
    to_ends = np.linalg.norm(ends - vertices[:, None, :], axis=2)
    nearer = to_ends.argmin(axis=1)
    target = ends[np.arange(len(vertices)), nearer]
    joint_distance = to_ends[np.arange(len(vertices)), nearer]
    ratio = np.divide(bone_distance, joint_distance, out=np.ones_like(bone_distance), where=joint_distance > 0)
    return target.astype(np.float32), (ratio >= ATTENTION_RATIO).astype(np.float32)


def stretched(vertices: np.ndarray, joints: np.ndarray, factors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and joints stretched per axis by ``factors`` and normalised again."""
    vertices, joints = vertices * factors, joints * factors
    transform = normalisation_transform(vertices)
    return apply_transform(vertices, transform), apply_transform(joints, transform)


def rig_example(name: str, mesh: Mesh, skeleton: Skeleton) -> RigExample:
    """The example of a normalised character (mesh and reference skeleton)."""
    proxy = simplified_proxy(mesh, PROXY_VERTICES).mesh
    graph = joint_graph(proxy)
    target, attention = joint_targets(graph.vertices, skeleton)
    return RigExample(name, graph, proxy.triangles, target, attention, skeleton.joints, skeleton.parents)


def sample_examples(sample: CharacterSample, rng: np.random.Generator,
                    variants: int = STRETCHED_VARIANTS) -> list[RigExample]:
    """The sample's example and its stretched variants."""
    reference = reference_skeleton(sample)
    examples = [rig_example(f"{sample.name}#0", sample.mesh, reference)]
    low, high = np.log(STRETCH_RANGE[0]), np.log(STRETCH_RANGE[1])
    for variant in range(1, variants + 1):
        factors = np.exp(rng.uniform(low, high, size=3))
        vertices, joints = stretched(sample.vertices, reference.joints, factors)
        skeleton = Skeleton(joints, reference.parents, reference.names)
        examples.append(rig_example(f"{sample.name}#{variant}", Mesh(vertices, sample.triangles), skeleton))
    return examples


def save_example(example: RigExample, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(path.name + ".tmp.npz")
    np.savez_compressed(
        temporary, format_version=np.int64(EXAMPLE_FORMAT_VERSION), name=np.asarray(example.name),
        vertices=example.graph.vertices, vertex_features=example.graph.vertex_features,
        mesh_edges=example.graph.mesh_edges, ball_edges=example.graph.ball_edges, triangles=example.triangles,
        target_points=example.target_points, attention=example.attention, joints=example.joints,
        parents=example.parents)
    temporary.replace(path)


def load_example(path: Path) -> RigExample | None:
    """The example at ``path``, or None when it is of another format."""
    with np.load(path, allow_pickle=False) as data:
        if int(data["format_version"]) != EXAMPLE_FORMAT_VERSION:
            return None
        graph = JointGraph(data["vertices"], data["vertex_features"], data["mesh_edges"], data["ball_edges"])
        return RigExample(str(data["name"]), graph, data["triangles"], data["target_points"], data["attention"],
                          data["joints"], data["parents"])


def build_examples(samples: list[CharacterSample], folder: Path, seed: int = 0,
                   variants: int = STRETCHED_VARIANTS, log=print) -> dict[str, list[RigExample]]:
    """Examples of every sample (name -> its variants), built once into ``folder``."""
    examples = {}
    for sample in samples:
        stem = sample.name.replace("/", "__")
        paths = [Path(folder) / f"{stem}#{variant}.npz" for variant in range(variants + 1)]
        loaded = [load_example(path) if path.is_file() else None for path in paths]
        if any(example is None for example in loaded):
            # One generator per character name, so adding a character does
            # not change the others' variants.
            rng = np.random.default_rng([seed, zlib.crc32(sample.name.encode())])
            loaded = sample_examples(sample, rng, variants)
            for example, path in zip(loaded, paths):
                save_example(example, path)
            log(f"examples of {sample.name}: {len(loaded)}")
        examples[sample.name] = loaded
    return examples
