"""Snapshots of what the writers change on a mesh object, for all-or-nothing writes.

:class:`ObjectSnapshot` records an object's mesh datablock, vertex groups,
Armature modifiers, parent and transform, and status attributes;
:func:`restored_on_failure` takes one of every object a block is about to
write and restores them all if the block raises, as the glTF importer
cleans up its helper objects in ``finally``.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Iterable

import bpy
import numpy as np
from mathutils import Matrix

from .convert import read_group_weights
from .status_attribute import STATUS_ATTRIBUTE_NAMES, remove_status_attributes
from .weight_writer import fill_groups

#: Armature modifier settings a snapshot records, so a removed one can be rebuilt.
_ARMATURE_MODIFIER_SETTINGS = (
    "use_vertex_groups", "use_bone_envelopes", "use_deform_preserve_volume", "use_multi_modifier",
    "show_viewport", "show_render", "show_in_editmode", "show_on_cage",
)


@dataclass
class _GroupState:
    """A vertex group: its members (k,) int64 and their weights (k,) float64."""

    name: str
    lock_weight: bool
    indices: np.ndarray
    weights: np.ndarray


@dataclass
class _ModifierState:
    """An Armature modifier: its armature, stack position and :data:`_ARMATURE_MODIFIER_SETTINGS`."""

    name: str
    armature: object
    index: int
    settings: dict


@dataclass
class _AttributeState:
    """A mesh attribute's values, flat: (n,) int32, or (4 n,) float32 for colours."""

    name: str
    data_type: str
    domain: str
    values: np.ndarray
    is_color: bool


@dataclass
class ObjectSnapshot:
    """Everything :func:`~.weight_writer.write_weights` and
    :func:`~.status_attribute.write_status_attribute` may change on one
    mesh object, so a failed write can be undone.

    Use :meth:`capture` before writing and :meth:`restore` on failure, or
    both at once through :func:`restored_on_failure`.
    """

    obj: object
    mesh: object = None
    groups: list = field(default_factory=list)
    active_group_index: int = -1
    modifier_names: list = field(default_factory=list)
    armature_modifiers: list = field(default_factory=list)
    parent: object = None
    parent_type: str = "OBJECT"
    parent_bone: str = ""
    matrix_parent_inverse: Matrix = None
    matrix_basis: Matrix = None
    attributes: list = field(default_factory=list)
    active_color_name: str = ""

    @classmethod
    def capture(cls, obj) -> "ObjectSnapshot":
        snapshot = cls(obj, obj.data)
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
        snapshot.parent_bone = obj.parent_bone
        snapshot.matrix_parent_inverse = obj.matrix_parent_inverse.copy()
        snapshot.matrix_basis = obj.matrix_basis.copy()
        mesh_data = obj.data
        for name in STATUS_ATTRIBUTE_NAMES:
            attribute = mesh_data.attributes.get(name)
            if attribute is not None:
                snapshot.attributes.append(_capture_attribute(attribute))
        active_color = mesh_data.color_attributes.active_color
        snapshot.active_color_name = active_color.name if active_color is not None else ""
        return snapshot

    def restore(self) -> None:
        obj = self.obj
        if obj.data != self.mesh:
            # A write gave a linked duplicate its own mesh: share the original again.
            own = obj.data
            obj.data = self.mesh
            if own.users == 0:
                bpy.data.meshes.remove(own)
        obj.vertex_groups.clear()
        vertex_count = len(obj.data.vertices)
        # All groups in one call (one scratch scene): dense, as capture read
        # them (read_group_weights), so no more memory than capture took.
        columns = {}
        for state in self.groups:
            column = np.zeros(vertex_count)
            column[state.indices] = state.weights
            columns[state.name] = column
        fill_groups(obj, columns)
        for state in self.groups:
            obj.vertex_groups[state.name].lock_weight = state.lock_weight
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
        obj.parent_bone = self.parent_bone
        obj.matrix_parent_inverse = self.matrix_parent_inverse
        obj.matrix_basis = self.matrix_basis
        _restore_attributes(obj.data, self.attributes, self.active_color_name)


def _capture_attribute(attribute) -> _AttributeState:
    is_color = attribute.data_type in {"FLOAT_COLOR", "BYTE_COLOR"}
    width = 4 if is_color else 1
    values = np.empty(len(attribute.data) * width, dtype=np.float32 if is_color else np.int32)
    attribute.data.foreach_get("color" if is_color else "value", values)
    return _AttributeState(attribute.name, attribute.data_type, attribute.domain, values, is_color)


def _restore_attributes(mesh_data, states: list, active_color_name: str) -> None:
    remove_status_attributes(mesh_data)
    for state in states:
        if state.is_color:
            attribute = mesh_data.color_attributes.new(state.name, state.data_type, state.domain)
            attribute.data.foreach_set("color", state.values)
        else:
            attribute = mesh_data.attributes.new(state.name, state.data_type, state.domain)
            attribute.data.foreach_set("value", state.values)
    if active_color_name and mesh_data.color_attributes.get(active_color_name) is not None:
        mesh_data.color_attributes.active_color_name = active_color_name


@contextmanager
def restored_on_failure(objects: Iterable):
    """Run a block that writes to ``objects``; if it raises, put every one
    of them back as it was and re-raise.

    Parameters
    ----------
    objects : iterable of bpy.types.Object of type 'MESH'
        Every object the block may change; each is captured once, before
        the block runs.

    Examples
    --------
    >>> with restored_on_failure(meshes):             # doctest: +SKIP
    ...     for obj, weights in zip(meshes, rows):
    ...         write_weights(obj, weights, armature)
    """
    snapshots = [ObjectSnapshot.capture(obj) for obj in objects]
    try:
        yield
    except BaseException:
        for snapshot in snapshots:
            snapshot.restore()
        raise
