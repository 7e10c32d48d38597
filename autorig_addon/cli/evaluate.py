"""``python -m autorig_addon eval {skin,rig,transfer} DATA... --method NAME``.

Runs one method on rigged characters whose artist rig is the reference and
scores it with ``core.evaluation.skin_metrics.evaluate_skin``,
``core.evaluation.skeleton_metrics.evaluate_rig`` or
``core.evaluation.skin_metrics.evaluate_transfer``. Prints a markdown table
per category (one row per character) and a summary (mean and median per
category and overall, ``core.evaluation.report``); ``--out`` writes the
same as JSON::

    {"task": "skin", "method": "boneheat",
     "characters": [{"name", "category", "path", "l1", ..., "seconds", "unweighted", "notes"} |
                    {"name", "category", "path", "error"}],
     "summary": {"categories": {CATEGORY: {"count", "failed", "mean": {...}, "median": {...}}},
                 "overall": {...}}}

The methods and their registries are in :mod:`.evaluation_methods`; the
files are picked, named and categorised by
``core.dataset.split.collect_data``; skin and transfer evaluation leave out
the characters the split marks ``skeleton_only`` (their weights are not an
artist's), saying so on stderr (:data:`TASK_PURPOSES`). This module parses
the arguments, runs the method on each file and writes the report.

The method never sees what it is judged against: a skin method gets the
mesh and the skeleton (bone heat runs on a copy built from the arrays, with
no vertex group), a rig method the mesh alone, a transfer method the source
body with its weights and the target without weights.

Tasks
-----
skin
    ``l1``, ``precision``, ``recall``, ``deform_mean``, ``deform_max``
    (10 seeded poses, 30 % of the deform bones, N(0, 25 deg); distances in
    units of the character size) plus ``unweighted``, the vertices the
    method left without weight. Such a vertex stays where it is under any
    pose, as in Blender, so the deformation error compares it unmoved with
    the reference. Vertices the *reference* leaves unweighted are not scored.
rig
    ``cd_j2j``, ``cd_j2b``, ``cd_b2b``, ``iou``, ``precision``, ``recall``,
    ``tree_edit`` on deform bones, joints at the same place merged;
    distances (and the joint matching tolerance) in units of the largest
    side of the character's bounding box, as RigNet reports them. A
    method's notes (e.g. which training character the
    ``nearest_character`` baseline chose) join the loader's.
transfer
    DATA files without an armature are garments: weights come from the body
    given by ``--source`` and are scored by edge stretch under the poses
    (``stretch_p99``, ``stretch_max``). DATA files that are rigged
    characters are a self-transfer check with an exact reference: the target
    is the character's own surface pushed out along its normals by
    ``core.evaluation.self_transfer.SELF_TRANSFER_OFFSET_FRACTION`` of its
    size (a skin-tight garment whose right weights are the character's
    own), scored by stretch and
    ``deform_mean``/``deform_max`` against those weights.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

from ..core.dataset.split import DEFAULT_SPLIT_FILE, PURPOSE_SKELETON, PURPOSE_SKIN, SUBSETS, DataItem, collect_data
from ..core.errors import InputError
from ..core.evaluation.report import markdown_report, summarise
from .batch import check_writable_folder, require_not_folder, stdout_to_stderr
from .evaluation_methods import (
    REFERENCE_METHOD,
    SKIN_METHODS,
    TRANSFER_METHODS,
    SkinInput,
    check_method,
    method_names,
    rig_predictor,
)
from .exit_codes import EXIT_FAILED, EXIT_OK, UsageError

NAME = "eval"
HELP = "Score a skinning, rigging or transfer method against artist rigs"

#: Task names, the first positional argument.
TASKS = ("skin", "rig", "transfer")
#: What each task scores against: a rig the skeleton, skin and transfer the
#: weights, so they leave out the split's skeleton-only characters.
TASK_PURPOSES = {"skin": PURPOSE_SKIN, "rig": PURPOSE_SKELETON, "transfer": PURPOSE_SKIN}


# --------------------------------------------------------------------------- arguments


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the ``eval`` arguments (no Blender needed)."""
    methods = "; ".join(f"{task}: " + ", ".join(method_names(task)) for task in TASKS)
    parser.add_argument("task", choices=TASKS,
                        help="What to evaluate: skin weights, rigs (skeletons) or weight transfer")
    parser.add_argument("data", nargs="+", metavar="DATA",
                        help="Rigged character files (.blend .glb .gltf .fbx) or folders of them; "
                             "garments for transfer")
    parser.add_argument("--method", required=True, help=f"Method to evaluate ({methods})")
    parser.add_argument("--out", metavar="FILE", help="Write the JSON report to FILE")
    parser.add_argument("--split", choices=SUBSETS, default="all",
                        help="Keep only the files of this subset of the data split (default all)")
    parser.add_argument("--split-file", metavar="FILE", default=str(DEFAULT_SPLIT_FILE),
                        help="The data split (default: data_split.json at the repository top)")
    parser.add_argument("--source", metavar="FILE",
                        help="transfer: the weighted body whose weights go onto the garments")
    parser.add_argument("--format", dest="stdout_format", choices=("markdown", "json"), default="markdown",
                        help="What to print on stdout (default markdown)")
    parser.add_argument("--baseline", metavar="REPORT",
                        help="A JSON report of another method (from --out) to show beside this one")
    parser.add_argument("--quiet", action="store_true", help="No per-character progress lines on stderr")


# --------------------------------------------------------------------------- evaluation


def _predict_timed(predict: Callable, *args) -> tuple:
    started = time.perf_counter()
    result = predict(*args)
    return result, round(time.perf_counter() - started, 3)


def evaluate_skin_item(item: DataItem, method: str) -> dict:
    """Load one character, run a skin method on it and score it."""
    from ..blender.characters import load_character
    from ..core.evaluation.skin_metrics import evaluate_skin

    character = load_character(item.path, item.name, item.category)
    if method == REFERENCE_METHOD:
        predicted, seconds = character.weights, 0.0
    else:
        task = SkinInput(character.mesh, character.skeleton, character.armature_name)
        predicted, seconds = _predict_timed(SKIN_METHODS[method].predict, task)
    scores = evaluate_skin(character.mesh.vertices, predicted, character.weights, character.skeleton)
    return {**scores, "seconds": seconds, "vertices": character.mesh.vertex_count,
            "reference_unweighted": character.unweighted_count, "notes": list(character.notes)}


def evaluate_rig_item(item: DataItem, method: str) -> dict:
    """Load one character, predict its rig from the mesh alone and score it."""
    from ..blender.characters import load_character
    from ..core.evaluation.key_joint_metrics import score_key_joints
    from ..core.evaluation.skeleton_metrics import evaluate_rig
    from ..core.geometry.bounding_box import largest_side

    character = load_character(item.path, item.name, item.category)
    predicted, seconds = _predict_timed(rig_predictor(method), character.mesh, item)
    # RigNet's unit: the largest side of the bounding box, not the diagonal the skin metrics use.
    size = largest_side(character.mesh.vertices)
    scores = evaluate_rig(predicted.skeleton, character.skeleton, size)
    scores.update(score_key_joints(predicted.skeleton, character.mesh, character.skeleton, size,
                                   item.sides_named_from_the_viewer))
    return {**scores, "seconds": seconds, "notes": list(character.notes) + list(predicted.notes)}


@dataclass
class _TransferSource:
    """The body of a garment transfer, loaded once."""

    mesh: object
    weights: object
    skeleton: object


def load_transfer_source(path: Optional[str]) -> Optional[_TransferSource]:
    if not path:
        return None
    from ..blender.characters import load_character

    body = load_character(path)
    return _TransferSource(body.mesh, body.weights, body.skeleton)


def _garment_mesh():
    """Every mesh with faces in the loaded scene, as one Mesh."""
    import bpy

    from ..blender import convert

    objects = [obj for obj in bpy.context.scene.objects if obj.type == "MESH" and len(obj.data.polygons)]
    if not objects:
        raise InputError("The garment file holds no mesh with faces.")
    return convert.read_mesh(sorted(objects, key=lambda obj: obj.name), bpy.context.evaluated_depsgraph_get())


def evaluate_transfer_item(item: DataItem, method: str, source: Optional[_TransferSource]) -> dict:
    """Transfer onto one DATA file: a self-transfer check for a rigged
    character, a garment transfer from ``source`` otherwise."""
    from ..blender import characters, scene_io
    from ..core.evaluation.self_transfer import self_transfer_target
    from ..core.evaluation.skin_metrics import evaluate_transfer
    from ..core.geometry.topology import edges

    scene_io.load_scene(item.path)
    try:
        characters.choose_armature()
        rigged = True
    except InputError:
        rigged = False
    predict = TRANSFER_METHODS[method].predict
    if rigged:
        character = characters.read_character(item.name, str(item.path), item.category)
        target = self_transfer_target(character.mesh, character.size)
        predicted, seconds = _predict_timed(predict, character.mesh, character.weights, target)
        scores = evaluate_transfer(
            target.vertices, edges(target.triangles), predicted, character.skeleton, character.weights,
        )
        return {**scores, "seconds": seconds, "kind": "self", "vertices": target.vertex_count}
    if source is None:
        raise InputError(f"'{item.name}' is not rigged, so it is a garment: give the body with --source.")
    target = _garment_mesh()
    predicted, seconds = _predict_timed(predict, source.mesh, source.weights, target)
    scores = evaluate_transfer(target.vertices, edges(target.triangles), predicted, source.skeleton)
    return {**scores, "seconds": seconds, "kind": "garment", "vertices": target.vertex_count}


def evaluate(task: str, method: str, items: list[DataItem], source_path: Optional[str] = None, log=None) -> dict:
    """Run ``method`` on every item; one failure does not stop the others.

    Returns
    -------
    dict: ``task``, ``method``, ``characters`` (one dict per item) and
    ``summary`` (:func:`summarise`).
    """
    check_method(task, method)
    with stdout_to_stderr():
        source = load_transfer_source(source_path) if task == "transfer" else None
    characters = []
    for index, item in enumerate(items):
        entry = {"name": item.name, "category": item.category, "path": str(item.path)}
        try:
            with stdout_to_stderr():
                if task == "skin":
                    entry.update(evaluate_skin_item(item, method))
                elif task == "rig":
                    entry.update(evaluate_rig_item(item, method))
                else:
                    entry.update(evaluate_transfer_item(item, method, source))
            outcome = "ok"
        except Exception as error:  # noqa: BLE001 - one bad character must not stop the evaluation
            entry["error"] = str(error) or type(error).__name__
            outcome = f"FAILED: {entry['error']}"
        characters.append(entry)
        if log is not None:
            log(f"[{index + 1}/{len(items)}] {item.name}: {outcome}")
    return {"task": task, "method": method, "characters": characters, "summary": summarise(task, characters)}


# --------------------------------------------------------------------------- output


def _read_baseline(path: str, task: str) -> dict:

    try:
        baseline = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise InputError(f"Cannot read the baseline report '{path}': {error}") from None
    if baseline.get("task") != task or "characters" not in baseline:
        raise InputError(f"'{path}' is not a report of an '{task}' evaluation (write one with --out).")
    return baseline


def run(args: argparse.Namespace) -> int:
    """The ``eval`` subcommand. Exit code 0 when every character was scored,
    1 when some failed (they are in the report with their error).

    Raises
    ------
    UsageError (exit code 2) when the arguments name no file to evaluate,
    an unknown method, an unreadable baseline or an ``--out`` that cannot be
    written (or is a folder): nothing was run.
    """
    if args.out:
        require_not_folder(Path(args.out), "--out")
        check_writable_folder(Path(args.out).parent, "--out")
    log = None if args.quiet else (lambda line: print(line, file=sys.stderr, flush=True))

    def skipped(name: str, reason: str) -> None:
        if log is not None:
            log(f"{name}: left out of {args.task} evaluation (skeleton only: {reason})")

    try:
        check_method(args.task, args.method)
        items = collect_data(args.data, args.split, args.split_file, TASK_PURPOSES[args.task], skipped)
        baseline = _read_baseline(args.baseline, args.task) if args.baseline else None
    except InputError as error:
        raise UsageError(str(error)) from None
    report = evaluate(args.task, args.method, items, args.source, log)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    sys.stdout.write(json.dumps(report, indent=2) + "\n" if args.stdout_format == "json"
                     else markdown_report(report, baseline))
    sys.stdout.flush()
    return EXIT_FAILED if any("error" in entry for entry in report["characters"]) else EXIT_OK
