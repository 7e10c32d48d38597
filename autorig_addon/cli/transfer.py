"""``python -m autorig_addon transfer``: copy skin weights from a body onto garments.

The options are made from the transfer's option table
(``core.transfer.options.TRANSFER_OPTIONS``), the one the Blender panel is
made from.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..core.errors import InputError
from ..core.transfer import combine
from ..core.transfer.options import TRANSFER_OPTIONS, TransferOptions
from .arguments import add_option, add_options, options_from
from .batch import add_batch_arguments, run_batch

NAME = "transfer"
HELP = "Copy skin weights from a body onto garments (robust transfer with inpainting)"

#: Options whose command line differs from the panel: the absolute distance
#: and the write mode are given only to change the defaults.
_GIVEN_ONLY = ("max_distance", "replace_mode", "mix_factor")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_batch_arguments(parser)
    parser.add_argument("--source", required=True, help="Name of the skinned mesh to copy weights from")
    parser.add_argument(
        "--target", action="append", default=[], metavar="OBJ",
        help="Mesh to weight (repeat, or comma-separate; default: every mesh not bound to an armature)",
    )
    add_options(parser, TRANSFER_OPTIONS, leave_out=_GIVEN_ONLY)
    add_option(parser, TRANSFER_OPTIONS["max_distance"], default=None, note="overrides --distance-fraction")
    parser.add_argument("--bones", default="", help="Comma-separated bones to transfer (default: all deform bones)")
    add_option(parser, TRANSFER_OPTIONS["mix_factor"], default=None, note="implies --replace mix")
    replace = TRANSFER_OPTIONS["replace_mode"]
    add_option(parser, replace, default=None,
               note=f"default {replace.word_of_choice(replace.default)}, or {replace.word_of_choice(combine.MIX)} "
                    "with --mix")


def transfer_settings(args: argparse.Namespace):
    """The job's ``TransferSettings`` from parsed arguments (whose
    destinations are named after the options)."""
    from ..blender.jobs.transfer import TransferSettings
    from ..blender.selection import split_names

    mode = TRANSFER_OPTIONS["replace_mode"].choice_of_word(args.replace_mode) if args.replace_mode else (
        combine.MIX if args.mix_factor is not None else combine.DEFAULT_REPLACE_MODE)
    return TransferSettings(
        options=options_from(args, TransferOptions),
        mask_group=args.mask_group,
        protect_group=args.protect_group,
        bones=tuple(split_names(args.bones)) if args.bones.strip() else None,
        replace_mode=mode,
        mix_factor=combine.DEFAULT_MIX_FACTOR if args.mix_factor is None else args.mix_factor,
    )


def default_targets(source) -> list:
    """The meshes a transfer weights when none is named
    (``selection.unbound_meshes``), refusing a file where there is none."""
    from ..blender.selection import unbound_meshes

    targets = unbound_meshes(source)
    if not targets:
        raise InputError("No target given and every other mesh is already rigged: name the meshes with --target.")
    return targets


def transfer_file(args: argparse.Namespace, settings, input_path: Path, output_path: Path, progress) -> dict:
    """Load ``input_path``, transfer, save to ``output_path``; the summary's details."""
    import bpy

    from ..blender import scene_io
    from ..blender.jobs.transfer import run_transfer
    from ..blender.selection import find_object, names_in

    scene_io.load_scene(input_path)
    source = find_object(args.source, "MESH")
    names = names_in(args.target)
    targets = [find_object(name, "MESH") for name in names] if names else default_targets(source)
    outcomes = run_transfer(source, targets, settings, bpy.context.evaluated_depsgraph_get(), progress,
                            named=bool(names))
    progress(1.0, "Saving")
    scene_io.save_scene(output_path)
    return {"targets": {outcome.target.name: outcome.summary for outcome in outcomes}}


def run(args: argparse.Namespace) -> int:
    settings = transfer_settings(args)

    def process(input_path, output_path, progress):
        return transfer_file(args, settings, input_path, output_path, progress)

    return run_batch(args.inputs, args.out, args.format, process, args.summary, args.quiet)
