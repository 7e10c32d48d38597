"""The parser, the subcommand registry and :func:`main`.

Subcommands live in :data:`SUBCOMMANDS` (name -> :class:`Subcommand`); a
feature adds its own with :func:`register_subcommand`. Declaring the
arguments never imports ``bpy``: ``python -m autorig_addon --help`` works
without Blender, which loads only when a subcommand runs.

Exit codes (:mod:`.exit_codes`): 0 every input succeeded, 1 some input or
the work failed (an :class:`~autorig_addon.core.errors.InputError`), 2 usage
error (:class:`~.exit_codes.UsageError` or a bad argument). See
:mod:`autorig_addon.core.errors` for what each exception means.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import sys
from dataclasses import dataclass
from typing import Callable

from ..core.errors import InputError
from . import evaluate, package, rename, rig, skin, transfer
from .exit_codes import EXIT_FAILED, EXIT_USAGE, UsageError


@dataclass(frozen=True)
class Subcommand:
    """One subcommand: ``add_arguments(parser)`` declares its options,
    ``run(args) -> exit code`` does the work."""

    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


SUBCOMMANDS: dict[str, Subcommand] = {}


def register_subcommand(name: str, help: str, add_arguments, run) -> None:
    """Add (or replace) the subcommand ``name``."""
    SUBCOMMANDS[name] = Subcommand(help, add_arguments, run)


#: The ``train`` subcommand's package and module, relative to this one: the
#: training package, which a source checkout has and the extension zip leaves out.
TRAINING_PACKAGE, TRAINING_COMMAND = "..training", "..training.command"

_modules = [transfer, skin, rig, rename, evaluate, package]
if importlib.util.find_spec(TRAINING_PACKAGE, __package__) is not None:
    _modules.append(importlib.import_module(TRAINING_COMMAND, __package__))
for _module in _modules:
    register_subcommand(_module.NAME, _module.HELP, _module.add_arguments, _module.run)


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
    """Run the command line; returns the exit code (never raises SystemExit).

    A :class:`UsageError` gives exit code 2 and an :class:`InputError`
    that stops the whole subcommand exit code 1, each with its message on
    stderr as ``error: MESSAGE``; anything else is a bug or an environment
    failure and propagates with its traceback.
    """
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
    try:
        return SUBCOMMANDS[args.command].run(args)
    except UsageError as error:
        print(f"error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return EXIT_FAILED
