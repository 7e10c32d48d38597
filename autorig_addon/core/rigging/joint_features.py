"""What the joint network sees: one :class:`JointGraph` per character.

RigNet's joint stage reads vertex positions over the mesh one-ring and
geodesic balls. Trained on a few dozen characters, it also needs to be told
how thick the body is where each vertex lies, which a graph of positions
only sees indirectly; so every vertex also carries a *depth profile*: the
distance to the outside of the solid, sampled along the inward normal
(:data:`DEPTH_STEPS`), and the point of that ray deepest inside (an estimate
of the medial axis, where joints sit). These are measured on a voxel solid
of the normalised character (:func:`solid_depth`).

The character must be in the normalised frame of
:func:`...dataset.normalise.normalisation_transform` (z up, facing -y, left
at +x, largest side 1). The columns listed in :data:`VERTEX_VECTORS` are
3-vectors, which augmentation turns and mirrors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..distances.interior import fill_interior
from ..distances.surface_voxels import voxelize_surface
from ..geometry.normals import vertex_normals
from ..nn.graph import geodesic_ball_edges, mesh_edges
from ..types import Mesh

#: Vertices of the simplified proxy the network runs on. RigNet simplifies
#: to 1k-5k; 2k keeps a hand's fingers apart on a 1-unit-tall character and
#: the forward pass well under a second.
PROXY_VERTICES = 2_000
#: Radius of the geodesic balls (share of the largest side).
GEODESIC_BALL_RADIUS = 0.05
#: Neighbours kept per geodesic ball (the nearest along the surface).
GEODESIC_BALL_NEIGHBOURS = 16
#: Voxels along the largest side of the solid the depth is measured in.
DEPTH_RESOLUTION = 96
#: Points sampled along each vertex's inward normal, and how far the last
#: lies (share of the largest side): a torso is about 0.15 deep.
DEPTH_STEPS = 12
DEPTH_REACH = 0.24

#: Per-vertex columns: position (0:3), normal (3:6), the deepest point of
#: the inward ray minus the vertex (6:9), its depth (9), the depth profile
#: (10:10+DEPTH_STEPS).
VERTEX_FEATURES = 10 + DEPTH_STEPS
VERTEX_VECTORS = (0, 3, 6)


@dataclass(frozen=True)
class JointGraph:
    """The joint network's input for one character (normalised frame).

    Attributes
    ----------
    vertices : (n, 3) float64, proxy vertex positions
    vertex_features : (n, VERTEX_FEATURES) float32
    mesh_edges : (2, e) int64, one-ring edges with self loops
    ball_edges : (2, b) int64, geodesic-ball edges with self loops
    """

    vertices: np.ndarray
    vertex_features: np.ndarray
    mesh_edges: np.ndarray
    ball_edges: np.ndarray

    @property
    def vertex_count(self) -> int:
        return len(self.vertices)


@dataclass(frozen=True)
class SolidDepth:
    """Distance to the outside of the character's solid on a voxel grid,
    read anywhere by trilinear interpolation (0 outside the grid).

    Open parts enclose nothing: their cells are surface cells, one cell
    deep, the honest answer for a sheet.
    """

    depth: np.ndarray
    origin: np.ndarray
    cell_size: float

    def at(self, points: np.ndarray) -> np.ndarray:
        """(k,) depth at the (k, 3) ``points``."""
        coordinates = ((np.asarray(points, dtype=np.float64).reshape(-1, 3) - self.origin) / self.cell_size - 0.5).T
        return ndimage.map_coordinates(self.depth, coordinates, order=1, mode="constant", cval=0.0)

    @property
    def inside_depth(self) -> float:
        """The depth (:meth:`at`) from which a point is inside the solid:
        half a cell, so the fringe the interpolation spreads around it is not."""
        return 0.5 * self.cell_size


def solid_depth(mesh: Mesh, resolution: int = DEPTH_RESOLUTION) -> SolidDepth:
    """The :class:`SolidDepth` of a mesh (units of ``mesh``)."""
    grid = fill_interior(voxelize_surface(mesh, resolution))
    return SolidDepth(ndimage.distance_transform_edt(grid.occupied) * grid.cell_size, grid.origin, grid.cell_size)


def depth_along_normals(vertices: np.ndarray, normals: np.ndarray, solid: SolidDepth) -> np.ndarray:
    """(n, DEPTH_STEPS) depth sampled at ``vertices - t * normals`` for ``t``
    evenly spaced up to :data:`DEPTH_REACH`."""
    steps = np.linspace(DEPTH_REACH / DEPTH_STEPS, DEPTH_REACH, DEPTH_STEPS)
    points = vertices[:, None, :] - steps[None, :, None] * normals[:, None, :]
    return solid.at(points.reshape(-1, 3)).reshape(len(vertices), DEPTH_STEPS)


def joint_graph(mesh: Mesh, solid: SolidDepth | None = None) -> JointGraph:
    """The joint network's input for a normalised (proxy) mesh.

    Parameters
    ----------
    mesh : Mesh in the normalised frame, at least one triangle
    solid : its :func:`solid_depth`, when the caller already has it
    """
    vertices = mesh.vertices
    normals = vertex_normals(vertices, mesh.triangles)
    solid = solid if solid is not None else solid_depth(mesh)
    profile = depth_along_normals(vertices, normals, solid)
    steps = np.linspace(DEPTH_REACH / DEPTH_STEPS, DEPTH_REACH, DEPTH_STEPS)
    deepest = profile.argmax(axis=1)
    # Where the ray never enters the solid (an open sheet) the deepest
    # point is the vertex itself.
    reach = np.where(profile.max(axis=1) > 0, steps[deepest], 0.0)
    features = np.concatenate([vertices, normals, -reach[:, None] * normals, profile.max(axis=1, keepdims=True),
                               profile], axis=1)
    return JointGraph(
        vertices=vertices,
        vertex_features=features.astype(np.float32),
        mesh_edges=mesh_edges(mesh.triangles, len(vertices), self_loops=True),
        ball_edges=geodesic_ball_edges(vertices, mesh.triangles, GEODESIC_BALL_RADIUS,
                                       max_neighbours=GEODESIC_BALL_NEIGHBOURS, self_loops=True)[0],
    )
