"""One normalised rigged character, stored as one ``.npz`` file."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..types import Mesh, Skeleton, Weights
from ..weights import normalize_rows
from .normalise import FACING_UNKNOWN, normalise

#: Bumped whenever the sample content or normalisation changes, so old cache
#: files are not reused. 2: bone tails of glTF files derived from the joints
#: when the stored ones are point-like, and the loader's notes kept.
#: 3: facing read from the deform bones near the body (lone side letters such
#: as ``bip01 l hand`` understood) and from the head ahead of the tail when the
#: side names disagree; the normalisation's scale and facing, the rest pose,
#: rigid weights and the Mixamo-name weight check noted; ``category`` is the
#: split's kind (humanoid, quadruped, bird, fish, other). 4: stored bones
#: that all point one way, not at their children (unturned joint frames),
#: get tails derived from the joints (``core.skeleton.tails``).
SAMPLE_FORMAT_VERSION = 4


@dataclass(frozen=True)
class CharacterSample:
    """One normalised rigged character, as stored in a cache ``.npz`` file.

    Attributes
    ----------
    vertices : (n, 3) float64 array, normalised positions
    triangles : (m, 3) int64 array
    joints : (j, 3) float64 array, bone heads, normalised
    parents : (j,) int64 array, -1 for roots, parents first
    names : tuple of j str, bone names
    tails : (j, 3) float64 array, bone tails, normalised
    deform : (j,) bool array, bones that carry weights
    weights : (n, d) float64 array
        Columns are the ``d`` deform bones in joint order; rows sum to one
        (rows of vertices the artist left unweighted are zero).
    name : str, the character's name
    category : str, the split's kind (``"humanoid"``, ``"quadruped"``, ...),
        a procedural kind, or the source folder
    transform : (4, 4) float64 array
        From the source file's world space to the normalised frame (see
        :func:`~.normalise.normalise`); its inverse maps predictions back.
    facing : str, see :class:`~.normalise.Normalised`
    source_vertex_count : int, vertices of the mesh before simplification
    notes : tuple of str
        What the loader chose or changed and why (which armature, meshes
        left out, bone tails derived from the joints, unweighted
        vertices, rigid weights, the rest pose, ...), as
        ``blender.characters.RiggedCharacter.notes``, then what the
        normalisation did (the scale, and the facing with its cue).
    """

    vertices: np.ndarray
    triangles: np.ndarray
    joints: np.ndarray
    parents: np.ndarray
    names: tuple
    tails: np.ndarray
    deform: np.ndarray
    weights: np.ndarray
    name: str
    category: str
    transform: np.ndarray
    facing: str = FACING_UNKNOWN
    source_vertex_count: int = 0
    notes: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "notes", tuple(str(note) for note in self.notes))

    @property
    def mesh(self) -> Mesh:
        return Mesh(self.vertices, self.triangles, object_names=(self.name,))

    @property
    def skeleton(self) -> Skeleton:
        return Skeleton(self.joints, self.parents, self.names, self.tails, self.deform)

    @property
    def deform_names(self) -> tuple:
        return tuple(name for name, deforms in zip(self.names, self.deform) if deforms)

    @property
    def skin(self) -> Weights:
        """The weights as :class:`Weights` named by deform bone."""
        return Weights(self.weights, self.deform_names)

    @classmethod
    def from_character(
        cls, name: str, category: str, mesh: Mesh, skeleton: Skeleton, weights: Weights, source_vertex_count: int = 0,
        notes: tuple = (), sides_named_from_the_viewer: bool = False,
    ) -> "CharacterSample":
        """Normalise a character and keep its deform-bone weights.

        Parameters
        ----------
        name, category : str
        mesh : Mesh, world space
        skeleton : Skeleton, world space
        weights : Weights (n, b), matched to the deform bones by name
        source_vertex_count : int, vertices before any simplification
        notes : tuple of str, the loader's notes, kept as they are; the
            normalisation's own (:attr:`.normalise.Normalised.notes`) follow
        sides_named_from_the_viewer : bool, its artist named the sides from
            the viewer (:func:`.normalise.facing_decision`)
        """
        if weights.vertex_count != mesh.vertex_count:
            raise InputError(
                f"'{name}': the weights have {weights.vertex_count} rows but the mesh has {mesh.vertex_count} vertices."
            )
        normalised = normalise(mesh, skeleton, sides_named_from_the_viewer)
        deform_names = skeleton.deform_subset().names
        matrix = normalize_rows(weights.select_bones(deform_names).matrix)
        return cls(
            vertices=normalised.mesh.vertices,
            triangles=normalised.mesh.triangles,
            joints=normalised.skeleton.joints,
            parents=normalised.skeleton.parents,
            names=normalised.skeleton.names,
            tails=normalised.skeleton.tails,
            deform=normalised.skeleton.deform,
            weights=matrix,
            name=name,
            category=category,
            transform=normalised.transform,
            facing=normalised.facing,
            source_vertex_count=int(source_vertex_count or mesh.vertex_count),
            notes=tuple(notes) + normalised.notes,
        )

    def save(self, path: str | os.PathLike) -> None:
        """Write the sample to ``path`` (``.npz``, compressed), atomically."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = path.with_name(path.name + f".{os.getpid()}.tmp")
        with open(temporary, "wb") as handle:
            np.savez_compressed(
                handle,
                format_version=np.int64(SAMPLE_FORMAT_VERSION),
                vertices=self.vertices,
                triangles=self.triangles,
                joints=self.joints,
                parents=self.parents,
                names=np.asarray(self.names, dtype=np.str_),
                tails=self.tails,
                deform=self.deform,
                weights=self.weights,
                name=np.asarray(self.name, dtype=np.str_),
                category=np.asarray(self.category, dtype=np.str_),
                transform=self.transform,
                facing=np.asarray(self.facing, dtype=np.str_),
                source_vertex_count=np.int64(self.source_vertex_count),
                notes=np.asarray(self.notes, dtype=np.str_).reshape(-1),
            )
        os.replace(temporary, path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> "CharacterSample":
        """Read a sample written by :meth:`save`.

        Raises
        ------
        InputError for a missing file or one of another format version.
        """
        path = Path(path)
        if not path.is_file():
            raise InputError(f"The sample file '{path}' does not exist.")
        with np.load(path, allow_pickle=False) as data:
            version = int(data["format_version"]) if "format_version" in data else -1
            if version != SAMPLE_FORMAT_VERSION:
                raise InputError(
                    f"'{path.name}' is a sample of format {version}, this version reads {SAMPLE_FORMAT_VERSION}: "
                    "delete it and build the samples again."
                )
            return cls(
                vertices=data["vertices"],
                triangles=data["triangles"],
                joints=data["joints"],
                parents=data["parents"],
                names=tuple(str(name) for name in data["names"]),
                tails=data["tails"],
                deform=data["deform"],
                weights=data["weights"],
                name=str(data["name"]),
                category=str(data["category"]),
                transform=data["transform"],
                facing=str(data["facing"]),
                source_vertex_count=int(data["source_vertex_count"]),
                notes=tuple(str(note) for note in data["notes"]),
            )
