"""Small meshes with known answers, built with numpy alone."""

import numpy as np

from autorig_addon.core.types import Mesh, Skeleton, Weights


def grid(nx: int, ny: int, size: float = 1.0) -> Mesh:
    """A flat (nx x ny)-vertex square grid in the z=0 plane, normals +z."""
    xs, ys = np.meshgrid(np.linspace(0, size, nx), np.linspace(0, size, ny), indexing="ij")
    V = np.stack([xs.ravel(), ys.ravel(), np.zeros(nx * ny)], axis=1)
    idx = np.arange(nx * ny).reshape(nx, ny)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return Mesh(V, F)


def cylinder(radius: float = 0.1, height: float = 1.0, segments: int = 24, rings: int = 21,
             capped: bool = True, z0: float = 0.0, flip: bool = False) -> Mesh:
    """A cylinder along +z from ``z0`` to ``z0 + height``, outward normals
    (inward if ``flip``), optionally closed with fan caps."""
    angles = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    zs = np.linspace(z0, z0 + height, rings)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    V = np.concatenate([np.column_stack([ring, np.full(segments, z)]) for z in zs])
    faces = []
    for r in range(rings - 1):
        for s in range(segments):
            a, b = r * segments + s, r * segments + (s + 1) % segments
            c, d = a + segments, b + segments
            faces += [[a, b, d], [a, d, c]]
    if capped:
        bottom, top = len(V), len(V) + 1
        V = np.vstack([V, [0, 0, z0], [0, 0, z0 + height]])
        last = (rings - 1) * segments
        for s in range(segments):
            faces.append([bottom, (s + 1) % segments, s])
            faces.append([top, last + s, last + (s + 1) % segments])
    F = np.asarray(faces)
    if flip:
        F = F[:, ::-1]
    return Mesh(V, F)


def two_bone_skeleton(height: float = 1.0) -> Skeleton:
    """Bone 'lower' from z=0 to z=h/2, 'upper' from h/2 to h."""
    return Skeleton(
        joints=[[0, 0, 0], [0, 0, height / 2]], parents=[-1, 0], names=("lower", "upper"),
        tails=[[0, 0, height / 2], [0, 0, height]],
    )


def two_bone_weights(mesh: Mesh, height: float = 1.0, blend: float = 0.2) -> Weights:
    """Weight of 'upper' rises linearly from 0 to 1 across ``z in [h/2 - blend/2, h/2 + blend/2]``."""
    z = mesh.vertices[:, 2]
    upper = np.clip((z - (height / 2 - blend / 2)) / blend, 0.0, 1.0)
    return Weights(np.stack([1 - upper, upper], axis=1), ("lower", "upper"))
