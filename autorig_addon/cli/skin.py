"""``python -m autorig_addon skin``: weight meshes to an armature.

The options are made from the skinning option table
(``core.skinning.options.SKINNING_OPTIONS``), the one the Blender panel is
made from.
"""

from __future__ import annotations

import argparse
import sys

from ..core.skinning.methods import GEOMETRIC, GEOMETRIC_OPTIONS
from ..core.skinning.options import SKINNING_OPTIONS, SkinningOptions, ignored_options
from .arguments import add_options, options_from
from .batch import add_batch_arguments, run_batch

NAME = "skin"
HELP = "Weight meshes to an armature by the geometric method or a trained network"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_batch_arguments(parser)
    parser.add_argument("--armature", default="", help="Armature to bind to (default: the only armature in the file)")
    parser.add_argument("--mesh", action="append", default=[], metavar="OBJ",
                        help="Mesh to skin (repeat, or comma-separate; default: every mesh except bone shapes)")
    add_options(parser, SKINNING_OPTIONS)


def ignored_options_note(args: argparse.Namespace) -> str:
    """The note printed when options of the geometric method alone were
    changed with a network, "" otherwise."""
    geometric_only = {name: getattr(args, name) for name in GEOMETRIC_OPTIONS}
    ignored = ignored_options(SkinningOptions(method=args.method, **geometric_only))
    if not ignored:
        return ""
    flags = ", ".join(SKINNING_OPTIONS[name].command_flag for name in ignored)
    return f"note: --method {args.method} ignores {flags}, which only --method {GEOMETRIC} uses."


def run(args: argparse.Namespace) -> int:
    from ..blender.jobs.skin import SkinSettings, run_skin

    settings = SkinSettings(options_from(args, SkinningOptions), replace_all=args.replace_all)
    note = ignored_options_note(args)
    if note:
        print(note, file=sys.stderr)

    def process(input_path, output_path, progress):
        import bpy

        from ..blender import scene_io
        from ..blender.selection import names_in, skin_objects

        scene_io.load_scene(input_path)
        armature, meshes = skin_objects(args.armature, args.mesh)
        plan, weights = run_skin(armature, meshes, settings, bpy.context.evaluated_depsgraph_get(), progress,
                                 named=bool(names_in(args.mesh)))
        progress(1.0, "Saving")
        scene_io.save_scene(output_path)
        details = {"method": settings.options.method, "armature": armature.name,
                   "meshes": [obj.name for obj in plan.meshes], "bones": len(weights.bone_names),
                   "vertices": int(weights.matrix.shape[0])}
        if plan.tail_decision.any_derived:
            details["tails"] = plan.tail_decision.note
        if plan.notes:
            details["notes"] = plan.notes
        return details

    return run_batch(args.inputs, args.out, args.format, process, args.summary, args.quiet)
