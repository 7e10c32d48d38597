"""Rename Bones: a standard biped skeleton's bones to another preset (Rigify, Mixamo, Unreal, Unity, VRM, Godot)."""

from __future__ import annotations

import bpy
from bpy.props import EnumProperty

from ...core.errors import InputError
from ...core.skeleton.name_presets import DEFAULT_PRESET, PRESET_LABELS, PRESET_TITLES
from ..bone_names import rename_bones

#: The Names menu: (identifier, title, tooltip) per preset.
PRESET_ITEMS = [(preset, PRESET_TITLES[preset], label) for preset, label in PRESET_LABELS.items()]


def _active_armature(context):
    obj = context.active_object
    return obj if obj is not None and obj.type == "ARMATURE" else None


class AUTORIG_OT_rename_bones(bpy.types.Operator):
    """Rename the active standard biped skeleton's bones (and its meshes' vertex groups) to an engine's or mocap library's names"""  # noqa: E501

    bl_idname = "autorig.rename_bones"
    bl_label = "Rename Bones"
    bl_options = {"REGISTER", "UNDO"}

    preset: EnumProperty(
        name="Names",
        description="The bone names to give",
        items=PRESET_ITEMS,
        default=DEFAULT_PRESET,
    )

    @classmethod
    def poll(cls, context):
        if _active_armature(context) is None:
            cls.poll_message_set("Make the skeleton (an armature) active")
            return False
        return True

    def execute(self, context):
        armature = _active_armature(context)
        try:
            mapping = rename_bones(armature, self.preset)
        except InputError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        label = PRESET_TITLES[self.preset]
        if not mapping:
            self.report({"INFO"}, f"'{armature.name}' already has {label} names.")
        else:
            self.report({"INFO"}, f"Renamed {len(mapping)} bones of '{armature.name}' (and their vertex groups) to "
                                  f"{label} names.")
        return {"FINISHED"}


classes = (AUTORIG_OT_rename_bones,)
