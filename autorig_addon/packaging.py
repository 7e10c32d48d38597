"""Build the installable Blender extension zips, one per platform.

The add-on's sources are ``autorig_addon/`` while ``blender_manifest.toml``
sits at the repository top, so a build stages a temporary directory::

    STAGE/__init__.py, core/, blender/, ...   contents of autorig_addon/ (less the
                                              training package, training/)
    STAGE/blender_manifest.toml               platforms + wheels rewritten
    STAGE/LICENSE                             the GPL-3.0 text
    STAGE/CREDITS.md                          who made the characters the networks learn from
    STAGE/wheels/*.whl                        the dependencies Blender lacks (scipy)

and runs Blender's own extension builder (``blender_ext.py build
--split-platforms``, shipped inside the ``bpy`` wheel), which also validates
the manifest. Wheels come from ``pip download`` into a cache that later
builds reuse. Where each platform's wheels come from is spelled out in
:data:`PLATFORM_TARGETS`; docs/packaging.md explains it for people.

torch is never shipped: inside Blender the networks run on numpy
(``core/nn``), and torch only trains them (``training/``, left out of the
zip).

Run ``python -m autorig_addon.packaging OUT_DIR [PLATFORM ...]`` from a
source checkout. Nothing here imports ``bpy``.
"""

from __future__ import annotations

import argparse
import glob
import importlib.metadata
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Sequence

from .core.errors import InputError
from .core.progress import ProgressCallback, report

#: The add-on package directory; its contents become the extension's root.
ADDON_DIR = Path(__file__).resolve().parent
#: Repository top, where the manifest lives.
REPO_ROOT = ADDON_DIR.parent
MANIFEST_FILENAME = "blender_manifest.toml"
MANIFEST_PATH = REPO_ROOT / MANIFEST_FILENAME
#: Folder inside the extension that holds the wheels (manifest entries are ``./wheels/NAME.whl``).
WHEELS_FOLDER = "wheels"

#: Python of every Blender release we support (4.2 to 5.0 ship CPython 3.11).
BLENDER_PYTHON_VERSION = "3.11"
BLENDER_PYTHON_IMPLEMENTATION = "cp"
#: What the add-on imports that Blender does not bundle, shipped at the
#: versions installed here (the ones the tests ran with). numpy is not
#: shipped: Blender 4.2+ bundles it. torch is not shipped: it only trains
#: the networks, which run on numpy inside Blender.
SHIPPED_DISTRIBUTIONS = ("scipy",)
#: Default download cache, reused between builds (one sub-folder per platform).
DEFAULT_WHEEL_CACHE = os.path.join("~", ".cache", "autorig_addon", "wheels")
#: Add-on folders (relative to ``autorig_addon/``) left out of the extension:
#: the training package (torch, training sets, the ``train`` command), which
#: nothing inside Blender imports.
EXCLUDED_SOURCE_FOLDERS = ("training",)


class PackagingError(InputError):
    """The build failed (pip could not fetch a wheel, Blender's builder
    rejected the package, not a source checkout); the message says why and
    what to do. The ``package`` subcommand exits 1 on it, not 2: the
    command line was right."""


@dataclass(frozen=True)
class WheelRequest:
    """One wheel to download.

    Attributes
    ----------
    distribution : str
        Project name as pip spells it (``"scipy"``).
    version : str
        Exact version (``"1.17.1"``).
    """

    distribution: str
    version: str

    @property
    def requirement(self) -> str:
        return f"{self.distribution}=={self.version}"


@dataclass(frozen=True)
class PlatformTarget:
    """How to fetch the wheels of one Blender platform.

    Attributes
    ----------
    blender_platform : str
        Blender's platform name (``"linux-x64"``).
    pip_platform_tags : tuple of str
        ``pip download --platform`` tags, most preferred first (oldest OS
        first, so the widest-compatible wheel wins); the newest is the
        oldest OS that both Blender and the shipped wheels allow, so no
        wheel needing a newer OS can slip in.
    """

    blender_platform: str
    pip_platform_tags: tuple


#: Every platform we ship; all wheels come from pip's configured sources (PyPI).
PLATFORM_TARGETS = {
    "linux-x64": PlatformTarget(
        "linux-x64",
        ("manylinux_2_28_x86_64", "manylinux_2_27_x86_64", "manylinux2014_x86_64"),
    ),
    "windows-x64": PlatformTarget("windows-x64", ("win_amd64",)),
    # Intel Macs: Blender 4.2 to 5.0 need macOS 11.2; scipy 1.17's wheel is
    # tagged macosx_10_14.
    "macos-x64": PlatformTarget(
        "macos-x64",
        ("macosx_10_13_x86_64", "macosx_10_14_x86_64", "macosx_10_15_x86_64", "macosx_11_0_x86_64"),
    ),
    # Apple silicon: scipy 1.17's oldest arm64 wheel is tagged macosx_12_0,
    # so this package needs macOS 12 (Blender itself runs from 11.2).
    "macos-arm64": PlatformTarget("macos-arm64", ("macosx_11_0_arm64", "macosx_12_0_arm64")),
}


def build_packages(
    out_dir: str,
    platforms: Optional[list[str]] = None,
    wheel_cache: Optional[str] = None,
    *,
    progress: Optional[ProgressCallback] = None,
) -> list[str]:
    """Build one extension zip per platform into ``out_dir``.

    Parameters
    ----------
    out_dir : str
        Folder for the zips (created if missing).
    platforms : list of str, optional
        Blender platform names from :data:`PLATFORM_TARGETS`; default all.
    wheel_cache : str, optional
        Download cache (default :data:`DEFAULT_WHEEL_CACHE`); wheels already
        there are reused.
    progress : ProgressCallback, optional

    Returns
    -------
    list of str
        Absolute zip paths, one per platform, named
        ``autorig_addon-VERSION-PLATFORM.zip`` (``-`` in the platform becomes ``_``).

    Raises
    ------
    InputError
        Unknown platform names.
    PackagingError
        Not run from a source checkout, pip cannot fetch a wheel, ``bpy`` (the
        builder) is missing, or Blender's builder rejects the package (its
        messages are included).
    """
    platforms = list(PLATFORM_TARGETS) if platforms is None else list(platforms)
    check_platforms(platforms)
    if not MANIFEST_PATH.is_file():
        raise PackagingError(
            f"{MANIFEST_FILENAME} not found next to {ADDON_DIR}; build from a source checkout of the repository."
        )
    cache_root = os.path.expanduser(wheel_cache or DEFAULT_WHEEL_CACHE)
    wheels_by_platform = {}
    for index, platform in enumerate(platforms):
        report(progress, 0.8 * index / len(platforms), f"Fetching wheels for {platform}")
        wheels_by_platform[platform] = download_wheels(platform, os.path.join(cache_root, platform))
    report(progress, 0.8, "Building extension packages")
    out_dir = os.path.abspath(out_dir)
    os.makedirs(out_dir, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="autorig_addon_stage_") as stage_dir:
        stage_extension(stage_dir, wheels_by_platform)
        zips = run_blender_builder(stage_dir, out_dir, platforms)
    for platform, zip_path in zip(platforms, zips):
        check_zip_wheels(zip_path, wheels_by_platform[platform])
    report(progress, 1.0, "Packages built")
    return zips


def wheel_requests(platform: str) -> list[WheelRequest]:
    """The wheels shipped for ``platform``: each of
    :data:`SHIPPED_DISTRIBUTIONS` at the version installed here (the one the
    tests ran with); every platform ships the same distributions, in its own
    build."""
    check_platforms([platform])
    return [WheelRequest(name, _installed_version(name)) for name in SHIPPED_DISTRIBUTIONS]


def download_wheels(platform: str, cache_dir: str) -> list[str]:
    """Paths of ``platform``'s wheels in ``cache_dir``, downloading the missing ones.

    Raises
    ------
    PackagingError
        pip cannot find or fetch a wheel (the message holds pip's output tail).
    """
    os.makedirs(cache_dir, exist_ok=True)
    target = PLATFORM_TARGETS[platform]
    paths = []
    for request in wheel_requests(platform):
        path = cached_wheel(cache_dir, request)
        if path is None:
            pip_download(request, target.pip_platform_tags, cache_dir)
            path = cached_wheel(cache_dir, request)
        if path is None:
            raise PackagingError(
                f"pip reported success but no wheel for {request.requirement} appeared in {cache_dir}."
            )
        paths.append(path)
    return paths


def cached_wheel(cache_dir: str, request: WheelRequest) -> Optional[str]:
    """Path of the wheel in ``cache_dir`` matching ``request`` exactly, or None."""
    wanted = (_normalized_distribution(request.distribution), request.version)
    for path in sorted(glob.glob(os.path.join(glob.escape(cache_dir), "*.whl"))):
        fields = os.path.basename(path).split("-")
        if len(fields) >= 5 and (_normalized_distribution(fields[0]), fields[1]) == wanted:
            return path
    return None


def stage_extension(stage_dir: str, wheels_by_platform: dict[str, list[str]]) -> None:
    """Fill ``stage_dir`` with the add-on sources, the rewritten manifest and
    the wheels of every platform in ``wheels_by_platform``."""
    copy_addon_sources(stage_dir)
    # The licence text the manifest's `license` names (GPL-3.0-or-later) ships beside the code,
    # and so do the credits of the (CC-BY, CC-BY-SA, GPL) characters the networks learn from.
    for name in ("LICENSE", "CREDITS.md"):
        shutil.copy2(REPO_ROOT / name, os.path.join(stage_dir, name))
    wheel_dir = os.path.join(stage_dir, WHEELS_FOLDER)
    os.makedirs(wheel_dir, exist_ok=True)
    names = []
    for paths in wheels_by_platform.values():
        for path in paths:
            name = os.path.basename(path)
            if name not in names:
                names.append(name)
                _link_or_copy(path, os.path.join(wheel_dir, name))
    manifest = manifest_text(MANIFEST_PATH.read_text(encoding="utf-8"), list(wheels_by_platform), names)
    Path(stage_dir, MANIFEST_FILENAME).write_text(manifest, encoding="utf-8")


def copy_addon_sources(stage_dir: str) -> None:
    """Copy ``autorig_addon/`` into ``stage_dir``, without caches and
    without :data:`EXCLUDED_SOURCE_FOLDERS`."""
    ignore_caches = shutil.ignore_patterns("__pycache__", "*.pyc")

    def ignored(folder, names):
        relative = Path(folder).relative_to(ADDON_DIR)
        excluded = {name for name in names if (relative / name).as_posix() in EXCLUDED_SOURCE_FOLDERS}
        return set(ignore_caches(folder, names)) | excluded

    shutil.copytree(ADDON_DIR, stage_dir, ignore=ignored, dirs_exist_ok=True)


def manifest_text(source_text: str, platforms: Sequence[str], wheel_names: Sequence[str]) -> str:
    """``source_text`` (a manifest) with its top-level ``platforms`` and
    ``wheels`` arrays replaced; comments and other keys are kept.

    Parameters
    ----------
    source_text : str
        Manifest TOML holding both keys as top-level arrays.
    platforms : sequence of str
        Blender platform names.
    wheel_names : sequence of str
        Wheel file names; written as ``./wheels/NAME``.
    """
    replacements = {
        "platforms": "platforms = [" + ", ".join(f'"{p}"' for p in platforms) + "]",
        "wheels": "wheels = [\n" + "".join(f'  "./{WHEELS_FOLDER}/{n}",\n' for n in wheel_names) + "]",
    }
    text = source_text
    for key, line in replacements.items():
        text, count = re.subn(rf"^{key}\s*=\s*\[[^\]]*\]", lambda _match, line=line: line, text, flags=re.MULTILINE)
        if count != 1:
            raise PackagingError(f"{MANIFEST_FILENAME} must define '{key} = [...]' exactly once, found {count}.")
    parsed = tomllib.loads(text)
    if parsed["platforms"] != list(platforms) or len(parsed["wheels"]) != len(wheel_names):
        raise PackagingError(f"Rewriting '{MANIFEST_FILENAME}' failed; check the platforms/wheels arrays there.")
    return text


def find_blender_extension_builder() -> tuple[str, str]:
    """Blender's extension command line tool and its valid-tags list, from
    the installed ``bpy`` wheel (located without importing bpy).

    Returns
    -------
    builder : str
        Path of ``bl_pkg/cli/blender_ext.py``.
    valid_tags : str
        Path of ``_bpy_internal/extensions/tags.py`` ("" when absent).
    """
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise PackagingError(
            "The 'bpy' package (Blender as a Python module) is needed to build extensions; "
            "install it with 'pip install bpy==5.0.1'."
        )
    bpy_dir = list(spec.submodule_search_locations)[0]
    builders = sorted(glob.glob(os.path.join(glob.escape(bpy_dir), "*", "scripts", "addons_core", "bl_pkg", "cli",
                                             "blender_ext.py")))
    if not builders:
        raise PackagingError(f"Blender's extension builder (bl_pkg/cli/blender_ext.py) is missing under {bpy_dir}.")
    builder = builders[-1]
    scripts_dir = Path(builder).parents[3]
    tags = scripts_dir / "modules" / "_bpy_internal" / "extensions" / "tags.py"
    return builder, str(tags) if tags.is_file() else ""


def run_blender_builder(stage_dir: str, out_dir: str, platforms: Sequence[str]) -> list[str]:
    """Run ``blender_ext.py build --split-platforms`` on ``stage_dir``.

    Returns
    -------
    list of str
        One zip path per platform, in ``platforms`` order.
    """
    builder, valid_tags = find_blender_extension_builder()
    command = [
        sys.executable, builder, "build",
        "--source-dir", stage_dir,
        "--output-dir", out_dir,
        "--split-platforms",
        "--valid-tags", valid_tags,
    ]
    result = subprocess.run(command, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    output = result.stdout + result.stderr
    errors = [line for line in output.splitlines() if line.startswith(("FATAL_ERROR", "ERROR"))]
    if result.returncode != 0 or errors:
        raise PackagingError("Blender's extension builder failed:\n" + "\n".join(errors or output.splitlines()[-20:]))
    manifest = tomllib.loads(Path(stage_dir, MANIFEST_FILENAME).read_text(encoding="utf-8"))
    zips = [
        os.path.join(out_dir, f"{manifest['id']}-{manifest['version']}-{platform.replace('-', '_')}.zip")
        for platform in platforms
    ]
    missing = [path for path in zips if not os.path.isfile(path)]
    if missing:
        raise PackagingError(f"Blender's builder finished but did not write {missing}. Its output:\n{output}")
    return zips


def check_zip_wheels(zip_path: str, wheel_paths: Sequence[str]) -> None:
    """Raise :class:`PackagingError` unless every wheel is inside the zip.

    Blender's builder keeps a wheel in a platform's zip only when it maps the
    wheel's platform tag to that platform, so a missing wheel means a tag
    Blender does not recognise.
    """
    with zipfile.ZipFile(zip_path) as archive:
        inside = set(archive.namelist())
    dropped = [os.path.basename(p) for p in wheel_paths if f"{WHEELS_FOLDER}/{os.path.basename(p)}" not in inside]
    if dropped:
        raise PackagingError(
            f"{os.path.basename(zip_path)} lacks {dropped}: Blender did not match their platform tags to the "
            "zip's platform. Pick wheels with standard tags (see PLATFORM_TARGETS)."
        )


def check_platforms(platforms: Sequence[str]) -> None:
    """Raise :class:`InputError` (not a :class:`PackagingError`: the request
    is wrong, not the build) for no, unknown or repeated platform names."""
    if not platforms:
        raise InputError(f"No platform given; choose from {', '.join(PLATFORM_TARGETS)}.")
    unknown = [p for p in platforms if p not in PLATFORM_TARGETS]
    if unknown:
        raise InputError(f"Unknown platform(s) {', '.join(unknown)}; choose from {', '.join(PLATFORM_TARGETS)}.")
    if len(set(platforms)) != len(platforms):
        raise InputError(f"Platforms are listed twice: {', '.join(platforms)}.")


def _installed_version(distribution: str) -> str:
    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        raise PackagingError(
            f"{distribution} is not installed in this Python; install the project's requirements "
            "(pip install -r requirements.txt) so the build knows which version to ship."
        ) from None


def _normalized_distribution(name: str) -> str:
    return re.sub(r"[-_.]+", "_", name).lower()


def pip_download(request: WheelRequest, platform_tags: Sequence[str], cache_dir: str) -> None:
    """``pip download`` one wheel for Blender's Python into ``cache_dir``
    from pip's configured sources (PyPI, the user's ``find-links``).

    Raises
    ------
    PackagingError
        pip failed; the message holds the tail of pip's output.
    """
    command = [
        sys.executable, "-m", "pip", "download",
        "--only-binary=:all:", "--no-deps",
        "--python-version", BLENDER_PYTHON_VERSION,
        "--implementation", BLENDER_PYTHON_IMPLEMENTATION,
        *[argument for tag in platform_tags for argument in ("--platform", tag)],
        "--dest", cache_dir,
        "--progress-bar", "off",
        request.requirement,
    ]
    result = subprocess.run(command, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if result.returncode == 0:
        return
    output = " ".join(command[4:]) + "\n" + "\n".join((result.stdout + result.stderr).splitlines()[-8:])
    raise PackagingError(
        f"pip could not download {request.requirement} for platform tags {', '.join(platform_tags)}. "
        f"Check the network (PyPI) or put the wheel into {cache_dir} by hand.\n{output}"
    )


def _link_or_copy(source: str, destination: str) -> None:
    # A hard link avoids copying the ~35 MB scipy wheel when cache and stage share a disk.
    try:
        os.link(source, destination)
    except OSError:
        shutil.copy2(source, destination)


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m autorig_addon.packaging", description=__doc__.split("\n\n")[0])
    parser.add_argument("out_dir", help="folder for the zips")
    parser.add_argument("platforms", nargs="*", help=f"default: all of {', '.join(PLATFORM_TARGETS)}")
    parser.add_argument("--wheel-cache", default=None, help=f"download cache (default {DEFAULT_WHEEL_CACHE})")
    args = parser.parse_args(argv)
    try:
        check_platforms(args.platforms or list(PLATFORM_TARGETS))
    except InputError as error:
        parser.error(str(error))  # a bad argument: exit 2, like every usage error
    try:
        zips = build_packages(args.out_dir, args.platforms or None, args.wheel_cache,
                              progress=lambda fraction, message: print(f"[{fraction:4.0%}] {message}", flush=True))
    except InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    print("\n".join(zips))
    return 0


if __name__ == "__main__":
    sys.exit(main())
