"""Reading Blender objects into the core's arrays: meshes, skeletons, weights.

Vertices, triangles and bone ends go through ``foreach_get`` into numpy;
deform weights, which have no ``foreach_get``, through one flat pass over
the vertices' group memberships. Nothing here changes the objects, except
that the armatures posing a mesh are shown in Rest Position while it is
read (:func:`.armature_binding.objects_at_rest`) and restored afterwards.

Writing lives beside this module: :mod:`.weight_writer` (vertex groups and
the armature binding), :mod:`.status_attribute` (the transfer status
colours) and :mod:`.snapshot` (undoing a write that fails half-way).
"""

from __future__ import annotations

from typing import Sequence

import bpy
import numpy as np
from mathutils import Matrix

from ..core.errors import InputError
from ..core.skeleton.hierarchy import parents_first_order, reindexed_parents
from ..core.types import Mesh, Skeleton, Weights
from .armature_binding import objects_at_rest


def _as_object_list(objects) -> list:
    if isinstance(objects, bpy.types.Object):
        return [objects]
    return list(objects)


def _matrix_to_numpy(matrix: Matrix) -> np.ndarray:
    """(4, 4) float64 array of a ``mathutils.Matrix``."""
    return np.array([list(row) for row in matrix], dtype=np.float64)


def _transform_points(points: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """(n, 3) float64 points multiplied by a (4, 4) affine matrix."""
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def require_mesh_object(obj, role: str = "object") -> None:
    """Raise InputError unless ``obj`` is a mesh object."""
    if obj is None:
        raise InputError(f"No {role} given: pick a mesh object.")
    if obj.type != "MESH":
        raise InputError(f"The {role} '{obj.name}' is not a mesh (its type is {obj.type.title()}): pick a mesh object.")


def _triangles_of(mesh_data) -> tuple[np.ndarray, np.ndarray]:
    """Triangles (m, 3) int64 and their polygon index (m,) int64 of a mesh datablock."""
    mesh_data.calc_loop_triangles()
    count = len(mesh_data.loop_triangles)
    triangles = np.empty(count * 3, dtype=np.int32)
    mesh_data.loop_triangles.foreach_get("vertices", triangles)
    polygons = np.empty(count, dtype=np.int32)
    mesh_data.loop_triangle_polygons.foreach_get("value", polygons)
    return triangles.reshape(-1, 3).astype(np.int64), polygons.astype(np.int64)


def _local_vertices(mesh_data) -> np.ndarray:
    """(n, 3) float64 local-space vertex positions of a mesh datablock."""
    positions = np.empty(len(mesh_data.vertices) * 3, dtype=np.float32)
    mesh_data.vertices.foreach_get("co", positions)
    return positions.reshape(-1, 3).astype(np.float64)


def _read_one_mesh(obj, depsgraph) -> Mesh:
    require_mesh_object(obj, "mesh")
    original = obj.data
    evaluated_object = obj.evaluated_get(depsgraph) if depsgraph is not None else None
    evaluated_mesh = None
    try:
        if evaluated_object is not None:
            evaluated_mesh = evaluated_object.to_mesh()
        # Modifiers that add or remove vertices break the 1:1 mapping back to
        # the original vertex groups, so such meshes are read undeformed.
        use_evaluated = evaluated_mesh is not None and len(evaluated_mesh.vertices) == len(original.vertices)
        source = evaluated_mesh if use_evaluated else original
        vertices = _local_vertices(source)
        triangles, polygons = _triangles_of(source)
    finally:
        if evaluated_mesh is not None:
            evaluated_object.to_mesh_clear()
    if not len(triangles):
        raise InputError(
            f"'{obj.name}' has no faces: it is only vertices or edges. "
            "Add faces to it (Edit Mode > Face > Fill) or pick a mesh with a surface."
        )
    # The evaluated object's matrix is current even before the original's is synced.
    matrix = _matrix_to_numpy((evaluated_object if evaluated_object is not None else obj).matrix_world)
    if np.linalg.det(matrix[:3, :3]) < 0:
        # A mirroring transform turns counter-clockwise triangles clockwise.
        triangles = triangles[:, ::-1].copy()
    return Mesh(_transform_points(vertices, matrix), triangles, polygons, None, (obj.name,))


def read_mesh(objects, depsgraph=None) -> Mesh:
    """World-space triangle mesh of one or several mesh objects, concatenated.

    Parameters
    ----------
    objects : bpy.types.Object or sequence of them
        Mesh objects. Vertex ``i`` of object ``k`` is vertex
        ``object_offsets[k] + i`` of the result, in Blender's own order, so
        results map back 1:1.
    depsgraph : bpy.types.Depsgraph or None
        Used to read modifier-deformed geometry where the modifiers keep the
        vertex count (the original mesh is read otherwise), with every
        armature deforming the objects in Rest Position. ``None`` reads the
        current context's evaluated depsgraph.

    Returns
    -------
    Mesh with ``object_names`` set to the objects' names.

    Raises
    ------
    InputError for non-mesh objects, meshes without faces, or no objects.
    """
    object_list = _as_object_list(objects)
    if not object_list:
        raise InputError("No mesh objects given.")
    with objects_at_rest(object_list):
        if depsgraph is None:
            depsgraph = bpy.context.evaluated_depsgraph_get()
        return Mesh.concatenate([_read_one_mesh(obj, depsgraph) for obj in object_list])


def require_armature_object(obj) -> None:
    """Raise InputError unless ``obj`` is an armature object."""
    if obj is None or obj.type != "ARMATURE":
        name = "None" if obj is None else f"'{obj.name}'"
        raise InputError(f"{name} is not an armature object.")


def read_skeleton(armature_obj) -> Skeleton:
    """World-space rest skeleton of an armature object.

    Parameters
    ----------
    armature_obj : bpy.types.Object of type 'ARMATURE'

    Returns
    -------
    Skeleton whose joints are the bone heads, tails the bone tails (rest
    pose, ``matrix_world`` applied), ``deform`` is ``Bone.use_deform``,
    ordered parents first (Blender's bone order, which already is, is kept:
    :func:`~autorig_addon.core.skeleton.hierarchy.parents_first_order`).
    """
    require_armature_object(armature_obj)
    bones = armature_obj.data.bones
    count = len(bones)
    if count == 0:
        raise InputError(f"The armature '{armature_obj.name}' has no bones.")
    heads = np.empty(count * 3, dtype=np.float32)
    tails = np.empty(count * 3, dtype=np.float32)
    deform = np.empty(count, dtype=bool)
    bones.foreach_get("head_local", heads)
    bones.foreach_get("tail_local", tails)
    bones.foreach_get("use_deform", deform)
    names = [bone.name for bone in bones]
    index_of = {name: i for i, name in enumerate(names)}
    parent_of = [index_of[bone.parent.name] if bone.parent else -1 for bone in bones]
    order = parents_first_order(parent_of)
    parents = reindexed_parents(parent_of, order)
    matrix = _matrix_to_numpy(armature_obj.matrix_world)
    heads = _transform_points(heads.reshape(-1, 3).astype(np.float64), matrix)[order]
    tails = _transform_points(tails.reshape(-1, 3).astype(np.float64), matrix)[order]
    return Skeleton(heads, parents, tuple(names[i] for i in order), tails, deform[order])


def deform_bone_names(armature_obj) -> tuple[str, ...]:
    """Names of the armature's bones with ``use_deform`` on, in bone order."""
    require_armature_object(armature_obj)
    return tuple(bone.name for bone in armature_obj.data.bones if bone.use_deform)


def read_group_weights(obj, group_names: Sequence[str]) -> np.ndarray:
    """(n, k) float64 weights of the named vertex groups (zero column when missing)."""
    names = list(group_names)
    column_of_group = np.full(max(len(obj.vertex_groups), 1), -1, dtype=np.int64)
    for column, name in enumerate(names):
        group = obj.vertex_groups.get(name)
        if group is not None:
            column_of_group[group.index] = column
    vertex_count = len(obj.data.vertices)
    matrix = np.zeros((vertex_count, len(names)), dtype=np.float64)
    if not np.any(column_of_group >= 0):
        return matrix
    # No foreach_get exists for deform weights; one flat comprehension over
    # the elements is the fastest route found (about 0.12 s for 50k vertices
    # with three groups each, half the time of a nested loop).
    memberships = [vertex.groups for vertex in obj.data.vertices]
    counts = np.fromiter(map(len, memberships), dtype=np.int64, count=vertex_count)
    elements = [(element.group, element.weight) for groups in memberships for element in groups]
    if not elements:
        return matrix
    pairs = np.array(elements, dtype=np.float64)
    rows = np.repeat(np.arange(vertex_count), counts)
    columns = column_of_group[pairs[:, 0].astype(np.int64)]
    wanted = columns >= 0
    matrix[rows[wanted], columns[wanted]] = pairs[wanted, 1]
    return matrix


def read_weights(obj, bone_names: Sequence[str]) -> Weights:
    """Weights of ``obj``'s vertex groups named ``bone_names``.

    Parameters
    ----------
    obj : bpy.types.Object of type 'MESH'
    bone_names : sequence of b str

    Returns
    -------
    Weights (n, b), raw as stored (not normalised); a bone without a vertex
    group gives a zero column.
    """
    require_mesh_object(obj)
    return Weights(read_group_weights(obj, bone_names), tuple(bone_names))


def vertex_group_mask(obj, group_name: str, threshold: float) -> np.ndarray | None:
    """(n,) bool: vertices whose weight in ``group_name`` is at least
    ``threshold``; None when the group does not exist or is empty."""
    if not group_name or obj.vertex_groups.get(group_name) is None:
        return None
    mask = read_group_weights(obj, [group_name])[:, 0] >= threshold
    return mask if mask.any() else None
