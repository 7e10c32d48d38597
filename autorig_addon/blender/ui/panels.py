"""Sidebar panels (3D Viewport > N > AutoRig)."""

import bpy

from ...core.skinning.methods import GEOMETRIC
from ..jobs.rig import live_note
from ..operators.bone_names import AUTORIG_OT_rename_bones
from ..operators.rig import AUTORIG_OT_auto_rig, AUTORIG_OT_predict_skeleton
from ..operators.skin import AUTORIG_OT_skin_weights
from ..operators.transfer import AUTORIG_OT_create_transfer_mask, AUTORIG_OT_transfer_weights
from ..selection import selected_meshes, selected_targets

#: Sidebar tab the add-on's panels live in.
SIDEBAR_CATEGORY = "AutoRig"
#: Object names a panel lists before counting the rest ("Shirt, Pants, Hat +2").
MAX_LISTED_OBJECTS = 3


class VIEW3D_PT_autorig(bpy.types.Panel):
    """Parent panel; Rig, Transfer and Skin panels open beneath it."""

    bl_label = "AutoRig"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = SIDEBAR_CATEGORY

    def draw(self, context):
        self.layout.label(text="Automatic rigging, skinning and weight transfer", icon="ARMATURE_DATA")


def _short_list(names: list[str]) -> str:
    """``names`` joined by commas, the ones past :data:`MAX_LISTED_OBJECTS` only counted."""
    extra = len(names) - MAX_LISTED_OBJECTS
    return ", ".join(names[:MAX_LISTED_OBJECTS]) + (f" +{extra}" if extra > 0 else "")


class _AutoRigSubPanel:
    """Shared placement of the panels under the AutoRig parent panel; a
    subclass draws with ``draw_settings(layout, settings, context)``."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = SIDEBAR_CATEGORY
    bl_parent_id = "VIEW3D_PT_autorig"

    @classmethod
    def poll(cls, context):
        return getattr(context.scene, "autorig", None) is not None

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        self.draw_settings(layout, context.scene.autorig, context)


class VIEW3D_PT_autorig_transfer(_AutoRigSubPanel, bpy.types.Panel):
    bl_label = "Weight Transfer"

    def draw_settings(self, layout, settings, context):
        column = layout.column(align=True)
        column.prop(settings, "source")
        column.prop(settings, "target")
        targets = [obj.name for obj in selected_targets(context.selected_objects, settings.source, settings.target)]
        if targets:
            column.label(text=f"Targets: {_short_list(targets)}", icon="MESH_DATA")
        else:
            column.label(text="Select the meshes to weight", icon="INFO")

        column = layout.column(align=True)
        column.prop(settings, "use_absolute_distance")
        if settings.use_absolute_distance:
            column.prop(settings, "max_distance")
        else:
            column.prop(settings, "distance_fraction")
        column.prop(settings, "max_normal_angle")
        column.prop(settings, "accept_flipped_normals")
        column.prop(settings, "allow_poor_match")

        column = layout.column(align=True)
        column.prop(settings, "smoothing_length")
        column.prop(settings, "smoothing_iterations")
        row = column.row()
        row.active = settings.smoothing_iterations > 0
        row.prop(settings, "smoothing_strength")
        column.prop(settings, "max_influences")
        column.prop(settings, "rigid_accessory")

        mask_target = settings.target or context.active_object
        column = layout.column(align=True)
        if mask_target is not None and mask_target.type == "MESH":
            column.prop_search(settings, "mask_group", mask_target, "vertex_groups")
            column.prop_search(settings, "protect_group", mask_target, "vertex_groups")
        else:
            column.prop(settings, "mask_group")
            column.prop(settings, "protect_group")
        column.operator(AUTORIG_OT_create_transfer_mask.bl_idname, icon="BRUSH_DATA")

        column = layout.column(align=True)
        column.prop(settings, "bone_subset")
        column.prop(settings, "replace_mode")
        row = column.row()
        row.active = settings.replace_mode == "MIX"
        row.prop(settings, "mix_factor")

        layout.operator(AUTORIG_OT_transfer_weights.bl_idname, icon="MOD_VERTEX_WEIGHT")


class VIEW3D_PT_autorig_skin(_AutoRigSubPanel, bpy.types.Panel):
    bl_label = "Skin Weights"

    def draw_settings(self, layout, settings, context):
        armatures = [obj.name for obj in context.selected_objects if obj.type == "ARMATURE"]
        meshes = [obj.name for obj in context.selected_objects if obj.type == "MESH"]
        column = layout.column(align=True)
        if len(armatures) == 1 and meshes:
            column.label(text=f"{_short_list(meshes)} to {armatures[0]}", icon="ARMATURE_DATA")
        else:
            column.label(text="Select the meshes and one armature", icon="INFO")

        column = layout.column(align=True)
        column.prop(settings, "skin_method")
        column.prop(settings, "skin_resolution")
        column.prop(settings, "skin_max_influences")
        column.prop(settings, "skin_rigid_parts")
        column.prop(settings, "skin_replace_all")
        # The networks ignore the geometric method's own options.
        column = layout.column(align=True)
        column.enabled = settings.skin_method == GEOMETRIC.upper()
        column.prop(settings, "skin_distance")
        column.prop(settings, "skin_falloff")
        column.prop(settings, "skin_smoothing_iterations")
        row = column.row()
        row.active = settings.skin_smoothing_iterations > 0
        row.prop(settings, "skin_smoothing_strength")
        layout.operator(AUTORIG_OT_skin_weights.bl_idname, icon="MOD_ARMATURE")


class VIEW3D_PT_autorig_rig(_AutoRigSubPanel, bpy.types.Panel):
    """Predict a skeleton for the selected meshes, tune it live, skin it, or all in one click."""

    bl_label = "Rig"

    def draw_settings(self, layout, settings, context):
        meshes = [obj.name for obj in selected_meshes(context)]
        column = layout.column(align=True)
        if meshes:
            column.label(text=f"Character: {_short_list(meshes)}", icon="MESH_DATA")
        else:
            column.label(text="Select the character's mesh(es)", icon="INFO")

        layout.prop(settings, "rig_template")
        fingers = layout.row()
        # Only a standard biped has fingers.
        fingers.active = settings.rig_template in ("AUTO", "BIPED")
        fingers.prop(settings, "rig_fingers")
        layout.prop(settings, "rig_names")
        column = layout.column(align=True)
        detail = column.column(align=True)
        # The clustering shapes only the free-form skeleton (a standard one has its fixed bones).
        detail.active = settings.rig_template in ("AUTO", "FREE-FORM")
        detail.prop(settings, "rig_bandwidth")
        detail.prop(settings, "rig_density_threshold")
        column.prop(settings, "rig_symmetry")
        column.prop(settings, "rig_keep_poor")
        note, icon = live_note(context)
        if note:
            layout.label(text=note, icon=icon)

        layout.operator(AUTORIG_OT_predict_skeleton.bl_idname, icon="ARMATURE_DATA")
        layout.operator(AUTORIG_OT_skin_weights.bl_idname, text="Skin", icon="MOD_ARMATURE")
        column = layout.column(align=True)
        column.prop(settings, "rig_replace")
        column.prop(settings, "rig_rigify")
        column.operator(AUTORIG_OT_auto_rig.bl_idname, icon="OUTLINER_OB_ARMATURE")
        generate = column.operator(AUTORIG_OT_auto_rig.bl_idname, text="Generate Rigify Rig", icon="POSE_HLT")
        generate.rig_rigify = True
        layout.operator_menu_enum(AUTORIG_OT_rename_bones.bl_idname, "preset", text="Rename Bones", icon="SORTALPHA")


classes = (VIEW3D_PT_autorig, VIEW3D_PT_autorig_rig, VIEW3D_PT_autorig_transfer, VIEW3D_PT_autorig_skin)
