"""Writing skin weights into a mesh: vertex groups and the armature binding.

There is no ``foreach_set`` for deform weights, and ``VertexGroup.add``
takes one weight per call: continuous weights (every vertex its own value)
cost one call per vertex and group. Instead each group goes in whole: its
weights into a temporary float point attribute with ``foreach_set``, which
Blender's *Convert Attribute* operator turns into a vertex group (vertices
of weight 0 are not members; the float32 values are stored exactly).

``bpy.ops`` re-evaluates the context's view layer around every operator
call, which re-runs the object's modifiers (its Armature modifier, when the
mesh is already bound) once per group and costs more than the conversion
itself. The operators therefore run with a temporary, empty scene as their
context (:func:`_operator_context`), so that evaluation is empty; the
object is evaluated once, when the job is done. Measured:
``bench/bench_weight_writer.py``, ``docs/benchmarks.md``.

The writers change the object in place and are not all-or-nothing by
themselves: a caller wraps all of its writes in
:func:`~.snapshot.restored_on_failure`, so a failure half-way through
restores every object it was writing.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Mapping, Sequence

import bpy
import numpy as np

from ..core.errors import InputError
from ..core.types import Weights
from .convert import deform_bone_names, read_group_weights, require_armature_object, require_mesh_object
from .modifier_stack import armature_place, kept_armature_modifier

#: Name given to the Armature modifier this add-on creates.
ARMATURE_MODIFIER_NAME = "Armature"
#: Start of the temporary attribute names a group is written through.
_TEMPORARY_ATTRIBUTE_PREFIX = "autorig_group_"
#: Name of the temporary scene the conversions run in (removed afterwards).
_SCRATCH_SCENE_NAME = "AutoRig scratch"


def _unused_attribute_name(obj) -> str:
    """A name neither an attribute nor a vertex group of ``obj`` uses."""
    taken = {attribute.name for attribute in obj.data.attributes} | {group.name for group in obj.vertex_groups}
    number = 0
    while f"{_TEMPORARY_ATTRIBUTE_PREFIX}{number}" in taken:
        number += 1
    return f"{_TEMPORARY_ATTRIBUTE_PREFIX}{number}"


@contextmanager
def _operator_context(obj):
    """Run ``bpy.ops`` on ``obj`` with a temporary empty scene as the context's
    scene and view layer, so the view-layer updates around each call
    evaluate nothing (module docstring); the scene is always removed."""
    scene = bpy.data.scenes.new(_SCRATCH_SCENE_NAME)
    try:
        with bpy.context.temp_override(object=obj, active_object=obj, scene=scene, view_layer=scene.view_layers[0]):
            yield
    finally:
        bpy.data.scenes.remove(scene)


def _new_group_from_values(obj, name: str, values: np.ndarray):
    """A new vertex group ``name`` holding ``values`` (members: values > 0),
    converted from a temporary attribute; call inside :func:`_operator_context`."""
    mesh = obj.data
    attribute = mesh.attributes.new(_unused_attribute_name(obj), "FLOAT", "POINT")
    temporary = attribute.name
    attribute.data.foreach_set("value", np.where(values > 0, values, 0.0).astype(np.float32))
    mesh.attributes.active = attribute
    try:
        bpy.ops.geometry.attribute_convert(mode="VERTEX_GROUP")
    except BaseException:
        # A failed conversion must not leave the temporary attribute behind.
        if mesh.attributes.get(temporary) is not None:
            mesh.attributes.remove(mesh.attributes[temporary])
        raise
    group = obj.vertex_groups[temporary]
    group.name = name
    return group


def fill_groups(obj, values: Mapping[str, np.ndarray]) -> None:
    """Set each named vertex group of ``obj`` to exactly the given weights.

    Parameters
    ----------
    obj : bpy.types.Object of type 'MESH'
    values : mapping of group name -> (n,) float array, one weight per vertex
        Vertices with a weight of 0 or less are not members. Weights are
        stored as float32, exactly.

    An existing group keeps its place in the list and its lock; new groups
    are appended in the mapping's order; the active group stays active.
    Groups after the first refilled one are rebuilt with their own weights
    (one conversion per group, whatever their order); a vertex that was a
    member of such a kept group with weight 0 is no longer a member.
    """
    if not values:
        return
    groups = obj.vertex_groups
    order = [group.name for group in groups]
    refilled = [index for index, name in enumerate(order) if name in values]
    # Blender moves a group one place per operator call, so putting refilled
    # groups back in place would cost O(groups^2) calls when they come in
    # another order. Instead every group from the first refilled one on is
    # rebuilt in the list's order, the kept ones with their own weights
    # read back: one conversion per group whatever the order.
    start = refilled[0] if refilled else len(order)
    rebuilt = {name: np.asarray(values[name], dtype=np.float64).reshape(-1) if name in values else None
               for name in order[start:]}
    kept = [name for name, weights in rebuilt.items() if weights is None]
    if kept:
        for name, column in zip(kept, read_group_weights(obj, kept).T):
            rebuilt[name] = column
    rebuilt.update({name: np.asarray(weights, dtype=np.float64).reshape(-1)
                    for name, weights in values.items() if name not in rebuilt})
    locks = {group.name: group.lock_weight for group in groups}
    active = groups.active.name if groups.active is not None else None
    attributes = obj.data.attributes
    active_attribute = attributes.active.name if attributes.active is not None else None
    for name in order[start:]:
        groups.remove(groups[name])
    with _operator_context(obj):
        for name, weights in rebuilt.items():
            group = _new_group_from_values(obj, name, weights)
            group.lock_weight = locks.get(name, False)
    if active is not None:
        groups.active_index = groups[active].index
    if active_attribute is not None and attributes.get(active_attribute) is not None:
        attributes.active = attributes[active_attribute]


def ensure_armature_binding(obj, armature_obj, world=None) -> None:
    """Give ``obj`` exactly one Armature modifier, on ``armature_obj``, and
    parent it to the armature object (never to a bone, nor with the old
    *Armature* parent type: either would move it a second time), keeping
    its world transform.

    An existing Armature modifier is reused where it is
    (:func:`~.modifier_stack.kept_armature_modifier`: one on this armature
    first, then an empty one, then one on another armature, which is
    retargeted); every other Armature modifier is removed, or the mesh would
    be deformed twice. :class:`~.snapshot.ObjectSnapshot` can rebuild them.
    A new one goes where posing deforms the rest shape the user sees
    (:func:`~.modifier_stack.armature_place`).

    Parameters
    ----------
    obj : bpy.types.Object of type 'MESH'
    armature_obj : bpy.types.Object of type 'ARMATURE'
    world : mathutils.Matrix or None
        World matrix to keep when the parent changes (default: the current
        one). A prop carried by a bone of a posed armature passes its rest
        one (:class:`~.object_roles.RigidBinding`).
    """
    keep = kept_armature_modifier(obj, armature_obj)
    if keep is not None:
        for modifier in [m for m in obj.modifiers if m.type == "ARMATURE" and m != keep]:
            obj.modifiers.remove(modifier)
    else:
        place = armature_place(obj)
        keep = obj.modifiers.new(ARMATURE_MODIFIER_NAME, "ARMATURE")
        # After the modifiers that shape the rest pose (a Mirror, a Simple
        # Deform), before those that finish the surface (subdivision, solidify).
        obj.modifiers.move(len(obj.modifiers) - 1, place)
    keep.object = armature_obj
    keep.use_vertex_groups = True
    if obj.parent != armature_obj or obj.parent_type != "OBJECT":
        world = (obj.matrix_world if world is None else world).copy()
        obj.parent = armature_obj
        obj.parent_type = "OBJECT"
        obj.parent_bone = ""
        obj.matrix_parent_inverse = armature_obj.matrix_world.inverted_safe()
        obj.matrix_basis = world


def _writable_columns(weights: Weights, armature_obj) -> list[int]:
    """Columns of ``weights`` naming deform bones of the armature."""
    deform = set(deform_bone_names(armature_obj))
    return [k for k, name in enumerate(weights.bone_names) if name in deform]


def write_weights(obj, weights: Weights, armature_obj, *, replace_all: bool = False, keep_groups: Sequence[str] = (),
                  world=None, every_bone: bool = False) -> None:
    """Store ``weights`` in ``obj``'s vertex groups and bind it to the armature
    (:func:`ensure_armature_binding`).

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
    world : mathutils.Matrix or None, passed to :func:`ensure_armature_binding`
    every_bone : bool
        Give every written deform bone a group, an empty one where it has no
        weight (a Mirror modifier gives its copies the mirrored bone's
        group only when that group exists).

    Raises
    ------
    InputError, before anything is changed, for a non-mesh, a non-armature
    or a row count other than the mesh's vertex count. Wrap the call in
    :func:`~.snapshot.restored_on_failure` to undo a write that fails later.
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
    if replace_all:
        for group in list(obj.vertex_groups):
            if group.name not in keep_groups:
                obj.vertex_groups.remove(group)
    used = np.any(weights.matrix > 0, axis=0)
    values = {}
    for column in columns:
        name = weights.bone_names[column]
        # A bone with no weight anywhere gets no new group, and an existing one is emptied.
        if every_bone or used[column] or obj.vertex_groups.get(name) is not None:
            values[name] = weights.matrix[:, column]
    fill_groups(obj, values)
    ensure_armature_binding(obj, armature_obj, world)


def bind_to_bone(obj, armature_obj, bone: str, rest_world) -> None:
    """Bind a prop wholly to one deform bone: every vertex in that bone's
    group with weight 1, the other deform bones' groups emptied, and the
    armature as object parent, placed at ``rest_world`` (its world matrix
    with the armature at rest), so the Armature modifier moves it as its
    bone parent did."""
    names = deform_bone_names(armature_obj)
    matrix = np.zeros((len(obj.data.vertices), len(names)))
    matrix[:, names.index(bone)] = 1.0
    write_weights(obj, Weights(matrix, names), armature_obj, world=rest_world)
