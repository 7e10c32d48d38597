"""Reading Blender objects into the core's arrays: meshes, skeletons, weights.

Vertices, triangles and bone ends go through ``foreach_get`` into numpy;
deform weights, which have no ``foreach_get``, through one flat pass over
the vertices' group memberships. Nothing here changes the objects, except
that while a mesh is read the armatures posing it are shown in Rest
Position (:func:`.armature_binding.objects_at_rest`) and, for its rest
shape (:func:`read_rest_shape`), the modifiers after its Armature
modifier's place are switched off and its vertices numbered
(:mod:`.modifier_stack`); all come back afterwards.

Writing lives beside this module: :mod:`.weight_writer` (vertex groups and
the armature binding), :mod:`.status_attribute` (the transfer status
colours) and :mod:`.snapshot` (undoing a write that fails half-way).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import bpy
import numpy as np
from mathutils import Matrix

from ..core.errors import InputError
from ..core.skeleton.hierarchy import parents_first_order, reindexed_parents
from ..core.types import Mesh, Skeleton, Weights
from .armature_binding import objects_at_rest
from .modifier_stack import cut_off, numbered_own_vertices, own_vertices_first, stack_cut, vertex_adders


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


def _world_mesh(obj, source, evaluated_object, later_modifiers: Sequence = ()) -> Mesh:
    """World-space Mesh of ``source`` (``obj``'s mesh datablock or its evaluated
    mesh); ``later_modifiers``: the modifiers switched off while it was read,
    which the message names when it has no faces."""
    vertices = _local_vertices(source)
    triangles, polygons = _triangles_of(source)
    if not len(triangles):
        if later_modifiers:
            names = ", ".join(f"'{modifier.name}'" for modifier in later_modifiers)
            raise InputError(
                f"'{obj.name}' has no faces before its modifier {names}, where the Armature modifier deforms it: "
                f"it is only vertices or edges there. Apply {names} first (Ctrl+A)."
            )
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
        return _world_mesh(obj, evaluated_mesh if use_evaluated else original, evaluated_object)
    finally:
        if evaluated_mesh is not None:
            evaluated_object.to_mesh_clear()


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


@dataclass(frozen=True)
class RestShape:
    """The shape each mesh's Armature modifier deforms (:mod:`.modifier_stack`),
    world space, as read by :func:`read_rest_shape`.

    Attributes
    ----------
    mesh : Mesh, every object's evaluated vertices: in object ``k``'s slice
        its own ``own_counts[k]`` vertices first, in Blender's order, then
        those a Mirror modifier added
    own_counts : tuple of int, each object's own vertex count
    places : tuple of int, the stack index each object was read at (its Armature modifier's place)
    """

    mesh: Mesh
    own_counts: tuple
    places: tuple

    def own_rows(self, index: int) -> slice:
        """Rows of ``mesh`` holding object ``index``'s own vertices."""
        start = int(self.mesh.object_offsets[index])
        return slice(start, start + self.own_counts[index])

    def added_count(self, index: int) -> int:
        """How many vertices object ``index``'s modifiers added (a Mirror's copies)."""
        rows = self.mesh.object_slice(index)
        return rows.stop - rows.start - self.own_counts[index]


def read_rest_shape(objects, places: Sequence[int], depsgraph=None) -> RestShape:
    """World-space shape of mesh objects as their Armature modifier deforms
    it: evaluated with every modifier from ``places[k]`` on switched off and
    the armatures posing them at rest (:func:`.modifier_stack.stack_cut`).

    Unlike :func:`read_mesh`, vertices a Mirror modifier adds before the
    place are kept, after the object's own (checked:
    :func:`.modifier_stack.own_vertices_first`).

    Raises
    ------
    InputError for non-mesh objects, a shape without faces, or modifiers
    before the place whose vertices cannot be traced back to the mesh's own.
    """
    object_list = _as_object_list(objects)
    if not object_list:
        raise InputError("No mesh objects given.")
    for obj in object_list:
        require_mesh_object(obj, "mesh")
    places = tuple(int(place) for place in places)
    numbered = [obj.data for obj, place in zip(object_list, places) if vertex_adders(obj, place)]
    later = [cut_off(obj, place) for obj, place in zip(object_list, places)]  # before they are switched off
    with objects_at_rest(object_list), stack_cut(dict(zip(object_list, places))), numbered_own_vertices(numbered):
        if depsgraph is None:
            depsgraph = bpy.context.evaluated_depsgraph_get()
        meshes = [_read_rest_mesh(obj, place, depsgraph, obj.data in numbered, cut)
                  for obj, place, cut in zip(object_list, places, later)]
    return RestShape(Mesh.concatenate(meshes), tuple(len(obj.data.vertices) for obj in object_list), places)


def _read_rest_mesh(obj, place: int, depsgraph, numbered: bool, later: list) -> Mesh:
    """One object of :func:`read_rest_shape`, its modifiers from ``place`` on
    (``later``) switched off; ``numbered``: its vertices carry their numbers."""
    own_count = len(obj.data.vertices)
    evaluated_object = obj.evaluated_get(depsgraph)
    evaluated_mesh = evaluated_object.to_mesh()
    try:
        count = len(evaluated_mesh.vertices)
        traced = own_vertices_first(evaluated_mesh, own_count) if numbered else count == own_count
        if not traced:
            before = vertex_adders(obj, place) or list(obj.modifiers)[:place]
            names = ", ".join(f"'{modifier.name}'" for modifier in before)
            raise InputError(
                f"'{obj.name}': the modifier {names} before the Armature modifier's place changes the mesh's own "
                f"vertices (a Mirror's Bisect cuts them), so weights could not be written back to them: apply {names} "
                "first (Ctrl+A)."
            )
        return _world_mesh(obj, evaluated_mesh, evaluated_object, later)
    finally:
        evaluated_object.to_mesh_clear()


def evaluated_bounds(obj, depsgraph=None) -> tuple[np.ndarray, np.ndarray] | None:
    """World-space bounding box ``(low, high)`` of ``obj`` as the viewport
    shows it with every modifier and its armatures at rest; None when the
    evaluated mesh has no vertices."""
    with objects_at_rest([obj]):
        if depsgraph is None:
            depsgraph = bpy.context.evaluated_depsgraph_get()
        evaluated_object = obj.evaluated_get(depsgraph)
        evaluated_mesh = evaluated_object.to_mesh()
        try:
            if not len(evaluated_mesh.vertices):
                return None
            points = _transform_points(_local_vertices(evaluated_mesh), _matrix_to_numpy(evaluated_object.matrix_world))
        finally:
            evaluated_object.to_mesh_clear()
    return points.min(axis=0), points.max(axis=0)


def read_rest_group_weights(obj, place: int, group_names: Sequence[str], depsgraph=None) -> np.ndarray:
    """(m, k) float64 deform weights of the named groups on every vertex the
    Armature modifier at ``place`` receives (a Mirror's copies included, with
    the groups it gave them): what posing will use. Zero column when missing."""
    with stack_cut({obj: place}):
        if depsgraph is None:
            depsgraph = bpy.context.evaluated_depsgraph_get()
        evaluated_object = obj.evaluated_get(depsgraph)
        evaluated_mesh = evaluated_object.to_mesh()
        try:
            return _group_weights_of(evaluated_mesh, obj.vertex_groups, group_names)
        finally:
            evaluated_object.to_mesh_clear()


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
    return _group_weights_of(obj.data, obj.vertex_groups, group_names)


def _group_weights_of(mesh_data, vertex_groups, group_names: Sequence[str]) -> np.ndarray:
    """(n, k) weights of the named groups (``vertex_groups``: the object's
    list, which numbers them) on the vertices of ``mesh_data``."""
    names = list(group_names)
    column_of_group = np.full(max(len(vertex_groups), 1), -1, dtype=np.int64)
    for column, name in enumerate(names):
        group = vertex_groups.get(name)
        if group is not None:
            column_of_group[group.index] = column
    vertex_count = len(mesh_data.vertices)
    matrix = np.zeros((vertex_count, len(names)), dtype=np.float64)
    if not np.any(column_of_group >= 0):
        return matrix
    # No foreach_get exists for deform weights; one flat comprehension over
    # the elements is the fastest route found (about 0.12 s for 50k vertices
    # with three groups each, half the time of a nested loop).
    memberships = [vertex.groups for vertex in mesh_data.vertices]
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
