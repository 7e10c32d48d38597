"""Temporary mesh objects built from core arrays, always removed afterwards.

Bone heat and simplification run Blender operators on copies built from
the arrays alone, so no vertex group, modifier or shape key of the user's
objects can leak in and nothing of the user's file changes.
"""

from __future__ import annotations

import bpy
import numpy as np

from ..core.types import Mesh

#: Name of the temporary objects this module creates (and callers always remove).
SCRATCH_NAME = "AutoRig scratch"


def scratch_object(mesh: Mesh):
    """A new mesh object holding ``mesh``, linked to the scene collection."""
    data = bpy.data.meshes.new(SCRATCH_NAME)
    data.vertices.add(mesh.vertex_count)
    data.vertices.foreach_set("co", mesh.vertices.astype(np.float32).ravel())
    triangle_count = len(mesh.triangles)
    data.loops.add(3 * triangle_count)
    data.loops.foreach_set("vertex_index", mesh.triangles.astype(np.int32).ravel())
    data.polygons.add(triangle_count)
    data.polygons.foreach_set("loop_start", np.arange(0, 3 * triangle_count, 3, dtype=np.int32))
    data.update(calc_edges=True)
    obj = bpy.data.objects.new(SCRATCH_NAME, data)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def remove_scratch_object(obj) -> None:
    """Remove a :func:`scratch_object` and its mesh data."""
    data = obj.data
    bpy.data.objects.remove(obj, do_unlink=True)
    if data is not None and data.users == 0:
        bpy.data.meshes.remove(data)
