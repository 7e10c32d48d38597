"""Renaming a standard biped skeleton to another bone-name preset
(:mod:`..core.skeleton.name_presets`), its meshes' vertex groups with it.

Blender renames the vertex groups of the meshes an armature deforms and the
animation paths that name a bone when the bone is renamed; the groups are
checked here all the same, so a mesh bound another way (a group named
after a bone, no modifier yet) follows too.
"""

from __future__ import annotations

import uuid

from ..core.errors import InputError
from ..core.skeleton.name_presets import renamed
from . import convert
from .armature_binding import followers


def rename_bones(armature, preset: str) -> dict:
    """Rename ``armature``'s standard bones to ``preset``; returns old -> new
    for the bones whose name changed.

    Raises
    ------
    InputError for an armature in Edit Mode, a skeleton that is not a
    standard biped, or an unknown preset. Nothing is renamed then.
    """
    convert.require_armature_object(armature)
    if armature.mode == "EDIT":
        raise InputError(f"'{armature.name}' is in Edit Mode: leave it to rename its bones.")
    mapping = {old: new for old, new in renamed([bone.name for bone in armature.data.bones], preset).items()
               if old != new}
    if not mapping:
        return {}
    meshes = [obj for obj in followers(armature) if obj.type == "MESH"]
    # Through unique temporary names: one preset's name may be another bone's name in the other (VRM's
    # "spine" is Rigify's "spine.001"), and Blender would number a clash instead.
    temporary = {old: f"{old}~{uuid.uuid4().hex[:8]}" for old in mapping}
    for step in (temporary, {temporary[old]: new for old, new in mapping.items()}):
        for old, new in step.items():
            armature.data.bones[old].name = new
            for obj in meshes:
                group = obj.vertex_groups.get(old)
                if group is not None:
                    group.name = new
    return mapping
