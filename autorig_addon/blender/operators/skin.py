"""The Skin Weights operator: the armature and meshes from its names or the
selection (:mod:`..selection`), the options from its properties, the work
done by :mod:`..jobs.skin`.

From the UI the computation runs in a worker thread so Blender stays
responsive, shows progress and stops on Esc; in background mode (scripts)
it runs synchronously.
"""

from __future__ import annotations

import bpy
from bpy.props import StringProperty

from ...core.errors import Cancelled, InputError
from ..jobs.input_checks import mode_poll
from ..jobs.skin import SkinJob, SkinPlan, plan_skin, run_skin, skin_report, write_skin
from ..progress import blender_progress
from ..selection import resolve_skin_inputs
from ..ui.properties import SKIN_OPTION_NAMES, SkinOptionProperties, scene_values, skin_settings_from
from .modal_job import ModalJobOperator, show_job_event

#: Prefix of the status-bar text while skinning runs.
SKIN_PROGRESS_TITLE = "Skin weights"


class AUTORIG_OT_skin_weights(ModalJobOperator, SkinOptionProperties, bpy.types.Operator):
    """Weight the selected meshes to the selected armature, by the geometric method or a trained network; Esc cancels"""

    bl_idname = "autorig.skin_weights"
    bl_label = "Skin Weights"
    bl_options = {"REGISTER", "UNDO"}

    armature: StringProperty(name="Armature", description="Armature to bind to (empty: the selected one)")
    meshes: StringProperty(name="Meshes", description="Comma-separated meshes to skin (empty: the selected ones)")

    _thread = None

    @classmethod
    def poll(cls, context):
        return mode_poll(cls, context, cls.bl_label)

    def invoke(self, context, event):
        for name, value in scene_values(context, SKIN_OPTION_NAMES, self.properties.is_property_set).items():
            setattr(self, name, value)
        if bpy.app.background or context.window_manager is None or not context.window_manager.windows:
            return self.execute(context)
        try:
            armature, meshes = resolve_skin_inputs(context, self.armature, self.meshes)
            plan = plan_skin(armature, meshes, skin_settings_from(self), context.evaluated_depsgraph_get())
        except InputError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self._job = SkinJob(plan).start()
        self._thread = self._job.thread
        self._begin_modal(context)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if not show_job_event(context, event, job, SKIN_PROGRESS_TITLE) or self._thread.is_alive():
            return {"RUNNING_MODAL"}
        self._end_modal(context)
        if isinstance(job.error, Cancelled):
            self.report({"WARNING"}, "Skinning cancelled; nothing was changed.")
            return {"CANCELLED"}
        if job.error is not None:
            message = str(job.error) if isinstance(job.error, InputError) else f"Skinning failed: {job.error!r}"
            self.report({"ERROR"}, message)
            return {"CANCELLED"}
        return self._write(job.plan, job.weights)

    def cancel(self, context):
        """Blender ends the running operator itself (a file is loaded, the
        window closes): the worker stops at its next progress report, its
        result is never written, and the timer, progress and status text go."""
        if self._job is not None:
            self._job.cancel = True
        self._end_modal(context)

    def _write(self, plan: SkinPlan, weights):
        try:
            write_skin(plan, weights)
        except InputError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, skin_report(plan, weights))
        return {"FINISHED"}

    def execute(self, context):
        try:
            armature, meshes = resolve_skin_inputs(context, self.armature, self.meshes)
            with blender_progress(context, SKIN_PROGRESS_TITLE) as progress:
                plan, weights = run_skin(armature, meshes, skin_settings_from(self), context.evaluated_depsgraph_get(),
                                         progress)
        except (InputError, Cancelled) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, skin_report(plan, weights))
        return {"FINISHED"}


classes = (AUTORIG_OT_skin_weights,)
