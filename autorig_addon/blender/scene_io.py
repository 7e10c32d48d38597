"""Loading and saving whole scenes for the command line and batch jobs."""

from __future__ import annotations

import os
from pathlib import Path

import bpy

from ..core.errors import InputError
from ..core.io.scene_formats import LOADABLE_EXTENSIONS, SAVABLE_EXTENSIONS


def _extension(path: str | os.PathLike) -> str:
    return Path(path).suffix.lower()


def load_scene(path: str | os.PathLike) -> None:
    """Replace the current scene with the contents of ``path``.

    ``.blend`` files are opened; ``.glb``/``.gltf``, ``.fbx`` and ``.obj``
    are imported into an empty factory-settings scene.

    Raises
    ------
    InputError for a missing file or an unsupported extension.
    """
    path = Path(path)
    extension = _extension(path)
    if extension not in LOADABLE_EXTENSIONS:
        raise InputError(f"Cannot read '{path.name}': use one of {', '.join(LOADABLE_EXTENSIONS)}.")
    if not path.is_file():
        raise InputError(f"The file '{path}' does not exist.")
    filepath = str(path.resolve())
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if extension == ".blend":
        bpy.ops.wm.open_mainfile(filepath=filepath, load_ui=False)
    elif extension in (".glb", ".gltf"):
        bpy.ops.import_scene.gltf(filepath=filepath)
    elif extension == ".fbx":
        bpy.ops.import_scene.fbx(filepath=filepath)
    else:
        bpy.ops.wm.obj_import(filepath=filepath)
    _leave_edit_modes()


def _leave_edit_modes() -> None:
    """Importers and saved files may leave an object in Edit or Pose mode."""
    active = bpy.context.view_layer.objects.active
    if active is not None and active.mode != "OBJECT":
        try:
            bpy.ops.object.mode_set(mode="OBJECT")
        except RuntimeError:
            pass


def save_scene(path: str | os.PathLike) -> None:
    """Write the current scene to ``path`` (format from the extension).

    ``.blend`` is saved as a copy (the session keeps its own file name);
    ``.glb``/``.gltf`` and ``.fbx`` are exported with armatures and skins.

    Raises
    ------
    InputError for an unsupported extension.
    """
    path = Path(path)
    extension = _extension(path)
    if extension not in SAVABLE_EXTENSIONS:
        raise InputError(f"Cannot write '{path.name}': use one of {', '.join(SAVABLE_EXTENSIONS)}.")
    path.parent.mkdir(parents=True, exist_ok=True)
    filepath = str(path.resolve())
    _leave_edit_modes()
    if extension == ".blend":
        bpy.ops.wm.save_as_mainfile(filepath=filepath, copy=True)
    elif extension in (".glb", ".gltf"):
        bpy.ops.export_scene.gltf(
            filepath=filepath,
            export_format="GLB" if extension == ".glb" else "GLTF_SEPARATE",
            export_skins=True,
            export_apply=False,
        )
    else:
        bpy.ops.export_scene.fbx(filepath=filepath, add_leaf_bones=False, use_armature_deform_only=False)
