"""Command line: ``python -m autorig_addon SUBCOMMAND ...``.

Works with ``bpy`` installed as a module and inside Blender::

    blender --background --python-expr "import sys; sys.path.insert(0, 'REPO'); \\
        from autorig_addon.cli import main; sys.exit(main(['transfer', ...]))"

Subcommands live in :data:`SUBCOMMANDS` (name -> :class:`Subcommand`);
a feature adds its own with :func:`register_subcommand`. File-processing
subcommands use :func:`run_batch`: one input or many (files or folders),
a text progress bar on stderr, and a JSON summary on stdout.

Exit codes: 0 every input succeeded, 1 some failed, 2 usage error.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_USAGE = 2

#: Extensions batch jobs pick up from a folder (what ``scene_io.load_scene`` reads).
INPUT_EXTENSIONS = (".blend", ".glb", ".gltf", ".fbx", ".obj")
#: Output formats of batch jobs, as ``--format`` choices.
OUTPUT_FORMATS = ("blend", "glb", "gltf", "fbx")
#: Width of the text progress bar, characters.
PROGRESS_BAR_WIDTH = 30
#: Least change of the progress fraction worth redrawing the bar.
PROGRESS_REDRAW_STEP = 0.01
#: Same as ``blender.properties.DEFAULT_MASK_GROUP`` (kept here so --help needs no Blender).
DEFAULT_MASK_GROUP = "AutoRig Inpaint"

#: ``--replace`` choices -> write modes of ``blender.operators_transfer``.
REPLACE_CHOICES = {"transfer": "REPLACE", "mix": "MIX", "all": "REPLACE_ALL"}


class UsageError(Exception):
    """The command line itself is wrong (exit code 2)."""


@dataclass(frozen=True)
class Subcommand:
    """One subcommand: ``add_arguments(parser)`` declares its options,
    ``run(args) -> exit code`` does the work."""

    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


SUBCOMMANDS: dict[str, Subcommand] = {}


def register_subcommand(name: str, help: str, add_arguments, run) -> None:
    SUBCOMMANDS[name] = Subcommand(help, add_arguments, run)


# --------------------------------------------------------------------------- batch machinery


class _NullStream:
    def write(self, _text: str) -> None:
        pass

    def flush(self) -> None:
        pass


class TextProgress:
    """A one-line progress bar on a text stream (stderr by default)."""

    def __init__(self, total: int, stream=None):
        self.total = max(total, 1)
        self.stream = stream if stream is not None else sys.stderr
        self._last = (-1.0, "")

    def update(self, index: int, name: str, fraction: float, message: str) -> None:
        overall = (index + min(max(fraction, 0.0), 1.0)) / self.total
        if abs(overall - self._last[0]) < PROGRESS_REDRAW_STEP and message == self._last[1]:
            return
        self._last = (overall, message)
        filled = int(round(overall * PROGRESS_BAR_WIDTH))
        bar = "#" * filled + "-" * (PROGRESS_BAR_WIDTH - filled)
        self.stream.write(f"\r[{bar}] {100 * overall:3.0f}% {index + 1}/{self.total} {name}: {message}\x1b[K")
        self.stream.flush()

    def finish_item(self, index: int, name: str, outcome: str) -> None:
        self._last = (-1.0, "")
        self.stream.write(f"\r{index + 1}/{self.total} {name}: {outcome}\x1b[K\n")
        self.stream.flush()


@contextlib.contextmanager
def stdout_to_stderr():
    """Send everything written to stdout, by Python (``sys.stdout``, which
    Blender's operator reports use) or C (file descriptor 1), to stderr, so
    stdout carries only the JSON summary."""
    sys.stdout.flush()
    with contextlib.redirect_stdout(sys.stderr):
        try:
            saved = os.dup(1)
        except OSError:
            yield
            return
        try:
            os.dup2(2, 1)
            yield
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)


def expand_inputs(inputs: list[str]) -> tuple[list[tuple[Path, Path]], bool]:
    """Input files and the path of each relative to its output folder.

    A folder contributes every file with an :data:`INPUT_EXTENSIONS`
    extension below it (sorted), keeping the sub-folders in the relative
    path. Returns ``(items, is_batch)``; a batch is several inputs or any
    folder. Missing files are kept: they fail alone in the batch.
    """
    items = []
    is_batch = len(inputs) > 1
    for text in inputs:
        path = Path(text)
        if path.is_dir():
            is_batch = True
            for found in sorted(path.rglob("*")):
                if found.is_file() and found.suffix.lower() in INPUT_EXTENSIONS:
                    items.append((found, found.relative_to(path)))
        else:
            items.append((path, Path(path.name)))
    if not items:
        raise UsageError(f"No input files found in {', '.join(inputs)} (looked for {', '.join(INPUT_EXTENSIONS)}).")
    return items, is_batch


def output_paths(items: list[tuple[Path, Path]], out: str, is_batch: bool, output_format: str) -> list[Path]:
    """Where each input's result goes.

    Batch: ``out`` is a folder and each output is named after its input
    (same sub-folder, extension from ``output_format``, ``_2``... on
    clashes). Single input: ``out`` is the file, or a folder when it exists
    as one or has no extension.
    """
    out_path = Path(out)
    if not is_batch and out_path.suffix and not out_path.is_dir():
        return [out_path]
    taken, paths = set(), []
    for _, relative in items:
        candidate = out_path / relative.with_suffix("." + output_format)
        stem, counter = candidate.with_suffix(""), 2
        while candidate in taken:
            candidate = Path(f"{stem}_{counter}.{output_format}")
            counter += 1
        taken.add(candidate)
        paths.append(candidate)
    return paths


def run_batch(inputs: list[str], out: str, output_format: str, process: Callable, summary_file: str | None, quiet: bool = False) -> int:
    """Run ``process(input_path, output_path, progress) -> dict`` on every input.

    One failing input is recorded and the batch goes on. The summary
    ``{"succeeded": [{"input", "output", ...}], "failed": [{"input", "error"}]}``
    is printed to stdout as JSON and written to ``summary_file`` if given.
    """
    items, is_batch = expand_inputs(inputs)
    outputs = output_paths(items, out, is_batch, output_format)
    bar = TextProgress(len(items), _NullStream() if quiet else None)
    summary = {"succeeded": [], "failed": []}
    for index, ((input_path, _), output_path) in enumerate(zip(items, outputs)):
        name = input_path.name
        started = time.perf_counter()

        def progress(fraction: float, message: str, index=index, name=name) -> None:
            bar.update(index, name, fraction, message)

        try:
            with stdout_to_stderr():
                details = process(input_path, output_path, progress) or {}
        except Exception as error:  # noqa: BLE001 - one bad file must not stop the batch
            message = str(error) or type(error).__name__
            summary["failed"].append({"input": str(input_path), "error": message})
            bar.finish_item(index, name, f"FAILED: {message}")
            continue
        seconds = round(time.perf_counter() - started, 3)
        summary["succeeded"].append({"input": str(input_path), "output": str(output_path), "seconds": seconds, **details})
        bar.finish_item(index, name, f"ok -> {output_path}")
    text = json.dumps(summary, indent=2)
    if summary_file:
        Path(summary_file).parent.mkdir(parents=True, exist_ok=True)
        Path(summary_file).write_text(text + "\n", encoding="utf-8")
    sys.stdout.write(text + "\n")
    sys.stdout.flush()
    return EXIT_FAILED if summary["failed"] else EXIT_OK


def add_batch_arguments(parser: argparse.ArgumentParser) -> None:
    """INPUT..., --out, --format, --summary, --quiet: shared by file-processing subcommands."""
    parser.add_argument("inputs", nargs="+", metavar="INPUT", help="Scene files (.blend .glb .gltf .fbx .obj) or folders of them")
    parser.add_argument("--out", required=True, help="Output file, or folder when several inputs or a folder are given")
    parser.add_argument("--format", choices=OUTPUT_FORMATS, default="blend", help="Output format in batch mode (default: blend)")
    parser.add_argument("--summary", metavar="FILE", help="Also write the JSON summary to FILE")
    parser.add_argument("--quiet", action="store_true", help="No progress bar")


# --------------------------------------------------------------------------- transfer


def _fraction(text: str) -> float:
    value = float(text)
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"{text} is not between 0 and 1")
    return value


def _positive(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} is not positive")
    return value


def _resolution(text: str) -> int:
    from .core.distances.voxelize import MAX_RESOLUTION, MIN_RESOLUTION

    value = int(text)
    if not MIN_RESOLUTION <= value <= MAX_RESOLUTION:
        raise argparse.ArgumentTypeError(f"{text} is outside {MIN_RESOLUTION} to {MAX_RESOLUTION}")
    return value


def _non_negative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text} is negative")
    return value


def _add_transfer_arguments(parser: argparse.ArgumentParser) -> None:
    add_batch_arguments(parser)
    parser.add_argument("--source", required=True, help="Name of the skinned mesh to copy weights from")
    parser.add_argument(
        "--target", action="append", default=[], metavar="OBJ",
        help="Mesh to weight (repeat, or comma-separate; default: every mesh not bound to an armature)",
    )
    from .core.transfer import transfer

    parser.add_argument("--distance-fraction", type=_positive, default=transfer.DEFAULT_DISTANCE_FRACTION,
                        help="Match distance as a fraction of the target's bounding-box diagonal "
                             f"(default {transfer.DEFAULT_DISTANCE_FRACTION})")
    parser.add_argument("--max-distance", type=_positive, default=None,
                        help="Match distance in scene units; overrides --distance-fraction")
    parser.add_argument("--max-normal-angle", type=_positive, default=transfer.DEFAULT_MAX_NORMAL_ANGLE,
                        help="Largest normal disagreement for a match, degrees (default 30)")
    parser.add_argument("--flipped-normals", action=argparse.BooleanOptionalAction, default=True,
                        help="Also match opposite normals, for inner layers (default on)")
    parser.add_argument("--smoothing-iterations", type=_non_negative_int, default=0,
                        help="Smoothing passes over inpainted vertices (default 0)")
    parser.add_argument("--smoothing-strength", type=_fraction, default=0.5,
                        help="Blend factor of one smoothing pass, 0 to 1 (default 0.5)")
    parser.add_argument("--max-influences", type=_non_negative_int, default=0,
                        help="Bones per vertex to keep, 0 = no limit (4 for most game engines)")
    parser.add_argument("--mask-group", default=DEFAULT_MASK_GROUP,
                        help=f"Target vertex group forcing inpainting (default '{DEFAULT_MASK_GROUP}')")
    parser.add_argument("--protect-group", default="", help="Target vertex group that keeps its weights")
    parser.add_argument("--bones", default="", help="Comma-separated bones to transfer (default: all deform bones)")
    parser.add_argument("--mix", type=_fraction, default=None,
                        help="Share of the transferred weights when mixing, 0 to 1 (implies --replace mix)")
    parser.add_argument("--replace", choices=tuple(REPLACE_CHOICES), default=None,
                        help="transfer: refill the transferred bones' groups (default); "
                             "mix: blend with existing weights; all: remove every group first")


def _transfer_settings(args: argparse.Namespace):
    from .blender.operators.transfer import TransferSettings, split_names

    replace = args.replace or ("mix" if args.mix is not None else "transfer")
    bones = tuple(split_names(args.bones)) if args.bones.strip() else None
    return TransferSettings(
        distance_fraction=args.distance_fraction,
        max_distance=args.max_distance,
        max_normal_angle=args.max_normal_angle,
        accept_flipped_normals=args.flipped_normals,
        smoothing_iterations=args.smoothing_iterations,
        smoothing_strength=args.smoothing_strength,
        max_influences=args.max_influences,
        mask_group=args.mask_group,
        protect_group=args.protect_group,
        bones=bones,
        replace_mode=REPLACE_CHOICES[replace],
        mix_factor=1.0 if args.mix is None else args.mix,
    )


def _default_targets(source) -> list:
    """Every mesh other than ``source`` not yet bound to an armature."""
    import bpy

    from .blender.convert import find_armature
    from .core.errors import InputError

    targets = []
    for obj in bpy.data.objects:
        if obj.type != "MESH" or obj == source:
            continue
        try:
            find_armature(obj)
        except InputError:
            targets.append(obj)
    if not targets:
        raise InputError("No target given and every other mesh is already rigged: name the meshes with --target.")
    return targets


def _transfer_one(args: argparse.Namespace, settings, input_path: Path, output_path: Path, progress) -> dict:
    import bpy

    from .blender import scene_io
    from .blender.operators.transfer import run_transfer, split_names

    scene_io.load_scene(input_path)
    source = scene_io.find_object(args.source, "MESH")
    names = [name for text in args.target for name in split_names(text)]
    targets = [scene_io.find_object(name, "MESH") for name in names] if names else _default_targets(source)
    outcomes = run_transfer(source, targets, settings, bpy.context.evaluated_depsgraph_get(), progress)
    progress(1.0, "Saving")
    scene_io.save_scene(output_path)
    return {"targets": {outcome.target.name: outcome.summary for outcome in outcomes}}


def _run_transfer(args: argparse.Namespace) -> int:
    settings = _transfer_settings(args)

    def process(input_path, output_path, progress):
        return _transfer_one(args, settings, input_path, output_path, progress)

    return run_batch(args.inputs, args.out, args.format, process, args.summary, args.quiet)


# --------------------------------------------------------------------------- skin


def _add_skin_arguments(parser: argparse.ArgumentParser) -> None:
    add_batch_arguments(parser)
    parser.add_argument("--armature", default="", help="Armature to bind to (default: the only armature in the file)")
    parser.add_argument("--mesh", action="append", default=[], metavar="OBJ",
                        help="Mesh to skin (repeat, or comma-separate; default: every mesh except bone shapes)")
    parser.add_argument("--distance", choices=("geodesic", "hollow"), default="hollow",
                        help="hollow (default): HollowDist through empty space, reaches bones outside the body and "
                             "loose parts (HeterSkinNet); geodesic: through the inside of the mesh (RigNet)")
    parser.add_argument("--resolution", type=_resolution, default=88,
                        help="Voxels along the longest side (default 88, 4 to 1024)")
    parser.add_argument("--falloff", type=_positive, default=4.0,
                        help="Heat strength: higher gives sharper blends between bones (default 4)")
    parser.add_argument("--max-influences", type=_non_negative_int, default=4,
                        help="Bones per vertex to keep, 0 = no limit (default 4)")
    parser.add_argument("--smoothing-iterations", type=_non_negative_int, default=0,
                        help="Extra surface smoothing passes (default 0)")
    parser.add_argument("--smoothing-strength", type=_fraction, default=0.5,
                        help="Blend factor of one smoothing pass, 0 to 1 (default 0.5)")
    parser.add_argument("--replace-all", action="store_true",
                        help="Remove every existing vertex group first (default: only the deform bones' groups)")


def _default_skin_objects(armature_name: str, mesh_names: list[str]):
    """The armature and meshes a skin run binds, from names or the file's content."""
    import bpy

    from .blender import scene_io
    from .blender.operators.transfer import split_names
    from .core.errors import InputError

    if armature_name:
        armature = scene_io.find_object(armature_name, "ARMATURE")
    else:
        armatures = [obj for obj in bpy.data.objects if obj.type == "ARMATURE"]
        if len(armatures) != 1:
            found = ", ".join(obj.name for obj in armatures) or "none"
            raise InputError(f"The file must hold exactly one armature, or name it with --armature (found: {found}).")
        armature = armatures[0]
    names = [name for text in mesh_names for name in split_names(text)]
    if names:
        return armature, [scene_io.find_object(name, "MESH") for name in names]
    shapes = {bone.custom_shape for obj in bpy.data.objects if obj.type == "ARMATURE" for bone in obj.pose.bones}
    meshes = [obj for obj in bpy.data.objects if obj.type == "MESH" and obj not in shapes]
    if not meshes:
        raise InputError("The file holds no mesh to skin.")
    return armature, meshes


def _run_skin(args: argparse.Namespace) -> int:
    from_args = dict(distance=args.distance, resolution=args.resolution, falloff=args.falloff,
                     max_influences=args.max_influences, smoothing_iterations=args.smoothing_iterations,
                     smoothing_strength=args.smoothing_strength, replace_all=args.replace_all)

    def process(input_path, output_path, progress):
        import bpy

        from .blender import scene_io
        from .blender.operators.skin import SkinSettings, run_skin

        scene_io.load_scene(input_path)
        armature, meshes = _default_skin_objects(args.armature, args.mesh)
        weights = run_skin(armature, meshes, SkinSettings(**from_args), bpy.context.evaluated_depsgraph_get(), progress)
        progress(1.0, "Saving")
        scene_io.save_scene(output_path)
        return {"armature": armature.name, "meshes": [obj.name for obj in meshes],
                "bones": len(weights.bone_names), "vertices": int(weights.matrix.shape[0])}

    return run_batch(args.inputs, args.out, args.format, process, args.summary, args.quiet)


# --------------------------------------------------------------------------- package


def _add_package_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", required=True, metavar="DIR", help="Folder to write the extension packages to")
    parser.add_argument("--platform", action="append", dest="platforms", default=None, metavar="PLATFORM",
                        help="Build for this platform only (repeat for several; default: all)")
    parser.add_argument("--wheel-cache", metavar="DIR", default=None,
                        help="Folder of already downloaded wheels to reuse")


def _run_package(args: argparse.Namespace) -> int:
    try:
        from .packaging import build_packages
    except ImportError as error:
        print(f"error: packaging is not available in this installation ({error}).", file=sys.stderr)
        return EXIT_FAILED
    extra = {"wheel_cache": args.wheel_cache} if args.wheel_cache else {}
    for path in build_packages(args.out, args.platforms, **extra):
        print(path)
    return EXIT_OK


register_subcommand("transfer", "Copy skin weights from a body onto garments (robust transfer with inpainting)",
                    _add_transfer_arguments, _run_transfer)
register_subcommand("skin", "Weight meshes to an armature from voxel distances through the shape",
                    _add_skin_arguments, _run_skin)
from . import eval_command  # noqa: E402  (after register_subcommand exists)

register_subcommand("eval", "Score a skinning, rigging or transfer method against artist rigs",
                    eval_command.add_arguments, eval_command.run)
register_subcommand("package", "Build the Blender extension .zip packages", _add_package_arguments, _run_package)


# --------------------------------------------------------------------------- entry point


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m autorig_addon",
        description="AutoRig: automatic rigging, skinning and weight transfer, without the Blender UI.",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="SUBCOMMAND")
    for name, subcommand in SUBCOMMANDS.items():
        subparser = subparsers.add_parser(name, help=subcommand.help, description=subcommand.help)
        subcommand.add_arguments(subparser)
    return parser


def arguments_from_sys_argv(argv: list[str] | None = None) -> list[str]:
    """The add-on's own arguments from a process command line: what follows
    ``--`` if present (Blender convention), nothing when the process is
    Blender itself, else everything after the program name."""
    argv = list(sys.argv if argv is None else argv)
    if "--" in argv:
        return argv[argv.index("--") + 1:]
    program = os.path.basename(argv[0]).lower() if argv else ""
    if program.startswith("blender"):
        return []
    return argv[1:]


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (never raises SystemExit)."""
    arguments = arguments_from_sys_argv() if argv is None else list(argv)
    parser = build_parser()
    try:
        args = parser.parse_args(arguments)
    except SystemExit as exit_request:
        code = exit_request.code
        return code if isinstance(code, int) else EXIT_USAGE
    if args.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    from .core.errors import InputError

    try:
        return SUBCOMMANDS[args.command].run(args)
    except (UsageError, InputError) as error:
        print(f"error: {error}", file=sys.stderr)
        return EXIT_USAGE
