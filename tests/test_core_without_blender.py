"""Import guards: ``autorig_addon.core`` never loads Blender, and nothing the
add-on loads when Blender registers it loads torch (which only the learned
networks need, on demand).

Each check runs in a fresh interpreter, so modules this test session already
imported cannot hide an import.
"""

import json
import subprocess
import sys

# Lists every module of a package, recursively, then imports them all and
# prints which of the watched top-level modules got loaded.
IMPORT_ALL_SCRIPT = """
import importlib, json, pkgutil, sys

packages, watched, register = sys.argv[1].split(","), sys.argv[2].split(","), sys.argv[3] == "register"
names = []
for package_name in packages:
    package = importlib.import_module(package_name)
    names.append(package_name)
    for info in pkgutil.walk_packages(package.__path__, package_name + "."):
        importlib.import_module(info.name)
        names.append(info.name)
if register:
    import autorig_addon
    autorig_addon.register()
loaded = sorted(name for name in sys.modules if name.split(".")[0] in watched)
print(json.dumps({"modules": names, "loaded": loaded}))
"""


def import_everything(repository_root, packages, watched, register=False) -> dict:
    result = subprocess.run(
        [sys.executable, "-c", IMPORT_ALL_SCRIPT, ",".join(packages), ",".join(watched), "register" if register else "-"],
        cwd=repository_root, capture_output=True, text=True, timeout=300,
    )
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout.strip().splitlines()[-1])


def test_every_core_module_imports_without_bpy(repository_root):
    outcome = import_everything(repository_root, ["autorig_addon.core"], ["bpy", "mathutils", "bmesh"])
    assert outcome["loaded"] == []
    # The walk reached the sub-packages' modules, not only the top level.
    assert {"autorig_addon.core.transfer.transfer", "autorig_addon.core.transfer.options",
            "autorig_addon.core.transfer.combine", "autorig_addon.core.weights",
            "autorig_addon.core.errors"} <= set(outcome["modules"])


def test_core_blender_and_register_never_import_torch(repository_root):
    outcome = import_everything(repository_root, ["autorig_addon.core", "autorig_addon.blender"], ["torch"],
                                register=True)
    assert outcome["loaded"] == []
    assert {"autorig_addon.blender.operators.transfer", "autorig_addon.blender.ui.properties",
            "autorig_addon.blender.ui.panels"} <= set(outcome["modules"])


def test_command_line_help_imports_neither_bpy_nor_torch(repository_root):
    script = (
        "import json, sys\n"
        "from autorig_addon.cli.main import main\n"
        "codes = [main(['--help'])] + [main([name, '--help']) for name in ('transfer', 'skin', 'eval', 'package')]\n"
        "print(json.dumps({'codes': codes, 'loaded': sorted(m for m in sys.modules if m.split('.')[0] in ('bpy', 'torch'))}))\n"
    )
    result = subprocess.run([sys.executable, "-c", script], cwd=repository_root, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    outcome = json.loads(result.stdout.strip().splitlines()[-1])
    assert outcome == {"codes": [0, 0, 0, 0, 0], "loaded": []}
