"""Turn a core :class:`~autorig_addon.core.types.Skeleton` into a Blender armature in one step.

Like Rigify's generation from a metarig: the skeleton is plain data, this
module writes it out whole or not at all (a failure removes everything it
created and restores the active object and mode).
"""

from __future__ import annotations

import bpy
import numpy as np
from mathutils import Vector

from ..core.errors import InputError
from ..core.skeleton.checks import check_buildable, skeleton_extent
from ..core.types import Skeleton
from .armature_binding import remove_armature

#: A child whose head sits on its parent's tail (within this fraction of the
#: skeleton's extent) is connected to it, so grabbing the parent's tail moves the child.
CONNECT_FRACTION = 1e-6


def build_armature(skeleton: Skeleton, name: str, context=None, collection=None):
    """A new armature object holding ``skeleton`` in world space.

    Parameters
    ----------
    skeleton : Skeleton, world-space joints and tails
    name : str, name of the object and its armature data
    context : bpy.types.Context, default ``bpy.context``
    collection : bpy.types.Collection, default the scene's active collection

    Returns
    -------
    bpy.types.Object of type 'ARMATURE', with identity transform, in Object
    Mode. The previously active object becomes active again.

    Raises
    ------
    InputError when Blender cannot hold the skeleton
    (:func:`~autorig_addon.core.skeleton.checks.check_buildable`) or the
    active object is not in Object Mode; nothing is created then.
    """
    check_buildable(skeleton)
    context = context or bpy.context
    collection = collection or context.view_layer.active_layer_collection.collection
    view_layer = context.view_layer
    previous_active = view_layer.objects.active
    if previous_active is not None and previous_active.mode != "OBJECT":
        raise InputError(f"Leave {previous_active.mode.replace('_', ' ').title()} Mode on "
                         f"'{previous_active.name}' first.")

    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    try:
        collection.objects.link(obj)
        view_layer.objects.active = obj
        bpy.ops.object.mode_set(mode="EDIT")
        try:
            _add_edit_bones(data, skeleton)
        finally:
            bpy.ops.object.mode_set(mode="OBJECT")
        if len(data.bones) != skeleton.bone_count:
            raise InputError("Blender dropped some bones while building the armature.")
        for bone, deform in zip((data.bones[n] for n in skeleton.names), skeleton.deform):
            bone.use_deform = bool(deform)
    except BaseException:
        remove_armature(obj)
        view_layer.objects.active = previous_active
        raise
    view_layer.objects.active = previous_active
    return obj


def _add_edit_bones(data, skeleton: Skeleton) -> None:
    size = skeleton_extent(skeleton)
    edit_bones = []
    for j, bone_name in enumerate(skeleton.names):
        bone = data.edit_bones.new(bone_name)
        bone.head = Vector(skeleton.joints[j].tolist())
        bone.tail = Vector(skeleton.tails[j].tolist())
        edit_bones.append(bone)
    for j, parent in enumerate(skeleton.parents):
        if parent < 0:
            continue
        edit_bones[j].parent = edit_bones[parent]
        gap = np.linalg.norm(skeleton.joints[j] - skeleton.tails[parent])
        edit_bones[j].use_connect = bool(gap <= CONNECT_FRACTION * size)
