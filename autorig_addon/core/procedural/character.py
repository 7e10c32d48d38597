"""Generated characters: :func:`generate_character` and its result,
:class:`ProceduralCharacter`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..errors import InputError
from ..types import Mesh, Skeleton, Weights
from .character_builder import CharacterBuilder
from .kinds import BUILDERS

#: Character kinds :func:`generate_character` can make, in the order a seed draws them.
KINDS = ("biped", "quadruped", "multileg", "winged", "tailed", "long_chain", "fish", "prop")


@dataclass(frozen=True)
class ProceduralCharacter:
    """A generated character with the weights it was built with.

    Attributes
    ----------
    mesh : Mesh
        The surface (one object), all parts concatenated.
    skeleton : Skeleton
        Bones, parents first; control bones have ``deform`` False.
    weights : Weights
        (n, j) ground-truth weights, one column per skeleton bone in skeleton
        order; rows non-negative and summing to one; control bone columns zero.
    kind : str
        One of :data:`KINDS`.
    variant : str
        Sub-kind, e.g. ``"spider"``, ``"dragon"``, ``"door"``.
    parts : (n,) int64 array
        Index into ``part_names`` of the piece each vertex belongs to.
    part_names : tuple of str
        Name of each piece (``"arm.L"``, ``"helmet"``...).
    part_types : tuple of str
        One of :data:`.parts.PART_TYPES` per piece.
    part_closed : (p,) bool array
        Whether each piece is a closed surface (every edge in two triangles).
    seed : int
    """

    mesh: Mesh
    skeleton: Skeleton
    weights: Weights
    kind: str
    variant: str
    parts: np.ndarray
    part_names: tuple
    part_types: tuple
    part_closed: np.ndarray
    seed: int


def generate_character(seed: int, kind: str | None = None) -> ProceduralCharacter:
    """Build one rigged character from ``seed``.

    Parameters
    ----------
    seed : int
        Non-negative; the same seed (and kind) always gives identical arrays.
    kind : str or None
        One of :data:`KINDS`; None draws the kind from the seed.

    Returns
    -------
    ProceduralCharacter
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError(f"The seed must be a non-negative integer, got {seed!r}.")
    if kind is not None and kind not in KINDS:
        raise InputError(f"Unknown character kind {kind!r}; use one of {', '.join(KINDS)} or None.")
    rng = np.random.default_rng(int(seed))
    chosen = KINDS[int(rng.integers(len(KINDS)))] if kind is None else kind
    builder = CharacterBuilder(rng)
    variant = BUILDERS[chosen](builder)
    return assemble(builder, chosen, variant, int(seed))


def generate_characters(seeds: Sequence[int], kind: str | None = None):
    """Yield :func:`generate_character` for each seed (a lazy data set)."""
    for seed in seeds:
        yield generate_character(seed, kind)


def assemble(builder: CharacterBuilder, kind: str, variant: str, seed: int) -> ProceduralCharacter:
    """The finished character: the builder's bones as a skeleton, its parts
    concatenated into one mesh, their weights spread over the skeleton's
    columns and normalised."""
    rig, parts = builder.rig, builder.parts
    skeleton = Skeleton(
        np.array(rig.heads), np.array([rig.index[p] if p is not None else -1 for p in rig.parents]),
        tuple(rig.names), np.array(rig.tails), np.array(rig.deform),
    )
    vertex_counts = [len(p.vertices) for p in parts]
    offsets = np.cumsum([0] + vertex_counts)
    weights = np.zeros((offsets[-1], skeleton.bone_count))
    for part, start in zip(parts, offsets):
        columns = [rig.index[b] for b in part.bone_names]
        weights[start:start + len(part.vertices), columns] += part.weights
    weights /= weights.sum(axis=1, keepdims=True)
    mesh = Mesh(
        np.concatenate([p.vertices for p in parts]),
        np.concatenate([p.triangles + o for p, o in zip(parts, offsets)]),
        object_names=(f"{kind}_{seed}",),
    )
    return ProceduralCharacter(
        mesh=mesh,
        skeleton=skeleton,
        weights=Weights(weights, skeleton.names),
        kind=kind,
        variant=variant,
        parts=np.repeat(np.arange(len(parts)), vertex_counts).astype(np.int64),
        part_names=tuple(p.name for p in parts),
        part_types=tuple(p.part_type for p in parts),
        part_closed=np.array([p.closed for p in parts], dtype=bool),
        seed=seed,
    )
