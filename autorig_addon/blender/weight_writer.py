"""Writing skin weights into a mesh: vertex groups and the armature binding.

There is no ``foreach_set`` for deform weights, so a vertex group is filled
through ``VertexGroup.add`` once per distinct weight value, the fastest
path the Python API offers.

The writers change the object in place and are not all-or-nothing by
themselves: a caller wraps all of its writes in
:func:`~.snapshot.restored_on_failure`, so a failure half-way through
restores every object it was writing.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ..core.errors import InputError
from ..core.types import Weights
from .convert import deform_bone_names, require_armature_object, require_mesh_object

#: Name given to the Armature modifier this add-on creates.
ARMATURE_MODIFIER_NAME = "Armature"


def fill_group(group, indices: np.ndarray, weights: np.ndarray) -> None:
    """Add vertices to a vertex group, one ``add`` call per distinct weight value.

    Parameters
    ----------
    group : bpy.types.VertexGroup
    indices : (k,) int array, vertex indices
    weights : (k,) float array, their weights
    """
    if not len(indices):
        return
    values, inverse = np.unique(np.asarray(weights, dtype=np.float32), return_inverse=True)
    order = np.argsort(inverse, kind="stable")
    boundaries = np.flatnonzero(np.diff(inverse[order])) + 1
    for value, members in zip(values, np.split(np.asarray(indices)[order], boundaries)):
        group.add(members.tolist(), float(value), "REPLACE")


def clear_group(group, vertex_count: int) -> None:
    """Remove every one of the mesh's ``vertex_count`` vertices from ``group``."""
    if vertex_count:
        group.remove(list(range(vertex_count)))


def ensure_armature_binding(obj, armature_obj) -> None:
    """Give ``obj`` exactly one Armature modifier, on ``armature_obj``, and
    parent it to the armature, keeping its world transform.

    An existing Armature modifier is reused (one on this armature first,
    then an empty one, then one on another armature, which is retargeted);
    every other Armature modifier is removed, or the mesh would be deformed
    twice. :class:`~.snapshot.ObjectSnapshot` can rebuild them."""
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
            clear_group(group, vertex_count)
        fill_group(group, members, values[members])
    ensure_armature_binding(obj, armature_obj)
