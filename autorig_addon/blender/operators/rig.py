"""The Predict Skeleton and Auto-Rig operators: the selected meshes
(:mod:`..selection`), the options from their properties, the steps of
:mod:`..jobs.rig` run by a worker thread (progress in the status bar, Esc
cancels) or, in background mode, on the main thread.
"""

from __future__ import annotations

import bpy

from ...core.errors import Cancelled, InputError
from ...core.rigging.options import KEEP_POOR, REPLACE_BINDING, RIGIFY
from ..jobs.input_checks import mode_poll
from ..jobs.rig import RigResult, TaskJob, plan_rig_steps, planned_rig_steps, run_steps
from ..jobs.skin import SkinSettings
from ..progress import blender_progress
from ..selection import character_name, selected_meshes
from ..ui.option_properties import option_property
from ..ui.properties import (
    RIG_OPTION_NAMES,
    SKIN_OPTION_NAMES,
    RigOptionProperties,
    SkinOptionProperties,
    rig_settings_from,
    scene_values,
    skin_settings_from,
)
from .modal_job import ModalJobOperator, show_job_event

#: Prefix of the status-bar text while a prediction runs.
RIG_PROGRESS_TITLE = "Auto-Rig"


class _RigOperator(ModalJobOperator, RigOptionProperties):
    """Shared by Predict Skeleton and Auto-Rig: the plan, the modal run of
    :func:`rig_steps` and the report. A subclass sets ``binds`` and its
    ``skin_settings``."""

    bl_options = {"REGISTER", "UNDO"}
    binds = False

    rig_keep_poor: option_property(KEEP_POOR)

    _steps = None

    @classmethod
    def poll(cls, context):
        return mode_poll(cls, context, cls.bl_label)

    def option_names(self) -> tuple:
        return RIG_OPTION_NAMES + ("rig_keep_poor",)

    def skin_settings(self) -> SkinSettings | None:
        return None

    def run_steps_of(self, context):
        """The steps of the whole run: planning (its one slow part, telling what the hands hold, a task of
        its own) then the prediction and binding."""
        meshes = selected_meshes(context)
        name = character_name(meshes, context.active_object) if meshes else ""
        plan_steps = plan_rig_steps(meshes, context.evaluated_depsgraph_get(), name, rig_settings_from(self),
                                    skin=self.skin_settings(), replace=bool(getattr(self, "rig_replace", False)),
                                    rigify=bool(getattr(self, "rig_rigify", False)), keep_poor=self.rig_keep_poor)
        return planned_rig_steps(context, plan_steps)

    def invoke(self, context, event):
        for name, value in scene_values(context, self.option_names(), self.properties.is_property_set).items():
            setattr(self, name, value)
        if bpy.app.background or context.window_manager is None or not context.window_manager.windows:
            return self.execute(context)
        # Refusals of bad input come from the first advance, before anything is built.
        self._steps = self.run_steps_of(context)
        outcome = self._advance(context, None, None)
        if outcome is not None:
            return outcome
        self._begin_modal(context)
        return {"RUNNING_MODAL"}

    def _advance(self, context, result, error):
        """Hand a task's outcome to the steps and start the next task;
        returns the operator's outcome once the steps end, else None."""
        try:
            task = self._steps.throw(error) if error is not None else self._steps.send(result)
        except StopIteration as stop:
            self._end_modal(context)
            return self._finish(context, stop.value)
        except (InputError, Cancelled) as failure:
            self._end_modal(context)
            return self._fail(failure)
        except BaseException as failure:
            self._end_modal(context)
            self.report({"ERROR"}, f"Rigging failed: {failure!r}")
            return {"CANCELLED"}
        self._job = TaskJob(task).start()
        return None

    def modal(self, context, event):
        job = self._job
        if not show_job_event(context, event, job, RIG_PROGRESS_TITLE) or job.thread.is_alive():
            return {"RUNNING_MODAL"}
        return self._advance(context, job.result, job.error) or {"RUNNING_MODAL"}

    def cancel(self, context):
        """Blender ends the operator itself (a file is loaded, the window
        closes): the worker stops at its next progress report and the steps
        are closed, which removes what they built."""
        if self._job is not None:
            self._job.cancel = True
        if self._steps is not None:
            self._steps.close()
        self._end_modal(context)

    def _fail(self, error):
        if isinstance(error, Cancelled):
            self.report({"WARNING"}, "Rigging cancelled; nothing was changed.")
        else:
            self.report({"ERROR"}, str(error))
        return {"CANCELLED"}

    def _finish(self, context, result: RigResult):
        armature = result.armature
        armature.select_set(True)
        context.view_layer.objects.active = armature
        text = f"Predicted '{armature.name}' with {len(armature.data.bones)} bones"
        if result.skin_plan is not None:
            plan = result.skin_plan
            text += f", {len(plan.meshes)} mesh(es) skinned with {plan.settings.method_label}{plan.summary}"
        notes = "".join(f"; {note}" for note in result.notes)
        self.report({"INFO"}, f"{text}{notes}.")
        return {"FINISHED"}

    def execute(self, context):
        try:
            with blender_progress(context, RIG_PROGRESS_TITLE) as progress:
                result = run_steps(self.run_steps_of(context), progress)
        except (InputError, Cancelled) as error:
            return self._fail(error)
        return self._finish(context, result)


class AUTORIG_OT_predict_skeleton(_RigOperator, bpy.types.Operator):
    """Predict a skeleton for the selected meshes (one character) and build it as a new armature; Esc cancels"""

    bl_idname = "autorig.predict_skeleton"
    bl_label = "Predict Skeleton"


class AUTORIG_OT_auto_rig(_RigOperator, SkinOptionProperties, bpy.types.Operator):
    """Predict a skeleton for the selected meshes and bind them to it with skin weights, in one step; Esc cancels"""

    bl_idname = "autorig.auto_rig"
    bl_label = "Auto-Rig"

    rig_replace: option_property(REPLACE_BINDING)
    rig_rigify: option_property(RIGIFY)

    def option_names(self) -> tuple:
        return RIG_OPTION_NAMES + SKIN_OPTION_NAMES + ("rig_replace", "rig_rigify", "rig_keep_poor")

    def skin_settings(self) -> SkinSettings:
        return skin_settings_from(self)


classes = (AUTORIG_OT_predict_skeleton, AUTORIG_OT_auto_rig)
