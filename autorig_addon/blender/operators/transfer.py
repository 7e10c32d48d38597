"""The Transfer Weights and Paint Inpaint Mask operators: the objects from
the operator's names or the selection (:mod:`..selection`), the options
from its properties, the work done by :mod:`..jobs.transfer`."""

import bpy
from bpy.props import StringProperty

from ...core.errors import Cancelled, InputError
from ...core.transfer.options import GROUP_MEMBER_THRESHOLD
from .. import convert
from ..armature_binding import find_armature
from ..jobs.input_checks import check_mode, mode_poll
from ..jobs.transfer import outcome_report, run_transfer
from ..progress import blender_progress
from ..selection import (
    PICK_IN_PANEL,
    PICK_IN_SCRIPT,
    HowToPick,
    chosen_bone_names,
    object_named,
    resolve_source,
    resolve_targets,
    selected_targets,
)
from ..ui.properties import TRANSFER_OPTION_NAMES, TransferOptionProperties, scene_values, transfer_settings_from


def scene_defaults(context, is_set) -> dict:
    """Operator property values taken from the scene settings (``scene.autorig``).

    Parameters
    ----------
    context : bpy.types.Context
    is_set : callable (name) -> bool
        True for properties the caller set explicitly; those are left out.

    Returns
    -------
    dict property name -> value: every transfer option, ``source`` (the
    panel's Source) and ``targets`` (``selection.selected_targets``: the
    selected meshes other than the source, plus the panel's Target), as the
    panel's Transfer button uses them.
    """
    settings = getattr(context.scene, "autorig", None)
    if settings is None:
        return {}
    values = scene_values(context, TRANSFER_OPTION_NAMES, is_set)
    if not is_set("source") and settings.source is not None:
        values["source"] = settings.source.name
    if not is_set("targets"):
        chosen = selected_targets(context.selected_objects, values.get("source", ""), settings.target)
        values["targets"] = ",".join(obj.name for obj in chosen)
    return values


class AUTORIG_OT_transfer_weights(TransferOptionProperties, bpy.types.Operator):
    """Copy skin weights from the source body onto the target meshes (garments, accessories), inpainting where they do not match"""  # noqa: E501

    bl_idname = "autorig.transfer_weights"
    bl_label = "Transfer Weights"
    bl_options = {"REGISTER", "UNDO"}

    source: StringProperty(
        name="Source",
        description="Name of the skinned mesh to take the weights from (empty: the active skinned mesh)",
        default="",
    )
    targets: StringProperty(
        name="Targets",
        description="Comma-separated names of the meshes to weight (empty: the selected meshes except the source)",
        default="",
    )
    bones: StringProperty(
        name="Bone Names",
        description="Comma-separated bone names to transfer (empty: as chosen by Bones)",
        default="",
    )

    @classmethod
    def poll(cls, context):
        return context.scene is not None and context.view_layer is not None and mode_poll(cls, context, cls.bl_label)

    def invoke(self, context, event):
        for name, value in scene_defaults(context, self.properties.is_property_set).items():
            setattr(self, name, value)
        return self._run(context, PICK_IN_PANEL)

    def execute(self, context):
        return self._run(context, PICK_IN_SCRIPT)

    def _run(self, context, how: HowToPick):
        """Transfer with the operator's properties; ``how`` words the refusals
        for the way it was started (panel button or script)."""
        try:
            source = resolve_source(context, self.source, how)
            targets = resolve_targets(context, self.targets, source, how=how)
            depsgraph = context.evaluated_depsgraph_get()
            bones = chosen_bone_names(self.bones, self.bone_subset, find_armature(source))
            with blender_progress(context, "Transfer weights") as progress:
                outcomes = run_transfer(source, targets, transfer_settings_from(self, bones), depsgraph, progress)
        except InputError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        except Cancelled:
            self.report({"WARNING"}, "Weight transfer cancelled; nothing was changed.")
            return {"CANCELLED"}
        self.report({"INFO"}, outcome_report(outcomes))
        return {"FINISHED"}


class AUTORIG_OT_create_transfer_mask(bpy.types.Operator):
    """Create the inpaint-mask vertex group on the target and start Weight Paint: painted vertices are always inpainted instead of copied"""  # noqa: E501

    bl_idname = "autorig.create_transfer_mask"
    bl_label = "Paint Inpaint Mask"
    bl_options = {"REGISTER", "UNDO"}

    group_name: StringProperty(
        name="Group",
        description="Name of the mask vertex group (empty: the scene's Inpaint Mask setting)",
        default="",
    )
    target: StringProperty(
        name="Target",
        description="Mesh to paint the mask on (empty: the panel's Target, else the active mesh)",
        default="",
    )

    @classmethod
    def poll(cls, context):
        return context.scene is not None and context.view_layer is not None

    def _target(self, context):
        if self.target:
            obj = object_named(self.target)
        else:
            settings = getattr(context.scene, "autorig", None)
            obj = (settings.target if settings is not None and settings.target is not None
                   else context.view_layer.objects.active)
        convert.require_mesh_object(obj, "mask target")
        return obj

    def _group_name(self, context) -> str:
        if self.group_name.strip():
            return self.group_name.strip()
        settings = getattr(context.scene, "autorig", None)
        name = settings.mask_group.strip() if settings is not None else ""
        if not name:
            raise InputError("No mask group name: set Inpaint Mask in the AutoRig panel.")
        return name

    def execute(self, context):
        try:
            obj = self._target(context)
            name = self._group_name(context)
            check_mode(obj, "transfer")
        except InputError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        group = obj.vertex_groups.get(name) or obj.vertex_groups.new(name=name)
        obj.vertex_groups.active_index = group.index
        for other in context.selected_objects:
            if other != obj:
                other.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
        _enter_weight_paint(obj)
        self.report({"INFO"}, f"Paint '{name}' on '{obj.name}': painted vertices "
                              f"(weight {GROUP_MEMBER_THRESHOLD:g} or more) will be inpainted.")
        return {"FINISHED"}


def _enter_weight_paint(obj) -> None:
    """Switch ``obj`` to Weight Paint mode where the context allows (not in
    some background sessions, where the mode switch is skipped)."""
    if obj.mode == "WEIGHT_PAINT":
        return
    try:
        bpy.ops.object.mode_set(mode="WEIGHT_PAINT")
    except RuntimeError:
        pass


classes = (AUTORIG_OT_transfer_weights, AUTORIG_OT_create_transfer_mask)
