"""``python -m autorig_addon skin``: weight meshes to an armature.

Defaults and bounds are the core's (``core.skinning.methods``,
``core.skinning.geometric``, ``core.distances.grid``), the ones the Blender
panel offers.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys

from ..core.distances.grid import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION
from ..core.skinning import geometric as skinning
from ..core.skinning.methods import (
    DEFAULT_SKIN_METHOD, GEOMETRIC, GEOMETRIC_OPTIONS, SKIN_METHOD_DESCRIPTIONS, SKIN_METHODS, ignored_options,
)
from .arguments import add_weight_arguments, bounded
from .batch import add_batch_arguments, run_batch

NAME = "skin"
HELP = "Weight meshes to an armature by the geometric method or a trained network"
#: What the options of the geometric method alone add to their help.
GEOMETRIC_ONLY = f"--method {GEOMETRIC} only"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_batch_arguments(parser)
    parser.add_argument("--armature", default="", help="Armature to bind to (default: the only armature in the file)")
    parser.add_argument("--mesh", action="append", default=[], metavar="OBJ",
                        help="Mesh to skin (repeat, or comma-separate; default: every mesh except bone shapes)")
    methods = " ".join(f"{name}: {SKIN_METHOD_DESCRIPTIONS[name]}." for name in SKIN_METHODS)
    parser.add_argument("--method", choices=SKIN_METHODS, default=DEFAULT_SKIN_METHOD,
                        help=f"How the weights are computed (default {DEFAULT_SKIN_METHOD}). {methods}")
    parser.add_argument("--distance", choices=skinning.DISTANCES, default=skinning.DEFAULT_DISTANCE,
                        help=f"{GEOMETRIC_ONLY}. hollow: HollowDist through empty space, reaches bones outside the "
                             "body and loose parts (HeterSkinNet); geodesic: through the inside of the mesh (RigNet) "
                             f"(default {skinning.DEFAULT_DISTANCE})")
    parser.add_argument("--resolution", type=bounded(int, MIN_RESOLUTION, MAX_RESOLUTION), default=DEFAULT_RESOLUTION,
                        help=f"Voxels along the longest side, {MIN_RESOLUTION} to {MAX_RESOLUTION} "
                             f"(default {DEFAULT_RESOLUTION})")
    parser.add_argument("--falloff", type=bounded(float, skinning.MIN_FALLOFF, skinning.MAX_FALLOFF),
                        default=skinning.DEFAULT_FALLOFF,
                        help=f"{GEOMETRIC_ONLY}. Heat strength: higher gives sharper blends between bones, "
                             f"{skinning.MIN_FALLOFF:g} to {skinning.MAX_FALLOFF:g} (default {skinning.DEFAULT_FALLOFF:g})")
    add_weight_arguments(parser, skinning.DEFAULT_MAX_INFLUENCES, skinning.DEFAULT_SMOOTHING_ITERATIONS,
                         f"{GEOMETRIC_ONLY}. Extra surface smoothing passes",
                         smoothing_strength_help=f"{GEOMETRIC_ONLY}. Blend factor of one smoothing pass")
    parser.add_argument("--replace-all", action="store_true",
                        help="Remove every existing vertex group first (default: only the deform bones' groups)")


def ignored_options_note(args: argparse.Namespace) -> str:
    """The note printed when options of the geometric method alone were
    changed with a network, "" otherwise."""
    ignored = ignored_options(args.method, {name: getattr(args, name) for name in GEOMETRIC_OPTIONS})
    if not ignored:
        return ""
    flags = ", ".join("--" + name.replace("_", "-") for name in ignored)
    return f"note: --method {args.method} ignores {flags}, which only --method {GEOMETRIC} uses."


def run(args: argparse.Namespace) -> int:
    from ..blender.jobs.skin import SkinSettings, compute_skin, plan_skin, write_skin

    # The options' destinations are named after the SkinSettings fields.
    settings = SkinSettings(**{field.name: getattr(args, field.name) for field in dataclasses.fields(SkinSettings)})
    note = ignored_options_note(args)
    if note:
        print(note, file=sys.stderr)

    def process(input_path, output_path, progress):
        import bpy

        from ..blender import scene_io
        from ..blender.selection import names_in, skin_objects

        scene_io.load_scene(input_path)
        armature, meshes = skin_objects(args.armature, args.mesh)
        plan = plan_skin(armature, meshes, settings, bpy.context.evaluated_depsgraph_get(),
                         named=bool(names_in(args.mesh)))
        weights = compute_skin(plan, progress)
        write_skin(plan, weights)
        progress(1.0, "Saving")
        scene_io.save_scene(output_path)
        details = {"method": settings.method, "armature": armature.name, "meshes": [obj.name for obj in plan.meshes],
                   "bones": len(weights.bone_names), "vertices": int(weights.matrix.shape[0])}
        if plan.tail_decision.any_derived:
            details["tails"] = plan.tail_decision.note
        if plan.notes:
            details["notes"] = plan.notes
        return details

    return run_batch(args.inputs, args.out, args.format, process, args.summary, args.quiet)
