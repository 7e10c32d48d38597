"""Skin weights for meshes and any armature, from voxel distances.

As with transfer, nothing is written before everything is computed:

1. :func:`plan_skin` checks the armature and meshes and reads them once,
2. :func:`compute_skin` runs the core method (no ``bpy``: safe in a thread),
3. :func:`write_skin` writes every mesh, restoring all of them if any
   write fails.

From the UI the operator runs step 2 in a worker thread so Blender stays
responsive, shows progress and stops on Esc; in background mode (scripts,
the command line) it runs synchronously.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import bpy
import numpy as np
from bpy.props import StringProperty

from ...core.skinning import geometric as skinning
from ...core.errors import Cancelled, InputError
from ...core.progress import ProgressCallback
from ...core.types import Mesh, Skeleton, Weights
from ...core.distances.voxelize import DEFAULT_RESOLUTION
from .. import convert
from ..progress import blender_progress
from ..scene_io import find_object
from ..ui.properties import SKIN_OPTION_NAMES, SkinOptionProperties

#: When even the deform bone point nearest the mesh's bounding box is
#: farther than this many mesh diagonals from it, the armature was not
#: placed on the character.
MAX_ARMATURE_OFFSET = 0.5
#: Deform bones shorter than this fraction of the skeleton's size count as zero-length
#: (they have no direction to measure distances along).
MIN_BONE_LENGTH_FRACTION = 1e-4
#: Seconds between progress refreshes of the running modal operator.
MODAL_TIMER_SECONDS = 0.1


@dataclass(frozen=True)
class SkinSettings:
    """Options of a skinning run (see ``core.geometric_skinning.geometric_weights``).

    Attributes
    ----------
    distance : "geodesic" (volumetric geodesic, RigNet) or "hollow" (HollowDist, HeterSkinNet)
    resolution : int, voxels along the longest side
    falloff : float, heat strength (higher: sharper blends)
    max_influences : int, bones per vertex (0 = no limit)
    smoothing_iterations : int
    smoothing_strength : float in [0, 1]
    replace_all : bool, remove every existing vertex group first
    """

    distance: str = skinning.DEFAULT_METHOD
    resolution: int = DEFAULT_RESOLUTION
    falloff: float = skinning.DEFAULT_FALLOFF
    max_influences: int = skinning.DEFAULT_MAX_INFLUENCES
    smoothing_iterations: int = skinning.DEFAULT_SMOOTHING_ITERATIONS
    smoothing_strength: float = skinning.DEFAULT_SMOOTHING_STRENGTH
    replace_all: bool = False


@dataclass
class SkinPlan:
    """Checked inputs: the armature, the meshes and their arrays."""

    armature: object
    meshes: list
    mesh: Mesh
    skeleton: Skeleton
    settings: SkinSettings


def _check_in_object_mode(obj) -> None:
    if obj.mode != "OBJECT":
        raise InputError(f"'{obj.name}' is in {obj.mode.replace('_', ' ').title()} Mode: leave it first.")


def _check_skeleton_fits_mesh(skeleton: Skeleton, mesh: Mesh, armature_name: str) -> None:
    size = mesh.bounding_box_diagonal
    lo, hi = mesh.vertices.min(0), mesh.vertices.max(0)
    points = np.vstack([skeleton.joints, skeleton.tails])
    outside = np.maximum(lo - points, 0) + np.maximum(points - hi, 0)
    if np.linalg.norm(outside, axis=1).min() > MAX_ARMATURE_OFFSET * size:
        raise InputError(
            f"The armature '{armature_name}' lies far from the mesh: move it onto the character "
            "(or apply the object transforms) before skinning."
        )


def plan_skin(armature, meshes: list, settings: SkinSettings, depsgraph) -> SkinPlan:
    """Read and check the inputs; raises :class:`InputError` on bad input."""
    convert.require_armature_object(armature)
    if not meshes:
        raise InputError("Select the mesh(es) to skin together with the armature.")
    for obj in [armature, *meshes]:
        _check_in_object_mode(obj)
    for obj in meshes:
        convert.require_mesh_object(obj, "mesh to skin")
    skeleton = convert.read_skeleton(armature)
    if not skeleton.deform.any():
        raise InputError(f"The armature '{armature.name}' has no deform bones: enable Deform on the bones to weight.")
    deform = skeleton.deform_subset()
    size = max(np.ptp(np.vstack([deform.joints, deform.tails]), axis=0).max(), 1e-12)
    short = [name for name, length in zip(deform.names, deform.bone_lengths) if length < MIN_BONE_LENGTH_FRACTION * size]
    if short:
        raise InputError(f"Deform bone(s) with zero length: {', '.join(short[:5])}. Give them a length first.")
    mesh = convert.read_mesh(meshes, depsgraph)
    if not np.all(np.isfinite(mesh.vertices)):
        raise InputError("A mesh has NaN or infinite vertex positions.")
    if mesh.bounding_box_diagonal <= 0:
        raise InputError("The mesh has zero size.")
    _check_skeleton_fits_mesh(deform, mesh, armature.name)
    return SkinPlan(armature, list(meshes), mesh, skeleton, settings)


def compute_skin(plan: SkinPlan, progress: ProgressCallback | None = None) -> Weights:
    """(n, deform bones) weights for every vertex of every mesh; no ``bpy``."""
    s = plan.settings
    return skinning.geometric_weights(
        plan.mesh, plan.skeleton, method=s.distance, resolution=int(s.resolution), falloff=float(s.falloff),
        max_influences=int(s.max_influences), smoothing_iterations=int(s.smoothing_iterations),
        smoothing_strength=float(s.smoothing_strength), progress=progress,
    )


def write_skin(plan: SkinPlan, weights: Weights) -> None:
    """Write each mesh's rows; on any failure every mesh is restored."""
    snapshots = [convert.ObjectSnapshot.capture(obj) for obj in plan.meshes]
    try:
        for index, obj in enumerate(plan.meshes):
            rows = plan.mesh.object_slice(index)
            convert.write_weights(obj, Weights(weights.matrix[rows], weights.bone_names), plan.armature,
                                  replace_all=plan.settings.replace_all)
    except BaseException:
        for snapshot in snapshots:
            snapshot.restore()
        raise


def run_skin(armature, meshes: list, settings: SkinSettings, depsgraph, progress: ProgressCallback | None = None) -> Weights:
    """Plan, compute and write in one call (scripts and the command line)."""
    plan = plan_skin(armature, meshes, settings, depsgraph)
    weights = compute_skin(plan, progress)
    write_skin(plan, weights)
    return weights


def resolve_skin_inputs(context, armature_name: str = "", mesh_names: str = ""):
    """The armature and meshes to skin: named ones, else the selection
    (the active or selected armature and the selected meshes)."""
    from .transfer import split_names

    if armature_name:
        armature = find_object(armature_name, "ARMATURE")
    else:
        armatures = [obj for obj in context.selected_objects if obj.type == "ARMATURE"]
        active = context.active_object
        if active is not None and active.type == "ARMATURE":
            armature = active
        elif len(armatures) == 1:
            armature = armatures[0]
        else:
            raise InputError("Select one armature (and the meshes to skin), or name it.")
    if mesh_names.strip():
        meshes = [find_object(name, "MESH") for name in split_names(mesh_names)]
    else:
        meshes = [obj for obj in context.selected_objects if obj.type == "MESH"]
    return armature, meshes


def _settings_from(props) -> SkinSettings:
    """SkinSettings from the ``skin_*`` properties of the operator or scene settings."""
    values = {name[len("skin_"):]: getattr(props, name) for name in SKIN_OPTION_NAMES}
    values["distance"] = values["distance"].lower()
    return SkinSettings(**values)


class AUTORIG_OT_skin_weights(SkinOptionProperties, bpy.types.Operator):
    """Weight the selected meshes to the selected armature from distances through the shape; Esc cancels"""

    bl_idname = "autorig.skin_weights"
    bl_label = "Skin Weights"
    bl_options = {"REGISTER", "UNDO"}

    armature: StringProperty(name="Armature", description="Armature to bind to (empty: the selected one)")
    meshes: StringProperty(name="Meshes", description="Comma-separated meshes to skin (empty: the selected ones)")

    _thread = None
    _timer = None

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def invoke(self, context, event):
        settings = context.scene.autorig
        for name in SKIN_OPTION_NAMES:
            if not self.properties.is_property_set(name):
                setattr(self, name, getattr(settings, name))
        if bpy.app.background or context.window_manager is None or not context.window_manager.windows:
            return self.execute(context)
        try:
            armature, meshes = resolve_skin_inputs(context, self.armature, self.meshes)
            self._plan = plan_skin(armature, meshes, _settings_from(self), context.evaluated_depsgraph_get())
        except InputError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self._state = {"fraction": 0.0, "message": "Starting", "result": None, "error": None, "cancel": False}
        self._thread = threading.Thread(target=self._work, daemon=True)
        self._thread.start()
        window_manager = context.window_manager
        self._timer = window_manager.event_timer_add(MODAL_TIMER_SECONDS, window=context.window)
        window_manager.progress_begin(0, 1000)
        window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _work(self) -> None:
        state = self._state

        def progress(fraction: float, message: str) -> None:
            if state["cancel"]:
                raise Cancelled("Skinning cancelled.")
            state["fraction"], state["message"] = fraction, message

        try:
            state["result"] = compute_skin(self._plan, progress)
        except BaseException as error:  # reported from the main thread
            state["error"] = error

    def modal(self, context, event):
        if event.type == "ESC":
            self._state["cancel"] = True
        if event.type != "TIMER":
            return {"RUNNING_MODAL"}
        context.window_manager.progress_update(int(1000 * self._state["fraction"]))
        if context.workspace is not None:
            context.workspace.status_text_set(
                f"Skin weights: {self._state['message']} ({100 * self._state['fraction']:.0f}%), Esc to cancel")
        if self._thread.is_alive():
            return {"RUNNING_MODAL"}
        self._finish_modal(context)
        error = self._state["error"]
        if isinstance(error, Cancelled):
            self.report({"WARNING"}, "Skinning cancelled; nothing was changed.")
            return {"CANCELLED"}
        if error is not None:
            self.report({"ERROR"}, str(error) if isinstance(error, InputError) else f"Skinning failed: {error!r}")
            return {"CANCELLED"}
        return self._write(self._plan, self._state["result"])

    def _finish_modal(self, context) -> None:
        context.window_manager.event_timer_remove(self._timer)
        context.window_manager.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)

    def _write(self, plan: SkinPlan, weights: Weights):
        try:
            write_skin(plan, weights)
        except InputError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Skinned {len(plan.meshes)} mesh(es) to {weights.matrix.shape[1]} deform bones of "
                              f"'{plan.armature.name}'.")
        return {"FINISHED"}

    def execute(self, context):
        try:
            armature, meshes = resolve_skin_inputs(context, self.armature, self.meshes)
            plan = plan_skin(armature, meshes, _settings_from(self), context.evaluated_depsgraph_get())
            with blender_progress(context, "Skin weights") as progress:
                weights = compute_skin(plan, progress)
        except (InputError, Cancelled) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        return self._write(plan, weights)


classes = (AUTORIG_OT_skin_weights,)
