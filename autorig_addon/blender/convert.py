"""Conversion between Blender objects and the core's arrays.

Reading goes through ``foreach_get`` into numpy; writing vertex groups goes
through ``VertexGroup.add`` once per distinct weight value, which is the
fastest path the Python API offers (there is no ``foreach_set`` for
deform weights).

Every writer here is all-or-nothing: it snapshots what it is about to touch
(:class:`ObjectSnapshot`) and restores it if anything fails half-way.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import bpy
import numpy as np
from mathutils import Matrix

from ..core.errors import InputError
from ..core.types import Mesh, Skeleton, Weights

#: Name of the INT point attribute holding each vertex's transfer status.
STATUS_ATTRIBUTE = "autorig_transfer_status"
#: Name of the FLOAT_COLOR point attribute that visualises the status.
STATUS_COLOR_ATTRIBUTE = "AutoRig Transfer"
#: Name given to the Armature modifier this add-on creates.
ARMATURE_MODIFIER_NAME = "Armature"

#: RGBA (linear) per transfer status, indexed by ``core.transfer.VertexStatus`` value:
#: copied green, copied through flipped normals teal, inpainted red,
#: masked orange, protected blue, part with no match magenta.
STATUS_COLORS = np.array(
    [
        [0.05, 0.80, 0.10, 1.0],
        [0.00, 0.60, 0.60, 1.0],
        [0.90, 0.05, 0.05, 1.0],
        [1.00, 0.45, 0.00, 1.0],
        [0.10, 0.25, 1.00, 1.0],
        [0.90, 0.00, 0.90, 1.0],
    ],
    dtype=np.float32,
)
#: Colour of a status value outside the table (should not happen; grey shows it).
UNKNOWN_STATUS_COLOR = np.array([0.5, 0.5, 0.5, 1.0], dtype=np.float32)


# --------------------------------------------------------------------------- reading


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
    with armatures_at_rest(object_list):
        if depsgraph is None:
            depsgraph = bpy.context.evaluated_depsgraph_get()
        return Mesh.concatenate([_read_one_mesh(obj, depsgraph) for obj in object_list])


@contextmanager
def armatures_at_rest(objects):
    """Put the armatures deforming ``objects`` in Rest Position while the
    block runs: weights belong to the rest shape, and some files (CesiumMan)
    import posed. The pose setting is restored afterwards."""
    armatures = {
        modifier.object
        for obj in objects if obj is not None and obj.type == "MESH"
        for modifier in obj.modifiers
        if modifier.type == "ARMATURE" and modifier.object is not None
    }
    posed = [armature for armature in armatures if armature.data.pose_position != "REST"]
    for armature in posed:
        armature.data.pose_position = "REST"
    try:
        if posed:
            bpy.context.view_layer.update()
        yield
    finally:
        for armature in posed:
            armature.data.pose_position = "POSE"
        if posed:
            bpy.context.view_layer.update()


def _parents_first_order(parent_of: Sequence[int]) -> list[int]:
    """Bone indices ordered so every parent precedes its children."""
    children: dict[int, list[int]] = {}
    roots = []
    for index, parent in enumerate(parent_of):
        if parent < 0:
            roots.append(index)
        else:
            children.setdefault(parent, []).append(index)
    order, stack = [], list(reversed(roots))
    while stack:
        index = stack.pop()
        order.append(index)
        stack.extend(reversed(children.get(index, [])))
    return order


def require_armature_object(obj) -> None:
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
    ordered parents first.
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
    order = _parents_first_order(parent_of)
    new_index = np.empty(count, dtype=np.int64)
    new_index[order] = np.arange(count)
    parents = np.array([new_index[parent_of[i]] if parent_of[i] >= 0 else -1 for i in order], dtype=np.int64)
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


def find_armature(mesh_obj):
    """The armature deforming ``mesh_obj``: its first Armature modifier's
    object, else its parent when that is an armature.

    Raises
    ------
    InputError when there is none.
    """
    for modifier in mesh_obj.modifiers:
        if modifier.type == "ARMATURE" and modifier.object is not None and modifier.object.type == "ARMATURE":
            return modifier.object
    if mesh_obj.parent is not None and mesh_obj.parent.type == "ARMATURE":
        return mesh_obj.parent
    raise InputError(
        f"'{mesh_obj.name}' is not bound to an armature: give it an Armature modifier "
        "or parent it to the armature (Ctrl+P > With Empty Groups) first."
    )


# --------------------------------------------------------------------------- snapshots


@dataclass
class _GroupState:
    name: str
    lock_weight: bool
    indices: np.ndarray
    weights: np.ndarray


#: Armature modifier settings a snapshot records, so a removed one can be rebuilt.
_ARMATURE_MODIFIER_SETTINGS = (
    "use_vertex_groups", "use_bone_envelopes", "use_deform_preserve_volume", "use_multi_modifier",
    "show_viewport", "show_render", "show_in_editmode", "show_on_cage",
)


@dataclass
class _ModifierState:
    name: str
    armature: object
    index: int
    settings: dict


@dataclass
class _AttributeState:
    name: str
    data_type: str
    domain: str
    values: np.ndarray
    is_color: bool


@dataclass
class ObjectSnapshot:
    """Everything :func:`write_weights` and :func:`write_status_attribute`
    may change on one mesh object, so a failed write can be undone.

    Use :meth:`capture` before writing and :meth:`restore` on failure.
    """

    obj: object
    groups: list = field(default_factory=list)
    active_group_index: int = -1
    modifier_names: list = field(default_factory=list)
    armature_modifiers: list = field(default_factory=list)
    parent: object = None
    parent_type: str = "OBJECT"
    matrix_parent_inverse: Matrix = None
    matrix_basis: Matrix = None
    attributes: list = field(default_factory=list)
    active_color_name: str = ""

    @classmethod
    def capture(cls, obj) -> "ObjectSnapshot":
        snapshot = cls(obj)
        group_names = [group.name for group in obj.vertex_groups]
        matrix = read_group_weights(obj, group_names)
        for column, group in enumerate(obj.vertex_groups):
            members = np.flatnonzero(matrix[:, column] > 0)
            snapshot.groups.append(_GroupState(group.name, group.lock_weight, members, matrix[members, column]))
        # Members with weight exactly 0 are dropped by the snapshot; they
        # carry no influence, so restoring without them changes nothing visible.
        snapshot.active_group_index = obj.vertex_groups.active_index
        snapshot.modifier_names = [modifier.name for modifier in obj.modifiers]
        snapshot.armature_modifiers = [
            _ModifierState(modifier.name, modifier.object, index,
                           {name: getattr(modifier, name) for name in _ARMATURE_MODIFIER_SETTINGS})
            for index, modifier in enumerate(obj.modifiers) if modifier.type == "ARMATURE"
        ]
        snapshot.parent = obj.parent
        snapshot.parent_type = obj.parent_type
        snapshot.matrix_parent_inverse = obj.matrix_parent_inverse.copy()
        snapshot.matrix_basis = obj.matrix_basis.copy()
        mesh_data = obj.data
        for name in (STATUS_ATTRIBUTE, STATUS_COLOR_ATTRIBUTE):
            attribute = mesh_data.attributes.get(name)
            if attribute is not None:
                snapshot.attributes.append(_capture_attribute(mesh_data, attribute))
        active_color = mesh_data.color_attributes.active_color
        snapshot.active_color_name = active_color.name if active_color is not None else ""
        return snapshot

    def restore(self) -> None:
        obj = self.obj
        obj.vertex_groups.clear()
        for state in self.groups:
            group = obj.vertex_groups.new(name=state.name)
            _fill_group(group, state.indices, state.weights)
            group.lock_weight = state.lock_weight
        if self.groups:
            obj.vertex_groups.active_index = max(self.active_group_index, 0)
        for modifier in list(obj.modifiers):
            if modifier.name not in self.modifier_names:
                obj.modifiers.remove(modifier)
        for state in self.armature_modifiers:
            modifier = obj.modifiers.get(state.name)
            if modifier is None:
                modifier = obj.modifiers.new(state.name, "ARMATURE")
            modifier.object = state.armature
            for name, value in state.settings.items():
                setattr(modifier, name, value)
            current = list(obj.modifiers).index(modifier)
            if current != state.index:
                obj.modifiers.move(current, min(state.index, len(obj.modifiers) - 1))
        obj.parent = self.parent
        obj.parent_type = self.parent_type
        obj.matrix_parent_inverse = self.matrix_parent_inverse
        obj.matrix_basis = self.matrix_basis
        _restore_attributes(obj.data, self.attributes, self.active_color_name)


def _capture_attribute(mesh_data, attribute) -> _AttributeState:
    is_color = attribute.data_type in {"FLOAT_COLOR", "BYTE_COLOR"}
    width = 4 if is_color else 1
    values = np.empty(len(attribute.data) * width, dtype=np.float32 if is_color else np.int32)
    attribute.data.foreach_get("color" if is_color else "value", values)
    return _AttributeState(attribute.name, attribute.data_type, attribute.domain, values, is_color)


def _restore_attributes(mesh_data, states: list, active_color_name: str) -> None:
    for name in (STATUS_ATTRIBUTE, STATUS_COLOR_ATTRIBUTE):
        attribute = mesh_data.attributes.get(name)
        if attribute is not None:
            mesh_data.attributes.remove(attribute)
    for state in states:
        if state.is_color:
            attribute = mesh_data.color_attributes.new(state.name, state.data_type, state.domain)
            attribute.data.foreach_set("color", state.values)
        else:
            attribute = mesh_data.attributes.new(state.name, state.data_type, state.domain)
            attribute.data.foreach_set("value", state.values)
    if active_color_name and mesh_data.color_attributes.get(active_color_name) is not None:
        mesh_data.color_attributes.active_color_name = active_color_name


# --------------------------------------------------------------------------- writing


def _fill_group(group, indices: np.ndarray, weights: np.ndarray) -> None:
    """Add ``indices`` (k,) int with ``weights`` (k,) float to a vertex group,
    one ``add`` call per distinct weight value."""
    if not len(indices):
        return
    values, inverse = np.unique(np.asarray(weights, dtype=np.float32), return_inverse=True)
    order = np.argsort(inverse, kind="stable")
    boundaries = np.flatnonzero(np.diff(inverse[order])) + 1
    for value, members in zip(values, np.split(np.asarray(indices)[order], boundaries)):
        group.add(members.tolist(), float(value), "REPLACE")


def _clear_group(group, vertex_count: int) -> None:
    if vertex_count:
        group.remove(list(range(vertex_count)))


def ensure_armature_binding(obj, armature_obj) -> None:
    """Give ``obj`` exactly one Armature modifier, on ``armature_obj``, and
    parent it to the armature, keeping its world transform.

    An existing Armature modifier is reused (one on this armature first,
    then an empty one, then one on another armature, which is retargeted);
    every other Armature modifier is removed, or the mesh would be deformed
    twice. :class:`ObjectSnapshot` can rebuild them."""
    armature_modifiers = [m for m in obj.modifiers if m.type == "ARMATURE"]
    ranked = sorted(armature_modifiers, key=lambda m: (m.object != armature_obj, m.object is not None))
    if ranked:
        keep = ranked[0]
        keep.object = armature_obj
        for modifier in ranked[1:]:
            obj.modifiers.remove(modifier)
    else:
        keep = obj.modifiers.new(ARMATURE_MODIFIER_NAME, "ARMATURE")
        keep.object = armature_obj
        # Deform before anything else (subdivision, solidify) as Ctrl+P does.
        obj.modifiers.move(len(obj.modifiers) - 1, 0)
    keep.use_vertex_groups = True
    if obj.parent != armature_obj:
        world = obj.matrix_world.copy()
        obj.parent = armature_obj
        obj.parent_type = "OBJECT"
        obj.matrix_parent_inverse = armature_obj.matrix_world.inverted_safe()
        obj.matrix_basis = world


def _writable_columns(weights: Weights, armature_obj) -> list[int]:
    """Columns of ``weights`` naming deform bones of the armature."""
    deform = set(deform_bone_names(armature_obj))
    return [k for k, name in enumerate(weights.bone_names) if name in deform]


def write_weights(obj, weights: Weights, armature_obj, *, replace_all: bool = False, keep_groups: Sequence[str] = ()) -> None:
    """Store ``weights`` in ``obj``'s vertex groups and bind it to the armature.

    Parameters
    ----------
    obj : bpy.types.Object of type 'MESH', with ``weights.vertex_count`` vertices
    weights : Weights (n, b)
        Columns naming bones the armature lacks, or bones with
        ``use_deform`` off, are not written. Zero weights are skipped.
    armature_obj : bpy.types.Object of type 'ARMATURE'
    replace_all : bool
        Remove every existing vertex group first (except ``keep_groups``);
        otherwise only the groups of the written bones are cleared and
        refilled, other groups stay.
    keep_groups : sequence of str
        Groups ``replace_all`` leaves alone (the artist's mask groups).

    All-or-nothing: on any exception the object is restored and the
    exception re-raised.
    """
    require_mesh_object(obj, "target")
    require_armature_object(armature_obj)
    vertex_count = len(obj.data.vertices)
    if weights.vertex_count != vertex_count:
        raise InputError(
            f"'{obj.name}' has {vertex_count} vertices but the weights have {weights.vertex_count} rows; "
            "the mesh changed since the weights were computed."
        )
    columns = _writable_columns(weights, armature_obj)
    snapshot = ObjectSnapshot.capture(obj)
    try:
        if replace_all:
            for group in list(obj.vertex_groups):
                if group.name not in keep_groups:
                    obj.vertex_groups.remove(group)
        for column in columns:
            name = weights.bone_names[column]
            values = weights.matrix[:, column]
            members = np.flatnonzero(values > 0)
            group = obj.vertex_groups.get(name)
            if group is None:
                if not len(members):
                    continue
                group = obj.vertex_groups.new(name=name)
            else:
                _clear_group(group, vertex_count)
            _fill_group(group, members, values[members])
        ensure_armature_binding(obj, armature_obj)
    except BaseException:
        snapshot.restore()
        raise


def status_colors(status: np.ndarray) -> np.ndarray:
    """(n, 4) float32 RGBA of each status value (see :data:`STATUS_COLORS`)."""
    status = np.asarray(status, dtype=np.int64).reshape(-1)
    colors = np.tile(UNKNOWN_STATUS_COLOR, (len(status), 1))
    known = (status >= 0) & (status < len(STATUS_COLORS))
    colors[known] = STATUS_COLORS[status[known]]
    return colors


def write_status_attribute(obj, status: np.ndarray) -> None:
    """Store the per-vertex transfer status on ``obj``'s mesh.

    Parameters
    ----------
    obj : bpy.types.Object of type 'MESH'
    status : (n,) int array of ``core.transfer.VertexStatus`` values

    Writes the INT point attribute :data:`STATUS_ATTRIBUTE` and the
    FLOAT_COLOR point attribute :data:`STATUS_COLOR_ATTRIBUTE`, made the
    active colour so Solid shading > Attribute displays it.
    """
    require_mesh_object(obj)
    mesh_data = obj.data
    status = np.asarray(status).reshape(-1)
    if len(status) != len(mesh_data.vertices):
        raise InputError(f"'{obj.name}' has {len(mesh_data.vertices)} vertices but {len(status)} status values.")
    for name in (STATUS_ATTRIBUTE, STATUS_COLOR_ATTRIBUTE):
        existing = mesh_data.attributes.get(name)
        if existing is not None:
            mesh_data.attributes.remove(existing)
    attribute = mesh_data.attributes.new(STATUS_ATTRIBUTE, "INT", "POINT")
    attribute.data.foreach_set("value", status.astype(np.int32))
    colors = mesh_data.color_attributes.new(STATUS_COLOR_ATTRIBUTE, "FLOAT_COLOR", "POINT")
    colors.data.foreach_set("color", status_colors(status).ravel())
    mesh_data.color_attributes.active_color_name = STATUS_COLOR_ATTRIBUTE
    mesh_data.update()


def read_status_attribute(obj) -> np.ndarray | None:
    """(n,) int32 status values written by :func:`write_status_attribute`, or None."""
    attribute = obj.data.attributes.get(STATUS_ATTRIBUTE)
    if attribute is None:
        return None
    values = np.empty(len(attribute.data), dtype=np.int32)
    attribute.data.foreach_get("value", values)
    return values


def vertex_group_mask(obj, group_name: str, threshold: float) -> np.ndarray | None:
    """(n,) bool: vertices whose weight in ``group_name`` is at least
    ``threshold``; None when the group does not exist or is empty."""
    if not group_name or obj.vertex_groups.get(group_name) is None:
        return None
    mask = read_group_weights(obj, [group_name])[:, 0] >= threshold
    return mask if mask.any() else None


def mesh_objects(objects: Iterable) -> list:
    """The mesh objects among ``objects``, order kept."""
    return [obj for obj in objects if obj is not None and obj.type == "MESH"]
