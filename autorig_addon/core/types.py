"""The three values every job passes around: a triangle mesh, a skeleton, weights.

All arrays are numpy, positions in world units (Blender metres unless the
scene says otherwise). The Blender layer builds these from objects and writes
results back; everything in ``core`` works on them alone.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from .errors import InputError
from .geometry.bounding_box import bounding_box_diagonal
from .skeleton.hierarchy import subset_parents


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh, possibly gathered from several Blender objects.

    Attributes
    ----------
    vertices : (n, 3) float64 array
        World-space positions.
    triangles : (m, 3) int64 array
        Vertex indices of each triangle, counter-clockwise seen from outside.
    triangle_polygons : (m,) int64 array
        Index of the source polygon (Blender ``MeshPolygon``) each triangle
        was cut from, counted per object. Defaults to ``arange(m)``.
    object_offsets : (k + 1,) int64 array
        Vertices ``object_offsets[i]:object_offsets[i + 1]`` belong to object
        ``object_names[i]``. Defaults to a single object holding every vertex.
    object_names : tuple of k str
        Names of the objects the mesh was read from.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    triangle_polygons: np.ndarray = None
    object_offsets: np.ndarray = None
    object_names: tuple = ("mesh",)

    def __post_init__(self):
        vertices = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        triangles = np.ascontiguousarray(self.triangles, dtype=np.int64).reshape(-1, 3)
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "triangles", triangles)
        if self.triangle_polygons is None:
            object.__setattr__(self, "triangle_polygons", np.arange(len(triangles), dtype=np.int64))
        if self.object_offsets is None:
            object.__setattr__(self, "object_offsets", np.array([0, len(vertices)], dtype=np.int64))
        object.__setattr__(self, "object_names", tuple(self.object_names))
        if len(self.object_offsets) != len(self.object_names) + 1:
            raise ValueError("object_offsets must have one more entry than object_names")
        if len(triangles) and (triangles.min() < 0 or triangles.max() >= len(vertices)):
            raise InputError("A triangle refers to a vertex that does not exist.")

    @property
    def vertex_count(self) -> int:
        return len(self.vertices)

    @property
    def bounding_box_diagonal(self) -> float:
        """Length of the axis-aligned bounding box diagonal (0 for an empty mesh),
        :func:`~.geometry.bounding_box.bounding_box_diagonal` of the vertices."""
        return bounding_box_diagonal(self.vertices)

    def object_slice(self, index: int) -> slice:
        return slice(int(self.object_offsets[index]), int(self.object_offsets[index + 1]))

    def subset(self, keep: np.ndarray) -> "Mesh":
        """The mesh of the ``keep`` vertices, in order, and the triangles
        whose corners are all kept; each object keeps its kept vertices
        (an object left with none is dropped).

        Parameters
        ----------
        keep : (n,) bool array
        """
        keep = np.asarray(keep, dtype=bool).reshape(-1)
        new_index = np.full(len(keep), -1, dtype=np.int64)
        new_index[keep] = np.arange(np.count_nonzero(keep))
        whole = keep[self.triangles].all(axis=1) if len(self.triangles) else np.zeros(0, dtype=bool)
        counts = np.array([np.count_nonzero(keep[self.object_slice(i)]) for i in range(len(self.object_names))],
                          dtype=np.int64)
        present = counts > 0
        return Mesh(self.vertices[keep], new_index[self.triangles[whole]], self.triangle_polygons[whole],
                    np.concatenate([[0], np.cumsum(counts[present])]),
                    tuple(name for name, kept in zip(self.object_names, present) if kept))

    @staticmethod
    def concatenate(meshes: Sequence["Mesh"]) -> "Mesh":
        """One mesh holding ``meshes`` one after another (vertex indices shifted)."""
        vertices, triangles, polygons, offsets, names = [], [], [], [0], []
        for mesh in meshes:
            triangles.append(mesh.triangles + offsets[-1])
            vertices.append(mesh.vertices)
            polygons.append(mesh.triangle_polygons)
            offsets.extend(mesh.object_offsets[1:] + offsets[-1])
            names.extend(mesh.object_names)
        return Mesh(
            np.concatenate(vertices) if vertices else np.zeros((0, 3)),
            np.concatenate(triangles) if triangles else np.zeros((0, 3), np.int64),
            np.concatenate(polygons) if polygons else np.zeros(0, np.int64),
            np.asarray(offsets, dtype=np.int64),
            tuple(names),
        )


@dataclass(frozen=True)
class Skeleton:
    """A hierarchy of bones, one per joint, as Blender stores an armature.

    Joint ``j`` is the head of bone ``names[j]``; the bone runs from
    ``joints[j]`` to ``tails[j]``. ``parents[j]`` is the index of the parent
    joint, -1 for a root. Joints come parents first (``parents[j] < j``).

    Attributes
    ----------
    joints : (j, 3) float64 array
        Head position of each bone, world space.
    parents : (j,) int64 array
        Parent joint index, -1 for roots.
    names : tuple of j str
        Bone names (Blender conventions: ``.L`` / ``.R`` suffixes).
    tails : (j, 3) float64 array
        Tail position of each bone. Defaults to the mean of the children's
        heads, or for a leaf, the head pushed along the parent direction.
    deform : (j,) bool array
        Whether the bone deforms the mesh (``Bone.use_deform``). Only deform
        bones receive weights. Defaults to all True.
    """

    joints: np.ndarray
    parents: np.ndarray
    names: tuple
    tails: np.ndarray = None
    deform: np.ndarray = None

    def __post_init__(self):
        joints = np.ascontiguousarray(self.joints, dtype=np.float64).reshape(-1, 3)
        parents = np.ascontiguousarray(self.parents, dtype=np.int64).reshape(-1)
        names = tuple(self.names)
        if not (len(joints) == len(parents) == len(names)):
            raise ValueError("joints, parents and names must have one entry per joint")
        if len(set(names)) != len(names):
            raise InputError("Bone names must be unique.")
        if np.any(parents >= np.arange(len(parents))):
            raise ValueError("parents must come before their children (parents[j] < j)")
        object.__setattr__(self, "joints", joints)
        object.__setattr__(self, "parents", parents)
        object.__setattr__(self, "names", names)
        if self.tails is None:
            object.__setattr__(self, "tails", _default_tails(joints, parents))
        else:
            object.__setattr__(self, "tails", np.ascontiguousarray(self.tails, dtype=np.float64).reshape(-1, 3))
        if self.deform is None:
            object.__setattr__(self, "deform", np.ones(len(joints), dtype=bool))
        else:
            object.__setattr__(self, "deform", np.asarray(self.deform, dtype=bool).reshape(-1))

    @property
    def bone_count(self) -> int:
        return len(self.joints)

    @property
    def bone_lengths(self) -> np.ndarray:
        """(j,) float64: length of each bone."""
        return np.linalg.norm(self.tails - self.joints, axis=1)

    def deform_subset(self) -> "Skeleton":
        """The skeleton restricted to deform bones, parents re-linked to the
        nearest deforming ancestor."""
        keep = np.flatnonzero(self.deform)
        return Skeleton(
            self.joints[keep], subset_parents(self.parents, self.deform), tuple(self.names[j] for j in keep),
            self.tails[keep], np.ones(len(keep), dtype=bool),
        )


def _default_tails(joints: np.ndarray, parents: np.ndarray) -> np.ndarray:
    tails = joints.copy()
    child_sum = np.zeros_like(joints)
    child_count = np.zeros(len(joints))
    has_parent = parents >= 0
    np.add.at(child_sum, parents[has_parent], joints[has_parent])
    np.add.at(child_count, parents[has_parent], 1)
    with_children = child_count > 0
    tails[with_children] = child_sum[with_children] / child_count[with_children, None]
    scale = bounding_box_diagonal(joints)
    for j in np.flatnonzero(~with_children):
        p = parents[j]
        direction = joints[j] - joints[p] if p >= 0 else np.array([0.0, 0.0, 1.0])
        length = np.linalg.norm(direction)
        if length < 1e-12:
            direction, length = np.array([0.0, 0.0, 1.0]), 1.0
        bone_length = 0.5 * length if p >= 0 else 0.1 * max(scale, 1e-3)
        tails[j] = joints[j] + direction / length * bone_length
    # Coincident tails would make zero-length bones, which Blender deletes.
    degenerate = np.linalg.norm(tails - joints, axis=1) < 1e-9
    tails[degenerate] = joints[degenerate] + np.array([0.0, 0.0, 0.01 * max(scale, 1e-3)])
    return tails


@dataclass(frozen=True)
class Weights:
    """Skin weights: how much each bone moves each vertex.

    Attributes
    ----------
    matrix : (n, b) float64 array
        ``matrix[v, k]`` is the weight of bone ``bone_names[k]`` on vertex
        ``v``. Rows of a finished result are non-negative and sum to one.
        Build from a scipy sparse matrix with :meth:`from_sparse`.
    bone_names : tuple of b str
    """

    matrix: np.ndarray
    bone_names: tuple = field(default_factory=tuple)

    def __post_init__(self):
        matrix = np.ascontiguousarray(self.matrix, dtype=np.float64)
        if matrix.ndim != 2 or matrix.shape[1] != len(self.bone_names):
            raise ValueError("matrix must be (vertices, bones) with one column per bone name")
        object.__setattr__(self, "matrix", matrix)
        object.__setattr__(self, "bone_names", tuple(self.bone_names))

    @classmethod
    def from_sparse(cls, sparse_matrix, bone_names) -> "Weights":
        return cls(np.asarray(sparse_matrix.todense()), bone_names)

    def to_sparse(self):
        """scipy.sparse.csr_matrix (n, b) of the non-zero weights."""
        from scipy.sparse import csr_matrix

        return csr_matrix(self.matrix)

    @property
    def vertex_count(self) -> int:
        return self.matrix.shape[0]

    def select_bones(self, names: Sequence[str]) -> "Weights":
        """Columns for ``names`` in that order; a name absent here gives zeros."""
        index = {name: k for k, name in enumerate(self.bone_names)}
        out = np.zeros((self.vertex_count, len(names)))
        for k, name in enumerate(names):
            if name in index:
                out[:, k] = self.matrix[:, index[name]]
        return Weights(out, tuple(names))
