"""Batch machinery of the file-processing subcommands (``transfer``, ``skin``).

One input or many (files or folders), a text progress bar on stderr, and a
JSON summary on stdout; one failing input does not stop the others.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

from ..core.io.scene_formats import LOADABLE_EXTENSIONS, SAVABLE_EXTENSIONS, scene_files
from .exit_codes import EXIT_FAILED, EXIT_OK, UsageError

#: Output formats of batch jobs, as ``--format`` choices: what ``scene_io.save_scene`` writes.
OUTPUT_FORMATS = tuple(extension.lstrip(".") for extension in SAVABLE_EXTENSIONS)
#: Format of batch outputs unless ``--format`` says otherwise.
DEFAULT_OUTPUT_FORMAT = "blend"
#: Width of the text progress bar, characters.
PROGRESS_BAR_WIDTH = 30
#: Least change of the progress fraction worth redrawing the bar.
PROGRESS_REDRAW_STEP = 0.01


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

    A folder contributes every file with an :data:`LOADABLE_EXTENSIONS`
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
            items.extend((found, found.relative_to(path)) for found in scene_files(path))
        else:
            items.append((path, Path(path.name)))
    if not items:
        raise UsageError(f"No input files found in {', '.join(inputs)} (looked for {', '.join(LOADABLE_EXTENSIONS)}).")
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


def check_outputs(outputs: list[Path], summary_file: str | None = None) -> None:
    """Raise :class:`UsageError` unless every output can be written: a
    format ``scene_io.save_scene`` writes, and a folder (existing, or to be
    created inside an existing one) that accepts new files; likewise the
    folder of the ``--summary`` file. Run before any input is processed, so
    a bad ``--out`` never costs a whole computation.
    """
    for path in outputs:
        if path.suffix.lower() not in SAVABLE_EXTENSIONS:
            raise UsageError(
                f"--out {str(path)!r}: cannot write '{path.suffix or 'extension-less'}' files; "
                f"use one of {', '.join(SAVABLE_EXTENSIONS)}, or a folder."
            )
        require_not_folder(path, "--out")
    for folder in sorted({path.parent for path in outputs}):
        check_writable_folder(folder, "--out")
    if summary_file:
        check_writable_folder(Path(summary_file).parent, "--summary")


def require_not_folder(path: Path, option: str) -> None:
    """Raise :class:`UsageError` naming ``option`` when the output file ``path`` is an existing folder."""
    if Path(path).is_dir():
        raise UsageError(f"{option} {str(path)!r} is a folder; name a file in it.")


def check_writable_folder(folder: Path, option: str) -> None:
    """Raise :class:`UsageError` naming ``option`` unless files can be
    created in ``folder``: its nearest existing ancestor (folders are created
    as needed) must be a folder that accepts a new file."""
    existing = Path(folder).absolute()
    while not existing.exists() and existing.parent != existing:
        existing = existing.parent
    if not existing.is_dir():
        raise UsageError(f"{option}: {str(existing)!r} is a file, not a folder; nothing can be written inside it.")
    try:
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as error:
        raise UsageError(f"{option}: cannot write in the folder {str(existing)!r} "
                         f"({error.strerror or error}).") from None


def run_batch(inputs: list[str], out: str, output_format: str, process: Callable, summary_file: str | None,
              quiet: bool = False) -> int:
    """Run ``process(input_path, output_path, progress) -> dict`` on every input.

    The outputs are checked first (:func:`check_outputs`, a usage error).
    One failing input is recorded and the batch goes on. The summary
    ``{"succeeded": [{"input", "output", ...}], "failed": [{"input", "error"}]}``
    is printed to stdout as JSON and written to ``summary_file`` if given.
    """
    items, is_batch = expand_inputs(inputs)
    outputs = output_paths(items, out, is_batch, output_format)
    check_outputs(outputs, summary_file)
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
        summary["succeeded"].append({"input": str(input_path), "output": str(output_path), "seconds": seconds,
                                     **details})
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
    parser.add_argument("inputs", nargs="+", metavar="INPUT",
                        help=f"Scene files ({' '.join(LOADABLE_EXTENSIONS)}) or folders of them")
    parser.add_argument("--out", required=True, help="Output file, or folder when several inputs or a folder are given")
    parser.add_argument("--format", choices=OUTPUT_FORMATS, default=DEFAULT_OUTPUT_FORMAT,
                        help=f"Output format in batch mode (default: {DEFAULT_OUTPUT_FORMAT})")
    parser.add_argument("--summary", metavar="FILE", help="Also write the JSON summary to FILE")
    parser.add_argument("--quiet", action="store_true", help="No progress bar")
