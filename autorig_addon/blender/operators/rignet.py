"""Import and export of RigNet's plain-text rig files (File > Import / Export).

Import builds an armature from the file and, when a mesh with the file's
vertex count is active, binds it with the file's skin weights. Export writes
the deform bones of an armature and the weights of a mesh bound to it
(:mod:`..jobs.rignet`).
"""

from __future__ import annotations

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ...core.errors import InputError
from .. import convert
from ..armature_binding import find_armature
from ..jobs.rignet import export_rignet_rig, import_rignet_rig, unweighted_vertex_count
from ..object_roles import shared_mesh_notes


def _active_mesh(context):
    obj = context.active_object
    return obj if obj is not None and obj.type == "MESH" else None


class AUTORIG_OT_import_rignet(bpy.types.Operator, ImportHelper):
    """Import a RigNet rig file (joints, hierarchy, skin weights) as an armature; the active mesh is bound if its vertex count matches"""  # noqa: E501

    bl_idname = "autorig.import_rignet"
    bl_label = "Import RigNet Rig"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".txt"
    filter_glob: StringProperty(default="*.txt", options={"HIDDEN"})

    def execute(self, context):
        mesh_obj = _active_mesh(context)
        shared = shared_mesh_notes([mesh_obj]).get(mesh_obj) if mesh_obj is not None else None
        try:
            armature, notes = import_rignet_rig(context, self.filepath, mesh_obj)
        except (InputError, OSError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        bound = ""
        if mesh_obj is not None and mesh_obj.parent == armature:
            unweighted = unweighted_vertex_count(convert.read_weights(mesh_obj, armature.data.bones.keys()))
            stays = (f" ({unweighted} of its vertices have no weight in the file and stay in place when posed)"
                     if unweighted else "")
            bound = f", '{mesh_obj.name}' bound{stays}" + (f"; it {shared}" if shared else "")
        bound += "".join(f"; {note}" for note in notes)
        self.report({"INFO"}, f"Imported '{armature.name}' with {len(armature.data.bones)} bones{bound}.")
        return {"FINISHED"}


class AUTORIG_OT_export_rignet(bpy.types.Operator, ExportHelper):
    """Export the active armature's deform bones, and the weights of the selected mesh bound to it, as a RigNet rig file"""  # noqa: E501

    bl_idname = "autorig.export_rignet"
    bl_label = "Export RigNet Rig"
    bl_options = {"REGISTER"}

    filename_ext = ".txt"
    filter_glob: StringProperty(default="*.txt", options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type in {"ARMATURE", "MESH"}

    def execute(self, context):
        try:
            mesh_obj = _active_mesh(context)
            armature = find_armature(mesh_obj) if mesh_obj is not None else context.active_object
            export_rignet_rig(self.filepath, armature, mesh_obj)
        except (InputError, OSError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Exported '{armature.name}' to {self.filepath}.")
        return {"FINISHED"}


def _menu_import(self, _context):
    self.layout.operator(AUTORIG_OT_import_rignet.bl_idname, text="RigNet Rig (.txt)")


def _menu_export(self, _context):
    self.layout.operator(AUTORIG_OT_export_rignet.bl_idname, text="RigNet Rig (.txt)")


classes = (AUTORIG_OT_import_rignet, AUTORIG_OT_export_rignet)


def register_extras() -> None:
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)


def unregister_extras() -> None:
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
