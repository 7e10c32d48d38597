"""``python -m autorig_addon rename``: give a standard biped skeleton another
bone-name preset (Rigify, Mixamo, Unreal, Unity, VRM, Godot), the vertex
groups of its meshes with it (:mod:`..blender.bone_names`)."""

from __future__ import annotations

import argparse

from ..core.skeleton.name_presets import DEFAULT_PRESET, PRESET_LABELS
from .batch import add_batch_arguments, run_batch

NAME = "rename"
HELP = "Rename a standard biped skeleton's bones to Rigify, Mixamo, Unreal, Unity, VRM or Godot names"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_batch_arguments(parser)
    parser.add_argument("--armature", default="", help="Armature to rename (default: the only armature in the file)")
    parser.add_argument("--names", choices=tuple(PRESET_LABELS), default=DEFAULT_PRESET,
                        help="The names to give: " + "; ".join(f"{preset}: {label}" for preset, label in
                                                                PRESET_LABELS.items()))


def run(args: argparse.Namespace) -> int:
    def process(input_path, output_path, progress):
        from ..blender import scene_io
        from ..blender.bone_names import rename_bones
        from ..blender.selection import file_armature

        scene_io.load_scene(input_path)
        armature = file_armature(args.armature)
        mapping = rename_bones(armature, args.names)
        progress(1.0, "Saving")
        scene_io.save_scene(output_path)
        return {"armature": armature.name, "names": args.names, "renamed": len(mapping)}

    return run_batch(args.inputs, args.out, args.format, process, args.summary, args.quiet)
