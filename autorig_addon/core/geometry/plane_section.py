"""Where a plane cuts a triangle mesh: the section's segments and its loops.

A limb's cross-section read from vertices alone fails on low-poly meshes,
whose long faces leave no vertex near the cut (a game character's upper arm
may be one ring of faces from shoulder to elbow); cutting the triangles
themselves gives the exact outline whatever the tessellation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..types import Mesh


@dataclass(frozen=True)
class PlaneSection:
    """The outline of a mesh in a plane: segment ``i`` runs from
    ``starts[i]`` to ``ends[i]`` (both (k, 3)), and ``loops[i]`` labels the
    piece of the outline it belongs to (segments of triangles that share a
    cut edge, or an edge at the same place, share a label: one closed loop
    per tube a closed mesh has there)."""

    starts: np.ndarray
    ends: np.ndarray
    loops: np.ndarray

    @property
    def lengths(self) -> np.ndarray:
        return np.linalg.norm(self.ends - self.starts, axis=1)

    @property
    def midpoints(self) -> np.ndarray:
        return 0.5 * (self.starts + self.ends)

    def keep(self, rows: np.ndarray) -> PlaneSection:
        """The section with only the segments ``rows`` (a mask or indices); loop labels kept."""
        return PlaneSection(self.starts[rows], self.ends[rows], self.loops[rows])


def plane_section(mesh: Mesh, point, normal) -> PlaneSection:
    """The section of ``mesh`` by the plane through ``point`` with ``normal``
    (any length but not zero). A vertex exactly on the plane counts as on
    its positive side, so each cut triangle gives exactly one segment."""
    normal = np.asarray(normal, dtype=np.float64)
    normal = normal / np.linalg.norm(normal)
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    triangles = np.asarray(mesh.triangles, dtype=np.int64).reshape(-1, 3)
    heights = (vertices - np.asarray(point, dtype=np.float64)) @ normal
    above = heights[triangles] >= 0.0
    cut = above.any(axis=1) & ~above.all(axis=1)
    triangles, above = triangles[cut], above[cut]
    if not len(triangles):
        empty = np.zeros((0, 3))
        return PlaneSection(empty, empty, np.zeros(0, dtype=np.int64))
    # The lone corner is the one alone on its side; the cut crosses its two edges.
    lone_above = above.sum(axis=1) == 1
    lone = np.where(lone_above, np.argmax(above, axis=1), np.argmin(above, axis=1))
    rows = np.arange(len(triangles))
    corner = triangles[rows, lone]
    first, second = triangles[rows, (lone + 1) % 3], triangles[rows, (lone + 2) % 3]

    def crossing(other: np.ndarray) -> np.ndarray:
        share = heights[corner] / (heights[corner] - heights[other])
        return vertices[corner] + share[:, None] * (vertices[other] - vertices[corner])

    starts, ends = crossing(first), crossing(second)
    # Loops: the cut edges are the nodes, each cut triangle joins its two. Vertices split at a UV or normal seam
    # sit at the same place: an edge is named by its corners' places, so the loop runs on across the seam (and
    # separate parts that share a corner's place, or a cut through a vertex on the plane, join one loop).
    used = np.unique(np.concatenate([corner, first, second]))
    place = np.zeros(len(vertices), dtype=np.int64)
    place[used] = np.unique(vertices[used], axis=0, return_inverse=True)[1].reshape(-1)
    corner, first, second = place[corner], place[first], place[second]
    edge_keys = np.concatenate([np.sort(np.stack([corner, first], axis=1), axis=1),
                                np.sort(np.stack([corner, second], axis=1), axis=1)])
    _, edge_ids = np.unique(edge_keys, axis=0, return_inverse=True)
    edge_ids = edge_ids.reshape(-1)
    count = int(edge_ids.max()) + 1
    links = coo_matrix((np.ones(len(triangles)), (edge_ids[:len(triangles)], edge_ids[len(triangles):])),
                       shape=(count, count))
    _, labels = connected_components(links, directed=False)
    return PlaneSection(starts, ends, labels[edge_ids[:len(triangles)]])
