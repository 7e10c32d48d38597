"""Does a rigged file's skeleton fit its own mesh? (bind-pose checks)

Blender keeps no bind matrices: the armature modifier moves a vertex by
``pose @ rest^-1`` of its bones, so the rest pose *is* the bind pose and a
rest pose edited after binding leaves no trace in a ``.blend`` file. What
can go wrong is elsewhere, and :func:`check_bind_pose` measures it:

* with the armature in REST position the evaluated mesh must equal the
  undeformed mesh; active shape keys and modifiers before the Armature
  modifier make it differ (``rest_error``);
* an imported file (glTF, FBX) also has a default pose, the joints' node
  transforms. The glTF importer makes Blender's rest pose the bind pose it
  reads from the inverse bind matrices and puts the node transforms in the
  pose bones. When the two differ the file's skeleton, as stored, does not
  fit its own mesh (``pose_error``, measured on the file imported without
  animations so the pose is the node transforms, not frame 0 of a clip).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Optional, Sequence

import bpy
import numpy as np

from ..core.errors import InputError
from ..core.geometry.bounding_box import character_size
from ..core.io.glb import glb_without_animations, gltf_without_animations
from ..core.messages import listed_names
from . import scene_io
from .armature_binding import pose_position
from .characters import choose_armature

#: A character deforms to itself when no vertex moves farther than this share
#: of its size (bounding-box diagonal) between the undeformed mesh and the
#: armature-evaluated one: 1e-4 of a 2 m character is 0.2 mm, far below any
#: visible error and far above float32 round-off (about 1e-7).
BIND_POSE_TOLERANCE = 1e-4
#: A bone counts as moved away from its rest pose when its pose matrix differs
#: from the rest matrix by more than this (rotation entries, and translations
#: as a share of the character size).
POSE_MATRIX_TOLERANCE = 1e-4


@dataclass(frozen=True)
class BindPoseCheck:
    """How far a character's mesh moves when nothing should move it.

    Attributes
    ----------
    rest_error : float
        Largest distance between the armature-evaluated mesh in REST position
        and the undeformed mesh, as a share of the character size.
    pose_error : float
        The same with the skeleton in its default pose (NaN when not measured).
    reasons : tuple of str
        Why the mesh moves, as far as the scene tells.
    vertex_count : int
    """

    rest_error: float
    pose_error: float
    reasons: tuple = ()
    vertex_count: int = 0

    @property
    def error(self) -> float:
        values = [value for value in (self.rest_error, self.pose_error) if not np.isnan(value)]
        return max(values) if values else 0.0

    @property
    def deforms_to_itself(self) -> bool:
        return self.error <= BIND_POSE_TOLERANCE


def _world_vertices(obj, mesh_data) -> np.ndarray:
    matrix = np.array([list(row) for row in obj.matrix_world], dtype=np.float64)
    positions = np.empty(len(mesh_data.vertices) * 3, dtype=np.float32)
    mesh_data.vertices.foreach_get("co", positions)
    return positions.reshape(-1, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]


def _evaluated_vertices(obj) -> Optional[np.ndarray]:
    """World positions of the evaluated mesh, None when modifiers change the count."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    data = evaluated.to_mesh()
    try:
        if len(data.vertices) != len(obj.data.vertices):
            return None
        return _world_vertices(obj, data)
    finally:
        evaluated.to_mesh_clear()


@contextlib.contextmanager
def _only_modifiers_up_to_armature(mesh_objects):
    """Hide modifiers after the Armature modifier (subdivision, solidify...):
    they do not change the binding but may change the vertex count."""
    hidden = []
    for obj in mesh_objects:
        seen_armature = False
        for modifier in obj.modifiers:
            if seen_armature and modifier.show_viewport:
                modifier.show_viewport = False
                hidden.append(modifier)
            seen_armature |= modifier.type == "ARMATURE"
    try:
        yield
    finally:
        for modifier in hidden:
            modifier.show_viewport = True


def _mesh_reasons(obj) -> list:
    reasons = []
    keys = obj.data.shape_keys
    if keys is not None:
        if not keys.use_relative:
            reasons.append(f"'{obj.name}' uses absolute shape keys, which move the mesh at rest")
        active = [block.name for block in keys.key_blocks[1:] if not block.mute and abs(block.value) > 0.0]
        if active:
            reasons.append(f"'{obj.name}' has active shape keys: {listed_names(active)}")
    before = []
    for modifier in obj.modifiers:
        if modifier.type == "ARMATURE":
            break
        if modifier.show_viewport:
            before.append(f"{modifier.name} ({modifier.type.title()})")
    if before:
        reasons.append(f"'{obj.name}' has modifiers before its Armature modifier: {', '.join(before)}")
    return reasons


def _moved_bones(armature_obj, size: float) -> list:
    """Names of bones whose current pose differs from their rest pose."""
    moved = []
    for pose_bone in armature_obj.pose.bones:
        pose = np.array([list(row) for row in pose_bone.matrix])
        rest = np.array([list(row) for row in pose_bone.bone.matrix_local])
        rotation_change = np.abs(pose[:3, :3] - rest[:3, :3]).max()
        translation_change = np.abs(pose[:3, 3] - rest[:3, 3]).max() / size
        if max(rotation_change, translation_change) > POSE_MATRIX_TOLERANCE:
            moved.append(pose_bone.name)
    return moved


def _largest_distance(moved: list, undeformed: np.ndarray, size: float) -> float:
    if any(positions is None for positions in moved):
        return float("inf")
    return float(np.linalg.norm(np.concatenate(moved) - undeformed, axis=1).max(initial=0.0)) / size


def bind_pose_error(armature_obj, mesh_objects: Sequence, measure_pose: bool = True) -> BindPoseCheck:
    """Measure whether the meshes deform to themselves (see the module docstring).

    Parameters
    ----------
    armature_obj : bpy.types.Object of type 'ARMATURE'
    mesh_objects : mesh objects it deforms
    measure_pose : bool
        Also measure the current pose (the file's default pose when loaded
        with :func:`load_default_pose`); False leaves ``pose_error`` NaN.

    Returns
    -------
    BindPoseCheck; the armature's pose position is restored afterwards.
    """
    if not mesh_objects:
        raise InputError(f"The armature '{armature_obj.name}' deforms no mesh, so there is nothing to check.")
    undeformed = np.concatenate([_world_vertices(obj, obj.data) for obj in mesh_objects])
    size = character_size(undeformed)
    reasons = [reason for obj in mesh_objects for reason in _mesh_reasons(obj)]
    with _only_modifiers_up_to_armature(mesh_objects):
        with pose_position([armature_obj], "REST"):
            rest_error = _largest_distance([_evaluated_vertices(obj) for obj in mesh_objects], undeformed, size)
        pose_error = float("nan")
        if measure_pose:
            with pose_position([armature_obj], "POSE"):
                pose_error = _largest_distance([_evaluated_vertices(obj) for obj in mesh_objects], undeformed, size)
                moved = _moved_bones(armature_obj, size)
            if pose_error > BIND_POSE_TOLERANCE and moved:
                reasons.append(
                    f"the default pose differs from the rest (bind) pose in {len(moved)} bones: {listed_names(moved)}"
                )
    if np.isinf(rest_error) or np.isinf(pose_error):
        reasons.append("a modifier before the Armature modifier changes the vertex count, "
                       "so positions cannot be compared")
    return BindPoseCheck(rest_error, pose_error, tuple(reasons), len(undeformed))


def load_default_pose(path: str | os.PathLike) -> bool:
    """Load a file with its skeleton in the file's default pose.

    glTF files are imported from a copy without animations (the importer
    would otherwise pose the skeleton at frame 0 of the first clip), FBX
    files without animation. Other formats load as they are.

    Returns
    -------
    bool: whether the format has a default pose apart from the rest pose
    (glTF and FBX do, ``.blend`` files do not).
    """
    path = Path(path)
    extension = path.suffix.lower()
    if extension in (".glb", ".gltf"):
        with tempfile.TemporaryDirectory(prefix="autorig_pose_") as folder:
            copy = Path(folder) / path.name
            (glb_without_animations if extension == ".glb" else gltf_without_animations)(path, copy)
            scene_io.load_scene(copy)
        return True
    if extension == ".fbx":
        if not path.is_file():
            raise InputError(f"The file '{path}' does not exist.")
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.import_scene.fbx(filepath=str(path.resolve()), use_anim=False)
        return True
    scene_io.load_scene(path)
    return False


def check_bind_pose(path: str | os.PathLike) -> BindPoseCheck:
    """Load ``path`` in its default pose and run :func:`bind_pose_error`
    on the armature :func:`choose_armature` picks (replaces the current scene)."""
    has_default_pose = load_default_pose(path)
    armature, meshes, _ = choose_armature()
    check = bind_pose_error(armature, meshes, measure_pose=has_default_pose)
    if has_default_pose and check.pose_error > BIND_POSE_TOLERANCE and Path(path).suffix.lower() in (".glb", ".gltf"):
        hint = "the joints' node transforms differ from the bind pose of the inverse bind matrices"
        check = replace(check, reasons=check.reasons + (hint,))
    return check
