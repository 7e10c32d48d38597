"""The skinning networks' training examples: network inputs of cached
character samples and of their augmented variants, stored as ``.npz`` so
training needs neither Blender nor the voxel distances again.

Augmentations that change the distances are made here, once per character
(each variant is normalised again, as an input would be):

* **stretch**: the character scaled along each axis by a factor drawn in
  :data:`...nn.augmentation.STRETCH_RANGE` (thin, stocky, long
  characters);
* **re-pose**: the character posed by its own weights (linear blend
  skinning, :mod:`...skeleton.posing`) with a random share of its bones
  turned, as Puppeteer does, so posed inputs are no surprise.

Turns about the up axis and left-right mirroring do not change any
distance; the training loop applies them to the feature vectors on the fly
(:data:`...core.skinning.learned.features.VERTEX_VECTORS` and friends). A uniform scale is undone
by the normalisation, so it needs no example.
"""

from __future__ import annotations

import os
import zlib
from pathlib import Path
from typing import Iterable, Optional

import numpy as np

from ....core.dataset.cache import cache_root
from ....core.dataset.normalise import apply_transform, normalisation_transform
from ....core.dataset.sample import CharacterSample
from ....core.progress import ProgressCallback, report
from ....core.skeleton.posing import pose_matrices, posed_vertices, random_poses
from ....core.skinning.learned.features import SkinGraph, candidate_targets
from ....core.skinning.learned.predict import network_graph
from ....core.types import Mesh, Skeleton
from ...nn.augmentation import STRETCH_RANGE

#: Bumped whenever the examples' content changes, so old files are rebuilt. 2: volumetric
#: geodesic distances enter open parts all along their bones.
EXAMPLE_FORMAT_VERSION = 2
#: Stretched variants per character.
STRETCH_VARIANTS = 2
#: Re-posed variants per character.
REPOSE_VARIANTS = 2
#: Share of the deform bones turned in a re-posed variant, and the
#: standard deviation of their angles (degrees): moderate poses, as an
#: artist's input might be (the evaluation's random poses use 30 % and 25).
REPOSE_FRACTION = 0.3
REPOSE_SIGMA_DEGREES = 20.0


#: Sub-folder of the cache root holding the examples.
EXAMPLES_FOLDER = "skin_examples"


def default_examples_dir() -> Path:
    """Where examples are kept: ``<cache root>/skin_examples`` (see
    :func:`...dataset.cache.cache_root`)."""
    return cache_root() / EXAMPLES_FOLDER


def sample_variants(sample: CharacterSample, seed: int, augment: bool = True) -> list[tuple[str, Mesh, Skeleton]]:
    """``(suffix, mesh, deform skeleton)`` of a sample and of its stretched
    and re-posed variants (only the sample itself without ``augment``),
    each normalised; vertex order and deform bones are the sample's."""
    skeleton = sample.skeleton.deform_subset()
    variants = [("rest", sample.mesh, skeleton)]
    if not augment:
        return variants
    rng = np.random.default_rng(seed)
    for index in range(STRETCH_VARIANTS):
        factors = rng.uniform(*STRETCH_RANGE, size=3)
        variants.append((f"stretch{index}",) + _renormalised(sample.mesh, skeleton, sample.vertices * factors,
                                                             skeleton.joints * factors, skeleton.tails * factors))
    poses = random_poses(skeleton, REPOSE_VARIANTS, seed=int(rng.integers(2**31)), fraction=REPOSE_FRACTION,
                         sigma_degrees=REPOSE_SIGMA_DEGREES)
    for index, rotations in enumerate(poses):
        matrices = pose_matrices(skeleton, rotations)
        vertices = posed_vertices(sample.vertices, sample.weights, skeleton, rotations)[0]
        heads = np.einsum("bij,bj->bi", matrices[:, :3, :3], skeleton.joints) + matrices[:, :3, 3]
        tails = np.einsum("bij,bj->bi", matrices[:, :3, :3], skeleton.tails) + matrices[:, :3, 3]
        variants.append((f"pose{index}",) + _renormalised(sample.mesh, skeleton, vertices, heads, tails))
    return variants


def _renormalised(mesh: Mesh, skeleton: Skeleton, vertices, heads, tails) -> tuple[Mesh, Skeleton]:
    transform = normalisation_transform(vertices)
    moved = Mesh(apply_transform(vertices, transform), mesh.triangles, mesh.triangle_polygons, mesh.object_offsets,
                 mesh.object_names)
    return moved, Skeleton(apply_transform(heads, transform), skeleton.parents, skeleton.names,
                           apply_transform(tails, transform), skeleton.deform)


def example_path(folder: Path, distance: str, sample: CharacterSample, suffix: str, seed: int,
                 prior: str = "geometric") -> Path:
    """Where an example lives: the variants depend on the seed, so it is in the path."""
    safe = sample.name.replace("/", "__")
    inputs = distance if prior == "geometric" else f"{distance}-{prior}"
    return folder / f"v{EXAMPLE_FORMAT_VERSION}" / inputs / f"seed{seed}" / f"{safe}--{suffix}.npz"


def build_examples(samples: Iterable[CharacterSample], distance: str, *, prior: str = "geometric",
                   augment: bool = True, seed: int = 0,
                   folder: Optional[Path] = None, progress: Optional[ProgressCallback] = None) -> list[Path]:
    """Write (or reuse) the examples of ``samples`` for networks that see
    ``distance`` and correct ``prior``; returns their paths, sample by sample.

    Each file holds the :class:`SkinGraph` arrays, ``target`` (the
    reference weights of the candidates, :func:`.features.candidate_targets`),
    ``reference`` (n, d) and ``name``.
    """
    folder = Path(folder) if folder is not None else default_examples_dir()
    samples = list(samples)
    paths = []
    for index, sample in enumerate(samples):
        report(progress, index / max(len(samples), 1), f"Examples of {sample.name}")
        character_seed = seed * 1_000_003 + zlib.crc32(sample.name.encode())
        for suffix, mesh, skeleton in sample_variants(sample, character_seed, augment):
            path = example_path(folder, distance, sample, suffix, seed, prior)
            if not path.is_file():
                graph = network_graph(mesh, skeleton, distance, prior=prior)
                _save_example(path, graph, sample, suffix)
            paths.append(path)
    report(progress, 1.0, "Examples ready")
    return paths


def _save_example(path: Path, graph: SkinGraph, sample: CharacterSample, suffix: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(path.name + f".{os.getpid()}.tmp")
    with open(temporary, "wb") as handle:
        np.savez_compressed(handle, **graph.arrays(), target=candidate_targets(graph, sample.weights),
                            reference=sample.weights.astype(np.float32),
                            name=np.asarray(f"{sample.name}--{suffix}"))
    os.replace(temporary, path)


def load_example(path: str | os.PathLike) -> tuple[SkinGraph, np.ndarray, np.ndarray, str]:
    """``(graph, target, reference, name)`` of an example file."""
    with np.load(path, allow_pickle=False) as data:
        return SkinGraph.from_arrays(data), data["target"], data["reference"], str(data["name"])
