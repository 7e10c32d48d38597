"""``python -m autorig_addon transfer``: copy skin weights from a body onto garments.

Defaults and bounds are the core's (``core.transfer.options``,
``core.transfer.combine``), the ones the Blender panel offers.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from ..core.errors import InputError
from ..core.transfer import combine
from ..core.transfer import options as defaults
from ..core.transfer.options import TransferOptions
from .arguments import add_weight_arguments, bounded, fraction, positive
from .batch import add_batch_arguments, run_batch

NAME = "transfer"
HELP = "Copy skin weights from a body onto garments (robust transfer with inpainting)"

#: ``--replace`` choices -> write modes of ``core.transfer.combine``.
REPLACE_CHOICES = {"transfer": combine.REPLACE, "mix": combine.MIX, "all": combine.REPLACE_ALL}
#: The ``--replace`` choice meaning the core's default write mode.
DEFAULT_REPLACE_CHOICE = next(word for word, mode in REPLACE_CHOICES.items() if mode == combine.DEFAULT_REPLACE_MODE)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_batch_arguments(parser)
    parser.add_argument("--source", required=True, help="Name of the skinned mesh to copy weights from")
    parser.add_argument(
        "--target", action="append", default=[], metavar="OBJ",
        help="Mesh to weight (repeat, or comma-separate; default: every mesh not bound to an armature)",
    )
    parser.add_argument(
        "--distance-fraction", type=bounded(float, defaults.MIN_DISTANCE_FRACTION, defaults.MAX_DISTANCE_FRACTION),
        default=defaults.DEFAULT_DISTANCE_FRACTION,
        help="Match distance as a fraction of the target's bounding-box diagonal, "
             f"{defaults.MIN_DISTANCE_FRACTION:g} to {defaults.MAX_DISTANCE_FRACTION:g} "
             f"(default {defaults.DEFAULT_DISTANCE_FRACTION:g})",
    )
    parser.add_argument("--max-distance", type=positive, default=None,
                        help="Match distance in scene units; overrides --distance-fraction")
    parser.add_argument(
        "--max-normal-angle", type=bounded(float, defaults.MIN_MAX_NORMAL_ANGLE, defaults.MAX_MAX_NORMAL_ANGLE),
        default=defaults.DEFAULT_MAX_NORMAL_ANGLE,
        help=f"Largest normal disagreement for a match, degrees, {defaults.MIN_MAX_NORMAL_ANGLE:g} to "
             f"{defaults.MAX_MAX_NORMAL_ANGLE:g} (default {defaults.DEFAULT_MAX_NORMAL_ANGLE:g})",
    )
    parser.add_argument("--flipped-normals", action=argparse.BooleanOptionalAction, dest="accept_flipped_normals",
                        default=defaults.DEFAULT_ACCEPT_FLIPPED_NORMALS,
                        help="Also match opposite normals, for inner layers "
                             f"(default {'on' if defaults.DEFAULT_ACCEPT_FLIPPED_NORMALS else 'off'})")
    parser.add_argument(
        "--smoothing-length",
        type=bounded(float, defaults.MIN_SMOOTHING_LENGTH, defaults.MAX_SMOOTHING_LENGTH),
        default=defaults.DEFAULT_SMOOTHING_LENGTH,
        help="Reach of the smoothing of all transferred weights, as a fraction of the source's bounding-box "
             f"diagonal, {defaults.MIN_SMOOTHING_LENGTH:g} (off) to {defaults.MAX_SMOOTHING_LENGTH:g} "
             f"(default {defaults.DEFAULT_SMOOTHING_LENGTH:g}: 1 cm on a 2 m body)",
    )
    add_weight_arguments(parser, defaults.DEFAULT_MAX_INFLUENCES, defaults.DEFAULT_SMOOTHING_ITERATIONS,
                         "Smoothing passes over inpainted vertices", "; 4 for most game engines")
    parser.add_argument("--mask-group", default=defaults.DEFAULT_MASK_GROUP,
                        help=f"Target vertex group forcing inpainting (default '{defaults.DEFAULT_MASK_GROUP}')")
    parser.add_argument("--protect-group", default="", help="Target vertex group that keeps its weights")
    parser.add_argument("--bones", default="", help="Comma-separated bones to transfer (default: all deform bones)")
    parser.add_argument("--mix", type=fraction, default=None,
                        help="Share of the transferred weights when mixing, 0 to 1 (implies --replace mix)")
    parser.add_argument("--allow-poor-match", action="store_true", default=defaults.DEFAULT_ALLOW_POOR_MATCH,
                        help="Transfer even when almost nothing matches, another unit scale fits much better, or "
                             "matches are far from the body, instead of refusing (default off)")
    parser.add_argument("--replace", choices=tuple(REPLACE_CHOICES), default=None,
                        help="transfer: refill the transferred bones' groups; mix: blend with existing weights; "
                             f"all: remove every group first (default {DEFAULT_REPLACE_CHOICE}, or mix with --mix)")


def transfer_settings(args: argparse.Namespace):
    """The operator's ``TransferSettings`` from parsed arguments (whose
    destinations are named after the ``TransferOptions`` fields)."""
    from ..blender.jobs.transfer import TransferSettings
    from ..blender.selection import split_names

    replace = args.replace or ("mix" if args.mix is not None else DEFAULT_REPLACE_CHOICE)
    options = TransferOptions(**{field.name: getattr(args, field.name) for field in dataclasses.fields(TransferOptions)})
    return TransferSettings(
        options=options,
        mask_group=args.mask_group,
        protect_group=args.protect_group,
        bones=tuple(split_names(args.bones)) if args.bones.strip() else None,
        replace_mode=REPLACE_CHOICES[replace],
        mix_factor=combine.DEFAULT_MIX_FACTOR if args.mix is None else args.mix,
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
