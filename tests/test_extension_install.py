"""The real Linux x64 extension zip, installed into a headless Blender that
has no torch, skins a character with the Skin operator's default method.

The zip is built the documented way (``packaging.build_packages``): the
scipy wheel comes from the wheel cache or, on a clean machine, from pip's
configured sources (PyPI). A failed download fails the test with pip's
message; it is never skipped.

Every Blender session runs in a subprocess whose first statement puts a
finder at the front of ``sys.meta_path`` that refuses ``torch`` and
``torch.*``, as a Blender without torch would, and records who asked.
The block refuses torch and records every attempt whether or not torch is
installed, so the sessions prove the same in .venv (where torch is on
``sys.path`` and only the block stops it) and in an environment without
torch, where this test must pass too.
"""

import json
import os
import shutil
import subprocess
import sys
import tomllib
import zipfile

import numpy as np
import pytest

from autorig_addon import packaging

pytestmark = pytest.mark.all_blenders

LINUX = "linux-x64"
ADDON_MODULE = "bl_ext.user_default.autorig_addon"
RESULT_PREFIX = "RESULT_JSON:"
TESTS_DIRECTORY = os.path.dirname(os.path.abspath(__file__))
#: Issue 18 keeps every zip under 40 MB. The Windows zip is the largest: its
#: scipy wheel is 1.26 MB larger than Linux's (docs/packaging.md), so the
#: Linux zip built here must stay under 40 - 1.26 MB (torch made it 234 MB).
LINUX_ZIP_SIZE_LIMIT = 38_700_000
#: Seconds one Blender session may take (bpy start, unpacking, skinning).
SESSION_TIMEOUT_SECONDS = 300
#: Row sums of the written vertex groups (float32 in Blender) equal 1 to this.
ROW_SUM_TOLERANCE = 1e-6
#: Vertices below this height (the lower half of the lower bone, z from 0
#: to 1) count as "lower"; the lowest ring sits at z = 0.
LOWER_REGION_TOP = 0.5
#: Their mean weight on the lower bone must reach this.
LOWER_REGION_MEAN_WEIGHT = 0.9

# Runs first in every session: Blender without torch.
BLOCK_TORCH = '''
import importlib.abc, importlib.machinery, sys

TORCH_ATTEMPTS = []


class _NoTorch(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name == "torch" or name.startswith("torch."):
            caller = next((f.f_globals.get("__name__") for f in _frames() if not _is_import_machinery(f)), None)
            TORCH_ATTEMPTS.append([name, caller])
            raise ModuleNotFoundError(f"No module named {name!r} (this Blender has no torch)", name=name)
        return None


def _frames():
    frame = sys._getframe(2)
    while frame is not None:
        yield frame
        frame = frame.f_back


def _is_import_machinery(frame):
    return frame.f_globals.get("__name__", "").startswith(("importlib", "_frozen_importlib"))


sys.meta_path.insert(0, _NoTorch())


def torch_report():
    """What this session proves about torch, for the test to assert."""
    attempts = list(TORCH_ATTEMPTS)  # before the probe below adds its own
    try:
        import torch  # noqa: F401
        import_error = None
    except ImportError as error:
        import_error = str(error)
    return {
        "torch_attempts": attempts,
        "torch_import_error": import_error,
        "torch_in_sys_modules": sorted(m for m in sys.modules if m == "torch" or m.startswith("torch.")),
        "torch_on_sys_path": importlib.machinery.PathFinder.find_spec("torch") is not None,
    }
'''

INSTALL_SCRIPT = BLOCK_TORCH + """
import json
import bpy

zip_path = sys.argv[1]
result = bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
module = sys.modules.get({module!r})
print({prefix!r} + json.dumps({{
    "result": sorted(result),
    "enabled": {module!r} in bpy.context.preferences.addons.keys(),
    "module_file": getattr(module, "__file__", None),
    "version": getattr(module, "__version__", None),
    "extensions_dir": bpy.utils.user_resource("EXTENSIONS"),
    "has_operator": hasattr(bpy.ops.autorig, "skin_weights"),
    **torch_report(),
}}))
""".format(module=ADDON_MODULE, prefix=RESULT_PREFIX)

# A fresh session, as after restarting Blender: the extension's wheel folder
# now comes before the environment's site-packages, so scipy loads from the
# shipped wheel. The scene comes from tests/blender_fixtures.py (bpy and
# numpy only; the repository's add-on is never imported here).
SKIN_SCRIPT = BLOCK_TORCH + """
import json
import bpy
import addon_utils

addon_utils.enable({module!r}, default_set=True)
sys.path.insert(0, {tests!r})
import blender_fixtures as fx

armature = fx.make_armature("Rig")
vertices, faces = fx.cylinder_geometry(fx.BODY_RADIUS, 0.0, fx.BODY_HEIGHT, 24, 20, capped=True)
body = fx.mesh_object("Body", vertices, faces)
bpy.context.view_layer.update()

operator = bpy.ops.autorig.skin_weights
defaults = {{p.identifier: getattr(p, "default", None) for p in operator.get_rna_type().properties
            if p.identifier.startswith("skin_")}}
skinned = operator(armature="Rig", meshes="Body")
sleeve, _, _ = fx.make_sleeve(with_button=False)
bpy.context.view_layer.update()
transferred = bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve")

# Auto-Rig on a bare tube: the skeleton networks and the learned skin, numpy only.
tube_vertices, tube_faces = fx.cylinder_geometry(fx.BODY_RADIUS, 0.0, fx.BODY_HEIGHT, 24, 20, capped=True)
tube = fx.mesh_object("Tube", tube_vertices, tube_faces)
bpy.ops.object.select_all(action="DESELECT")
tube.select_set(True)
bpy.context.view_layer.objects.active = tube
rigged = bpy.ops.autorig.auto_rig()
tube_armatures = [m.object for m in tube.modifiers if m.type == "ARMATURE"]
tube_bones = [b.name for b in tube_armatures[0].data.bones] if tube_armatures else []

import scipy
bones = [fx.LOWER_BONE, fx.UPPER_BONE]
print({prefix!r} + json.dumps({{
    "skin_result": sorted(skinned),
    "transfer_result": sorted(transferred),
    "operator_defaults": defaults,
    "body_groups": sorted(g.name for g in body.vertex_groups),
    "body_heights": fx.local_positions(body)[:, 2].tolist(),
    "body_weights": fx.group_weights(body, bones).tolist(),
    "sleeve_heights": fx.local_positions(sleeve)[:, 2].tolist(),
    "sleeve_weights": fx.group_weights(sleeve, bones).tolist(),
    "armature_modifier": [m.object.name for m in body.modifiers if m.type == "ARMATURE"],
    "rig_result": sorted(rigged),
    "tube_bones": tube_bones,
    "tube_weights": fx.group_weights(tube, tube_bones).tolist() if tube_bones else [],
    "scipy_file": scipy.__file__,
    "addon_file": sys.modules[{module!r}].__file__,
    "repository_addon_loaded": "autorig_addon" in sys.modules,
    **torch_report(),
}}))
""".format(module=ADDON_MODULE, prefix=RESULT_PREFIX, tests=TESTS_DIRECTORY)


@pytest.fixture(scope="module")
def linux_zip(tmp_path_factory):
    out_dir = tmp_path_factory.mktemp("dist")
    try:
        zips = packaging.build_packages(str(out_dir), [LINUX])
    except packaging.PackagingError as error:
        pytest.fail(f"Could not build the linux-x64 extension zip; the machine needs PyPI (pip's configured "
                    f"sources) to fetch scipy on a first build.\n{error}")
    assert len(zips) == 1
    yield zips[0]
    shutil.rmtree(out_dir, ignore_errors=True)


@pytest.fixture
def blender_user_dir(tmp_path):
    yield tmp_path
    # The unpacked scipy takes about 100 MB; do not leave it behind.
    shutil.rmtree(tmp_path / "blender", ignore_errors=True)


def _run_blender_script(script: str, user_dir, *args) -> dict:
    script_path = user_dir / "script.py"
    script_path.write_text(script)
    env = {k: v for k, v in os.environ.items() if not k.startswith("BLENDER_USER_") and k != "PYTHONPATH"}
    # Every user folder (config, scripts, extensions) goes under user_dir, so
    # the real ~/.config/blender is never touched.
    env["BLENDER_USER_RESOURCES"] = str(user_dir / "blender")
    completed = subprocess.run(
        [sys.executable, str(script_path), *args],
        capture_output=True, text=True, env=env, cwd=str(user_dir), stdin=subprocess.DEVNULL,
        timeout=SESSION_TIMEOUT_SECONDS,
    )
    lines = [line for line in completed.stdout.splitlines() if line.startswith(RESULT_PREFIX)]
    assert completed.returncode == 0 and lines, (
        f"Blender script failed (exit {completed.returncode}):\n{completed.stdout[-3000:]}\n{completed.stderr[-3000:]}"
    )
    return json.loads(lines[-1][len(RESULT_PREFIX):])


def _assert_torch_unimportable(session: dict) -> None:
    # The import fails (with torch installed, only the block stops it), and nothing tried it.
    assert session["torch_import_error"] == "No module named 'torch' (this Blender has no torch)"
    assert session["torch_in_sys_modules"] == []
    assert session["torch_attempts"] == [], "something inside Blender tried to import torch"


def test_linux_zip_contents_and_size(linux_zip):
    version = tomllib.loads(packaging.MANIFEST_PATH.read_text())["version"]
    assert os.path.basename(linux_zip) == f"autorig_addon-{version}-linux_x64.zip"
    assert os.path.getsize(linux_zip) < LINUX_ZIP_SIZE_LIMIT
    with zipfile.ZipFile(linux_zip) as archive:
        names = set(archive.namelist())
        manifest = tomllib.loads(archive.read("blender_manifest.toml").decode())
    assert {"blender_manifest.toml", "LICENSE", "CREDITS.md", "__init__.py", "core/types.py",
            "core/nn/layers.py"} <= names
    assert not any("__pycache__" in name or name.endswith(".pyc") for name in names)
    assert not any(name.startswith("training/") for name in names), "training code shipped"
    wheels = sorted(name for name in names if name.startswith("wheels/"))
    assert wheels == ["wheels/scipy-1.17.1-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl"]
    # Blender's builder records the platform; the wheel list names exactly the files shipped.
    assert manifest["build"]["generated"]["platforms"] == [LINUX]
    assert sorted(w[2:] for w in manifest["wheels"]) == wheels
    # The repository manifest already lists every wheel a build ships (no drift).
    repo_wheels = tomllib.loads(packaging.MANIFEST_PATH.read_text())["wheels"]
    assert set(manifest["wheels"]) <= set(repo_wheels)


def test_installed_zip_skins_without_torch(linux_zip, blender_user_dir):
    user_dir = blender_user_dir
    installed = _run_blender_script(INSTALL_SCRIPT, user_dir, linux_zip)
    assert installed["result"] == ["FINISHED"]
    assert installed["enabled"] and installed["has_operator"]
    assert installed["extensions_dir"].startswith(os.path.realpath(user_dir))
    expected = os.path.join(installed["extensions_dir"], "user_default", "autorig_addon", "__init__.py")
    assert os.path.realpath(installed["module_file"]) == os.path.realpath(expected)
    # The installed package reads its version from the manifest beside it.
    assert installed["version"] == tomllib.loads(packaging.MANIFEST_PATH.read_text())["version"]
    _assert_torch_unimportable(installed)

    used = _run_blender_script(SKIN_SCRIPT, user_dir)
    defaults = used["operator_defaults"]
    assert used["skin_result"] == ["FINISHED"], defaults
    _assert_torch_unimportable(used)
    # The installed copy and the shipped scipy ran, not the repository's.
    assert os.path.realpath(used["addon_file"]) == os.path.realpath(expected)
    assert not used["repository_addon_loaded"]
    site_packages = os.path.join(installed["extensions_dir"], ".local", "lib")
    assert os.path.realpath(used["scipy_file"]).startswith(os.path.realpath(site_packages))

    assert used["body_groups"] == ["Lower", "Upper"]
    assert used["armature_modifier"] == ["Rig"]
    heights = np.array(used["body_heights"])
    weights = np.array(used["body_weights"])
    assert weights.shape == (24 * 21 + 2, 2)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=ROW_SUM_TOLERANCE, err_msg=str(defaults))
    lower = heights < LOWER_REGION_TOP
    assert lower.sum() >= 5 * 24
    assert (weights[lower, 0] > weights[lower, 1]).all(), (defaults, weights[lower])
    assert weights[lower, 0].mean() >= LOWER_REGION_MEAN_WEIGHT, defaults
    assert (weights[heights > 2.0 - LOWER_REGION_TOP, 1] > 0.5).all(), defaults

    # The skinned body is a transfer source inside the same Blender.
    assert used["transfer_result"] == ["FINISHED"]
    sleeve = np.array(used["sleeve_weights"])
    np.testing.assert_allclose(sleeve.sum(axis=1), 1.0, atol=ROW_SUM_TOLERANCE)
    sleeve_lower = np.array(used["sleeve_heights"]) < LOWER_REGION_TOP
    assert sleeve_lower.any() and (sleeve[sleeve_lower, 0] > sleeve[sleeve_lower, 1]).all()

    # Auto-Rig predicted a skeleton and bound the tube, without torch.
    assert used["rig_result"] == ["FINISHED"]
    assert len(used["tube_bones"]) >= 2
    np.testing.assert_allclose(np.array(used["tube_weights"]).sum(axis=1), 1.0, atol=ROW_SUM_TOLERANCE)
