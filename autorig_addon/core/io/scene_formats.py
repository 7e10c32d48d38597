"""Scene file formats the add-on reads and writes (through Blender's own
importers and exporters), declared without Blender so the command line can
name them in ``--help`` and pick files from folders before Blender loads."""

from __future__ import annotations

from pathlib import Path

#: File extensions ``blender.scene_io.load_scene`` reads.
LOADABLE_EXTENSIONS = (".blend", ".glb", ".gltf", ".fbx", ".obj")
#: File extensions ``blender.scene_io.save_scene`` writes (Blender has no OBJ armatures).
SAVABLE_EXTENSIONS = (".blend", ".glb", ".gltf", ".fbx")


def scene_files(folder: str | Path) -> list[Path]:
    """Every file Blender can load below ``folder`` (any depth), sorted by path."""
    return [path for path in sorted(Path(folder).rglob("*"))
            if path.is_file() and path.suffix.lower() in LOADABLE_EXTENSIONS]
