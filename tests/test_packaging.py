"""Extension packaging: manifest rewriting, Blender's builder, and a real
install of the Linux x64 zip into a throw-away headless Blender user folder.

The install test downloads scipy and its pure-Python companions from PyPI
and takes the CPU torch wheel from pip's find-links (or PyTorch's CPU index)
on its first run; later runs reuse the wheel cache.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap
import tomllib
import zipfile

import pytest

from autorig_addon import packaging
from autorig_addon.core.errors import InputError

LINUX = "linux-x64"
ADDON_MODULE = "bl_ext.user_default.autorig_addon"
RESULT_PREFIX = "RESULT_JSON:"


# ----------------------------------------------------------------- fast checks


def test_repo_manifest_is_complete():
    manifest = tomllib.loads(packaging.MANIFEST_PATH.read_text())
    assert manifest["id"] == "autorig_addon"
    assert manifest["type"] == "add-on"
    assert manifest["blender_version_min"] == "4.2.0"
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    assert len(manifest["tagline"]) < 64 and manifest["tagline"][-1].isalnum()
    assert set(manifest["platforms"]) == set(packaging.PLATFORM_TARGETS)
    wheels = manifest["wheels"]
    assert all(w.startswith("./wheels/") and w.endswith(".whl") for w in wheels)
    assert not any(os.path.basename(w).startswith("numpy-") for w in wheels), "Blender bundles numpy"
    # Each platform ships scipy and torch; the Linux torch is the CPU build.
    for tag in ("manylinux", "win_amd64", "macosx"):
        names = [os.path.basename(w) for w in wheels if tag in w]
        assert sorted(n.split("-")[0] for n in names) == ["scipy", "torch"], tag
    assert any(w.startswith("./wheels/torch-2.13.0+cpu-") and "manylinux" in w for w in wheels)
    with open(packaging.ADDON_DIR / "__init__.py") as handle:
        assert f'__version__ = "{manifest["version"]}"' in handle.read()


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
    text = packaging.manifest_text(source, ["macos-arm64"], ["a-1.0-py3-none-any.whl", "b-2.0-cp311-cp311-win_amd64.whl"])
    parsed = tomllib.loads(text)
    assert parsed["platforms"] == ["macos-arm64"]
    assert parsed["wheels"] == ["./wheels/a-1.0-py3-none-any.whl", "./wheels/b-2.0-cp311-cp311-win_amd64.whl"]
    assert parsed["permissions"] == {"files": "Import/export rigs"}
    assert "# a comment that must survive" in text
    with pytest.raises(packaging.PackagingError, match="'wheels = \\[...\\]' exactly once, found 0"):
        packaging.manifest_text('platforms = ["linux-x64"]\n', ["linux-x64"], [])


def test_cached_wheel_matches_name_and_exact_version(tmp_path):
    for name in ("torch-2.13.0-cp311-cp311-win_amd64.whl", "typing_extensions-4.16.0-py3-none-any.whl", "notes.txt"):
        (tmp_path / name).write_bytes(b"")
    cpu = packaging.WheelRequest("torch", "2.13.0+cpu")
    assert packaging.cached_wheel(str(tmp_path), cpu) is None  # a CUDA/other build never stands in
    assert packaging.cached_wheel(str(tmp_path), packaging.WheelRequest("torch", "2.13.0")).endswith("win_amd64.whl")
    found = packaging.cached_wheel(str(tmp_path), packaging.WheelRequest("typing-extensions", "4.16.0"))
    assert os.path.basename(found) == "typing_extensions-4.16.0-py3-none-any.whl"


def test_pip_failure_is_a_clear_packaging_error(tmp_path):
    missing = packaging.WheelRequest("scipy", "0.0.1")
    with pytest.raises(packaging.PackagingError, match=r"pip could not download scipy==0\.0\.1 for platform tags win_amd64"):
        packaging.pip_download(missing, ("win_amd64",), str(tmp_path))
    assert list(tmp_path.iterdir()) == []


def test_wheel_requests_pin_linux_torch_to_cpu_build():
    linux = {r.distribution: r for r in packaging.wheel_requests(LINUX)}
    assert linux["torch"].version == "2.13.0+cpu"
    assert linux["torch"].fallback_index_url == packaging.PYTORCH_CPU_INDEX_URL
    windows = {r.distribution: r for r in packaging.wheel_requests("windows-x64")}
    assert windows["torch"].version == "2.13.0" and windows["torch"].fallback_index_url is None
    assert set(linux) == {"scipy", "torch", "typing_extensions", "sympy", "mpmath"}
    assert "numpy" not in linux


def test_unknown_platform_is_input_error(tmp_path):
    with pytest.raises(InputError, match="Unknown platform\\(s\\) macos-x64; choose from linux-x64, windows-x64, macos-arm64"):
        packaging.build_packages(str(tmp_path), ["macos-x64"])
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


# ------------------------------------------------------- build, install, use

INSTALL_SCRIPT = """
import json, sys
import bpy

zip_path = sys.argv[1]
result = bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
module = sys.modules.get({module!r})
print({prefix!r} + json.dumps({{
    "result": sorted(result),
    "enabled": {module!r} in bpy.context.preferences.addons.keys(),
    "module_file": getattr(module, "__file__", None),
    "extensions_dir": bpy.utils.user_resource("EXTENSIONS"),
    "has_operator": hasattr(bpy.ops.autorig, "transfer_weights"),
}}))
""".format(module=ADDON_MODULE, prefix=RESULT_PREFIX)

# A fresh session (as after restarting Blender): the extension's wheel
# folder now precedes the environment's site-packages, so torch and scipy
# load from the shipped wheels.
USE_SCRIPT = """
import json, sys
import bpy
import addon_utils
import numpy as np

addon_utils.enable({module!r}, default_set=True)
import scipy, torch

SEGMENTS, RINGS = 16, 21


def tube(name, radius, z_bottom, z_top):
    angles = np.linspace(0.0, 2.0 * np.pi, SEGMENTS, endpoint=False)
    heights = np.linspace(z_bottom, z_top, RINGS)
    vertices = [(radius * np.cos(a), radius * np.sin(a), z) for z in heights for a in angles]
    faces = [
        (k * SEGMENTS + s, k * SEGMENTS + (s + 1) % SEGMENTS,
         (k + 1) * SEGMENTS + (s + 1) % SEGMENTS, (k + 1) * SEGMENTS + s)
        for k in range(RINGS - 1) for s in range(SEGMENTS)
    ]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


armature_data = bpy.data.armatures.new("Rig")
armature = bpy.data.objects.new("Rig", armature_data)
bpy.context.scene.collection.objects.link(armature)
bpy.context.view_layer.objects.active = armature
bpy.ops.object.mode_set(mode="EDIT")
lower = armature_data.edit_bones.new("lower")
lower.head, lower.tail = (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)
upper = armature_data.edit_bones.new("upper")
upper.head, upper.tail = (0.0, 0.0, 1.0), (0.0, 0.0, 2.0)
upper.parent = lower
bpy.ops.object.mode_set(mode="OBJECT")

body = tube("Body", 0.3, 0.0, 2.0)
heights = np.array([v.co.z for v in body.data.vertices])
upper_weight = np.clip((heights - 0.8) / 0.4, 0.0, 1.0)
groups = {{name: body.vertex_groups.new(name=name) for name in ("lower", "upper")}}
for index, w in enumerate(upper_weight.tolist()):
    groups["upper"].add([index], w, "REPLACE")
    groups["lower"].add([index], 1.0 - w, "REPLACE")
body.parent = armature
body.modifiers.new("Armature", "ARMATURE").object = armature

sleeve = tube("Sleeve", 0.35, 0.1, 1.9)
bpy.context.view_layer.update()
result = bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve")

sleeve_groups = {{g.index: g.name for g in sleeve.vertex_groups}}
weights = {{"lower": [0.0] * len(sleeve.data.vertices), "upper": [0.0] * len(sleeve.data.vertices)}}
for vertex in sleeve.data.vertices:
    for element in vertex.groups:
        name = sleeve_groups[element.group]
        if name in weights:
            weights[name][vertex.index] = element.weight
print({prefix!r} + json.dumps({{
    "result": sorted(result),
    "torch_file": torch.__file__,
    "scipy_file": scipy.__file__,
    "addon_file": sys.modules[{module!r}].__file__,
    "group_names": sorted(sleeve_groups.values()),
    "heights": [v.co.z for v in sleeve.data.vertices],
    "lower": weights["lower"],
    "upper": weights["upper"],
}}))
""".format(module=ADDON_MODULE, prefix=RESULT_PREFIX)


@pytest.fixture(scope="module")
def linux_zip(tmp_path_factory):
    out_dir = tmp_path_factory.mktemp("dist")
    try:
        zips = packaging.build_packages(str(out_dir), [LINUX])
    except packaging.PackagingError as error:
        pytest.fail(
            "Could not build the linux-x64 extension zip. If pip failed, the machine needs PyPI access "
            f"(and the torch CPU wheel in pip's find-links or {packaging.PYTORCH_CPU_INDEX_URL}).\n{error}"
        )
    assert len(zips) == 1
    yield zips[0]
    shutil.rmtree(out_dir, ignore_errors=True)


def _run_blender_script(script: str, user_dir, *args) -> dict:
    script_path = user_dir / "script.py"
    script_path.write_text(script)
    env = {k: v for k, v in os.environ.items() if not k.startswith("BLENDER_USER_")}
    # Every user folder (config, scripts, extensions) goes under user_dir, so
    # the real ~/.config/blender is never touched.
    env["BLENDER_USER_RESOURCES"] = str(user_dir / "blender")
    completed = subprocess.run(
        [sys.executable, str(script_path), *args],
        capture_output=True, text=True, env=env, cwd=str(user_dir), stdin=subprocess.DEVNULL, timeout=600,
    )
    lines = [line for line in completed.stdout.splitlines() if line.startswith(RESULT_PREFIX)]
    assert completed.returncode == 0 and lines, (
        f"Blender script failed (exit {completed.returncode}):\n{completed.stdout[-3000:]}\n{completed.stderr[-3000:]}"
    )
    return json.loads(lines[-1][len(RESULT_PREFIX):])


def test_linux_zip_contents(linux_zip):
    assert os.path.basename(linux_zip) == "autorig_addon-0.1.0-linux_x64.zip"
    with zipfile.ZipFile(linux_zip) as archive:
        names = set(archive.namelist())
        manifest = tomllib.loads(archive.read("blender_manifest.toml").decode())
    assert {"blender_manifest.toml", "__init__.py", "core/types.py", "core/io/rignet_rig.py"} <= names
    assert not any("__pycache__" in name or name.endswith(".pyc") for name in names)
    wheels = sorted(name for name in names if name.startswith("wheels/"))
    assert [w.split("/")[1].split("-")[0] for w in wheels] == ["mpmath", "scipy", "sympy", "torch", "typing_extensions"]
    torch_wheel = next(w for w in wheels if w.startswith("wheels/torch-"))
    assert torch_wheel == "wheels/torch-2.13.0+cpu-cp311-cp311-manylinux_2_28_x86_64.whl"
    assert all("win_amd64" not in w and "macosx" not in w for w in wheels)
    # Blender's builder records the platform; the wheel list names exactly the files shipped.
    assert manifest["build"]["generated"]["platforms"] == [LINUX]
    assert sorted(w[2:] for w in manifest["wheels"]) == wheels
    # The repository manifest already lists every wheel a build ships (no drift).
    repo_wheels = tomllib.loads(packaging.MANIFEST_PATH.read_text())["wheels"]
    assert set(manifest["wheels"]) <= set(repo_wheels)


@pytest.fixture
def blender_user_dir(tmp_path):
    yield tmp_path
    # The unpacked torch and scipy take about 1 GB; do not leave them behind.
    shutil.rmtree(tmp_path / "blender", ignore_errors=True)


def test_install_into_headless_blender_and_transfer(linux_zip, blender_user_dir):
    tmp_path = blender_user_dir
    installed = _run_blender_script(INSTALL_SCRIPT, tmp_path, linux_zip)
    assert installed["result"] == ["FINISHED"]
    assert installed["enabled"]
    assert installed["has_operator"]
    user_dir = os.path.realpath(tmp_path)
    assert installed["extensions_dir"].startswith(user_dir)
    # The installed copy runs, not the repository's sources.
    expected = os.path.join(installed["extensions_dir"], "user_default", "autorig_addon", "__init__.py")
    assert os.path.realpath(installed["module_file"]) == os.path.realpath(expected)

    used = _run_blender_script(USE_SCRIPT, tmp_path)
    assert used["result"] == ["FINISHED"]
    site_packages = os.path.join(installed["extensions_dir"], ".local", "lib")
    assert os.path.realpath(used["torch_file"]).startswith(os.path.realpath(site_packages))
    assert os.path.realpath(used["scipy_file"]).startswith(os.path.realpath(site_packages))
    assert os.path.realpath(used["addon_file"]) == os.path.realpath(expected)
    assert {"lower", "upper"} <= set(used["group_names"])

    import numpy as np

    heights = np.array(used["heights"])
    lower = np.array(used["lower"])
    upper = np.array(used["upper"])
    np.testing.assert_allclose(lower + upper, 1.0, atol=1e-4)
    bottom, top = heights < 0.6, heights > 1.4
    assert bottom.sum() >= 16 and top.sum() >= 16
    assert lower[bottom].min() > 0.9, lower[bottom]
    assert upper[top].min() > 0.9, upper[top]
    # Through the blend zone the weights follow the body's ramp (upper bone
    # from 0 at z = 0.8 to 1 at z = 1.2).
    np.testing.assert_allclose(upper, np.clip((heights - 0.8) / 0.4, 0.0, 1.0), atol=0.05)
    np.testing.assert_allclose(upper[np.abs(heights - 1.0) < 1e-6], 0.5, atol=0.02)
