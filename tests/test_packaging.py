"""Extension packaging without building a zip: the manifest, the wheels
each platform ships, manifest rewriting, wheel cache lookup, pip and
Blender-builder failures. The real Linux zip, built and installed into a
Blender without torch, is tests/test_extension_install.py.
"""

import importlib.metadata
import importlib.util
import os
import textwrap
import tomllib

import pytest

from autorig_addon import packaging
from autorig_addon.core.errors import InputError

LINUX = "linux-x64"
SCIPY_VERSION = importlib.metadata.version("scipy")
#: The one wheel each platform ships (scipy 1.17.1, cp311), by Blender platform.
EXPECTED_WHEELS = {
    "linux-x64": f"scipy-{SCIPY_VERSION}-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl",
    "windows-x64": f"scipy-{SCIPY_VERSION}-cp311-cp311-win_amd64.whl",
    "macos-x64": f"scipy-{SCIPY_VERSION}-cp311-cp311-macosx_10_14_x86_64.whl",
    "macos-arm64": f"scipy-{SCIPY_VERSION}-cp311-cp311-macosx_12_0_arm64.whl",
}
#: What torch needed and the add-on does not: none of it may ship.
TORCH_AND_ITS_DEPENDENCIES = ("torch", "typing_extensions", "sympy", "mpmath")


def _blender_builder_module():
    """Blender's own extension builder (``blender_ext.py``) as a module, for
    its wheel-platform rules."""
    path, _ = packaging.find_blender_extension_builder()
    spec = importlib.util.spec_from_file_location("blender_ext_cli", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_repo_manifest_is_complete():
    manifest = tomllib.loads(packaging.MANIFEST_PATH.read_text())
    assert manifest["id"] == "autorig_addon"
    assert manifest["type"] == "add-on"
    assert manifest["blender_version_min"] == "4.2.0"
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    assert len(manifest["tagline"]) < 64 and manifest["tagline"][-1].isalnum()
    # Intel Macs are back: torch's missing macOS x86-64 wheel kept them out.
    assert manifest["platforms"] == ["linux-x64", "windows-x64", "macos-x64", "macos-arm64"]
    assert list(packaging.PLATFORM_TARGETS) == manifest["platforms"]
    assert manifest["wheels"] == [f"./wheels/{name}" for name in EXPECTED_WHEELS.values()]


def test_the_manifest_is_the_one_source_of_the_version():
    """The package and its installed metadata (pyproject.toml reads the
    package) give the manifest's version, which no other file repeats."""
    import autorig_addon

    version = tomllib.loads(packaging.MANIFEST_PATH.read_text())["version"]
    assert autorig_addon.__version__ == version
    assert importlib.metadata.version("autorig_addon") == version
    for path in (packaging.ADDON_DIR / "__init__.py", packaging.REPO_ROOT / "pyproject.toml"):
        assert version not in path.read_text(), path


def test_the_stage_holds_the_licence_the_credits_and_the_manifest_beside_the_package(tmp_path):
    """Inside the installed extension the manifest sits next to __init__.py
    (where the package reads its version), and the GPL text and the credits come along."""
    packaging.stage_extension(str(tmp_path), {})
    assert (tmp_path / "LICENSE").read_bytes() == (packaging.REPO_ROOT / "LICENSE").read_bytes()
    assert (tmp_path / "CREDITS.md").read_bytes() == (packaging.REPO_ROOT / "CREDITS.md").read_bytes()
    credits = (tmp_path / "CREDITS.md").read_text()
    for author in ("Wildfire Games", "Alientrap", "OpenClonk team", "Red Eclipse team", "SuperTuxKart team",
                   "GDQuest", "Godot demo projects' authors", "Quaternius", "Kenney", "Kay Lousberg"):
        assert author in credits, author
    assert (tmp_path / "LICENSE").read_text().startswith("                    GNU GENERAL PUBLIC LICENSE\n"
                                                         "                       Version 3, 29 June 2007\n")
    assert (tmp_path / "__init__.py").is_file()
    staged = tomllib.loads((tmp_path / packaging.MANIFEST_FILENAME).read_text())
    assert staged["version"] == tomllib.loads(packaging.MANIFEST_PATH.read_text())["version"]


def test_manifest_text_rewrites_only_platforms_and_wheels():
    source = textwrap.dedent(
        """\
        schema_version = "1.0.0"
        # a comment that must survive
        platforms = ["linux-x64", "windows-x64"]
        wheels = [
          "./wheels/old-1.0-py3-none-any.whl",
        ]

        [permissions]
        files = "Import/export rigs"
        """
    )
    text = packaging.manifest_text(source, ["macos-arm64"],
                                   ["a-1.0-py3-none-any.whl", "b-2.0-cp311-cp311-win_amd64.whl"])
    parsed = tomllib.loads(text)
    assert parsed["platforms"] == ["macos-arm64"]
    assert parsed["wheels"] == ["./wheels/a-1.0-py3-none-any.whl", "./wheels/b-2.0-cp311-cp311-win_amd64.whl"]
    assert parsed["permissions"] == {"files": "Import/export rigs"}
    assert "# a comment that must survive" in text
    with pytest.raises(packaging.PackagingError, match="'wheels = \\[...\\]' exactly once, found 0"):
        packaging.manifest_text('platforms = ["linux-x64"]\n', ["linux-x64"], [])


def test_manifest_wheel_of_each_platform_is_that_platforms_by_blenders_rules():
    """Blender's builder puts a wheel into a platform's zip by its platform
    tag: each shipped wheel must land in its own platform's zip and no other."""
    builder = _blender_builder_module()
    platforms = list(packaging.PLATFORM_TARGETS)
    for platform, name in EXPECTED_WHEELS.items():
        compatible_with = builder.blender_platform_compatible_with_wheel_platform_from_filepath
        compatible = [p for p in platforms if compatible_with(p, name)]
        assert compatible == [platform], name
    # Every tag pip may download with maps to the target's own platform too.
    for platform, target in packaging.PLATFORM_TARGETS.items():
        assert target.blender_platform == platform
        for tag in target.pip_platform_tags:
            assert builder.blender_platforms_from_wheel_platform(tag) == [platform], tag


def test_cached_wheel_matches_name_and_exact_version(tmp_path):
    names = ("scipy-1.17.0-cp311-cp311-win_amd64.whl", "scipy-1.17.1-cp311-cp311-win_amd64.whl",
             "typing_extensions-4.16.0-py3-none-any.whl", "notes.txt")
    for name in names:
        (tmp_path / name).write_bytes(b"")
    found = packaging.cached_wheel(str(tmp_path), packaging.WheelRequest("scipy", "1.17.1"))
    assert os.path.basename(found) == "scipy-1.17.1-cp311-cp311-win_amd64.whl"
    assert packaging.cached_wheel(str(tmp_path), packaging.WheelRequest("scipy", "1.17")) is None
    assert packaging.cached_wheel(str(tmp_path), packaging.WheelRequest("scipy", "1.17.2")) is None
    found = packaging.cached_wheel(str(tmp_path), packaging.WheelRequest("typing-extensions", "4.16.0"))
    assert os.path.basename(found) == "typing_extensions-4.16.0-py3-none-any.whl"


def test_pip_failure_is_a_clear_packaging_error(tmp_path):
    missing = packaging.WheelRequest("scipy", "0.0.1")
    with pytest.raises(packaging.PackagingError,
                       match=r"pip could not download scipy==0\.0\.1 for platform tags win_amd64"):
        packaging.pip_download(missing, ("win_amd64",), str(tmp_path))
    assert list(tmp_path.iterdir()) == []


def test_every_platform_requests_only_scipy_at_the_installed_version():
    """No torch and none of what only torch needed; no numpy (Blender has it)."""
    for platform in packaging.PLATFORM_TARGETS:
        assert packaging.wheel_requests(platform) == [packaging.WheelRequest("scipy", SCIPY_VERSION)], platform
    assert SCIPY_VERSION == "1.17.1"  # the version EXPECTED_WHEELS and the manifest name
    assert not set(TORCH_AND_ITS_DEPENDENCIES) & set(packaging.SHIPPED_DISTRIBUTIONS)


def test_unknown_platform_is_input_error(tmp_path):
    with pytest.raises(InputError, match="Unknown platform\\(s\\) linux-arm64; choose from linux-x64, windows-x64, "
                                         "macos-x64, macos-arm64"):
        packaging.build_packages(str(tmp_path), ["linux-arm64"])
    with pytest.raises(InputError, match="No platform given"):
        packaging.build_packages(str(tmp_path), [])


def test_blender_builder_errors_are_surfaced(tmp_path):
    stage = tmp_path / "stage"
    stage.mkdir()
    (stage / "__init__.py").write_text("")
    manifest = packaging.MANIFEST_PATH.read_text()
    manifest = packaging.manifest_text(manifest, [LINUX], []).replace('"Rigging"', '"Not A Blender Tag"')
    (stage / packaging.MANIFEST_FILENAME).write_text(manifest)
    with pytest.raises(packaging.PackagingError, match="Blender's extension builder failed:\n.*Not A Blender Tag"):
        packaging.run_blender_builder(str(stage), str(tmp_path / "out"), [LINUX])
