"""The target of a self-transfer check: a skin-tight garment whose right
weights are known exactly.

A rigged character's own surface, pushed out a little along its normals,
is a garment that should receive the character's own weights, vertex for
vertex; a transfer method is scored against them.
"""

from __future__ import annotations

from ..geometry.normals import vertex_normals
from ..types import Mesh

#: Self-transfer targets are offset along the normals by this share of the
#: character size (bounding-box diagonal): 0.5 % of a 2 m character is 1 cm,
#: a tight garment.
SELF_TRANSFER_OFFSET_FRACTION = 0.005


def self_transfer_target(mesh: Mesh, size: float) -> Mesh:
    """The character's surface pushed out along its vertex normals.

    Parameters
    ----------
    mesh : Mesh
        The character's rest mesh.
    size : float
        The character's size (:func:`~..geometry.bounding_box.character_size`);
        every vertex moves by :data:`SELF_TRANSFER_OFFSET_FRACTION` of it.

    Returns
    -------
    target : Mesh
        Same vertex order, triangles and objects as ``mesh``; a vertex
        without a face (no normal) stays where it is.
    """
    offset = SELF_TRANSFER_OFFSET_FRACTION * size * vertex_normals(mesh.vertices, mesh.triangles)
    return Mesh(mesh.vertices + offset, mesh.triangles, mesh.triangle_polygons, mesh.object_offsets, mesh.object_names)
