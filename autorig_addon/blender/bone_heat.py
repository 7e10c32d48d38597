"""Blender's Automatic Weights (bone heat), run as the baseline it is for artists.

``eval skin --method boneheat`` scores it against the artist's weights. It
runs on copies (meshes built from the arrays, a copy of the armature with
the bones measured with) so the loaded file never changes.
"""

from __future__ import annotations

import contextlib

import bpy
import numpy as np

from ..core.errors import InputError
from ..core.geometry.weld import weld_objects
from ..core.types import Mesh, Skeleton, Weights
from . import convert
from .armature_binding import pose_position, remove_armature
from .scratch_objects import SCRATCH_NAME, remove_scratch_object, scratch_object


@contextlib.contextmanager
def _armature_with_tails(armature_obj, skeleton: Skeleton):
    """A temporary copy of ``armature_obj`` whose bones end at ``skeleton.tails``.

    Blender's bone heat diffuses from the armature's own bones, so they must
    be the bones measured with: the skeleton's tails (derived from the joints
    when the stored ones are point-like, ``core.skeleton.tails``) are set on
    a copy of the object and its armature data, so nothing of the loaded
    file changes. World-space tails go through the inverse of the
    armature's ``matrix_world``; heads stay as stored. Every bone of the copy
    is disconnected first, since a connected child's head follows its
    parent's tail (roll changes with the tail, which bone heat ignores).
    ``Bone.use_deform`` is set from ``skeleton.deform``. The copy is removed
    on leaving the block.
    """
    data = armature_obj.data.copy()
    rig = armature_obj.copy()
    rig.data = data
    rig.name = SCRATCH_NAME
    rig.animation_data_clear()
    bpy.context.scene.collection.objects.link(rig)
    try:
        rig.hide_viewport = False
        rig.hide_select = False
        rig.hide_set(False)
        if bpy.context.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        for obj in bpy.context.view_layer.objects:
            obj.select_set(False)
        rig.select_set(True)
        bpy.context.view_layer.objects.active = rig
        bpy.context.view_layer.update()
        inverse = np.linalg.inv(np.array([list(row) for row in armature_obj.matrix_world], dtype=np.float64))
        local_tails = skeleton.tails @ inverse[:3, :3].T + inverse[:3, 3]
        bpy.ops.object.mode_set(mode="EDIT")
        try:
            edit_bones = data.edit_bones
            for bone in edit_bones:
                bone.use_connect = False
            for name, tail in zip(skeleton.names, local_tails):
                bone = edit_bones.get(name)
                if bone is not None:
                    bone.tail = tail.tolist()
        finally:
            bpy.ops.object.mode_set(mode="OBJECT")
        wanted = dict(zip(skeleton.names, skeleton.deform.tolist()))
        for bone in data.bones:
            bone.use_deform = bool(wanted.get(bone.name, False))
        yield rig
    finally:
        if bpy.context.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        remove_armature(rig)


def bone_heat_weights(mesh: Mesh, skeleton: Skeleton, armature_obj) -> Weights:
    """Blender's Automatic Weights (bone heat) on a copy of ``mesh``.

    Each object of ``mesh`` becomes a new mesh object built from the arrays
    alone, so no existing vertex group can leak in. Coincident vertices are
    welded first, as an artist runs Merge by Distance before Ctrl+P: bone
    heat fails ("failed to find solution for one or more bones") on meshes
    split at UV seams, which every glTF import is. Bone heat measures from
    the bones, so it runs against a temporary copy of the armature whose
    bones have ``skeleton.tails`` (:func:`_armature_with_tails`): with the
    point-like bones Blender's glTF importer makes for the Quaternius
    characters it scores L1 0.33 on the T-rex, with the derived tails of
    :func:`.characters.read_character` 0.055. The copies are parented to it with
    ``parent_set(type='ARMATURE_AUTO')`` in REST position, their weights
    read back onto the original vertices and every copy removed.

    Parameters
    ----------
    mesh : Mesh, world space, rest pose
    skeleton : Skeleton whose ``deform`` flags choose the bones that get
        weights and whose ``tails`` end the bones (world space)
    armature_obj : bpy.types.Object of type 'ARMATURE', with bones named as
        in ``skeleton``; never changed

    Returns
    -------
    Weights (n, d) over the deform bones; rows of vertices bone heat left
    unweighted (it still fails on some meshes) are zero. Not renormalised.
    """
    deform_names = skeleton.deform_subset().names
    parts, to_welded = weld_objects(mesh)
    with _armature_with_tails(armature_obj, skeleton) as rig:
        copies = []
        try:
            copies.extend(scratch_object(part) for part in parts)
            with pose_position([rig]):
                for obj in bpy.context.view_layer.objects:
                    obj.select_set(False)
                for copy in copies:
                    copy.select_set(True)
                rig.select_set(True)
                bpy.context.view_layer.objects.active = rig
                try:
                    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
                except RuntimeError as error:
                    raise InputError(f"Blender's Automatic Weights failed: {error}") from None
                matrix = np.concatenate([convert.read_group_weights(copy, deform_names) for copy in copies])
        finally:
            for copy in copies:
                remove_scratch_object(copy)
    return Weights(matrix[to_welded], deform_names)
