"""``python -m autorig_addon package``: build the Blender extension zips.

Unknown or repeated ``--platform`` values are usage errors (exit 2); a
build that fails (pip cannot download a wheel, Blender's builder rejects
the package) exits 1 with the reason on stderr.
"""

from __future__ import annotations

import argparse

from ..core.errors import InputError
from .exit_codes import EXIT_OK, UsageError

NAME = "package"
HELP = "Build the Blender extension .zip packages"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", required=True, metavar="DIR", help="Folder to write the extension packages to")
    parser.add_argument("--platform", action="append", dest="platforms", default=None, metavar="PLATFORM",
                        help="Build for this platform only (repeat for several; default: all)")
    parser.add_argument("--wheel-cache", metavar="DIR", default=None,
                        help="Folder of already downloaded wheels to reuse")


def run(args: argparse.Namespace) -> int:
    from .. import packaging

    if args.platforms is not None:
        try:
            packaging.check_platforms(args.platforms)
        except InputError as error:
            raise UsageError(str(error)) from None
    # A PackagingError (an InputError) from the build is a failure, exit 1 (see main).
    for path in packaging.build_packages(args.out, args.platforms, args.wheel_cache):
        print(path)
    return EXIT_OK
