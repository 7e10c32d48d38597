"""``autorig_addon.core`` must import and run without Blender."""

import pkgutil
import subprocess
import sys
from pathlib import Path

import autorig_addon.core

REPOSITORY_ROOT = Path(__file__).resolve().parent.parent


def test_every_core_module_imports_without_bpy():
    modules = [f"autorig_addon.core.{info.name}" for info in pkgutil.iter_modules(autorig_addon.core.__path__)]
    assert "autorig_addon.core.transfer" in modules and len(modules) > 10
    script = (
        "import importlib, sys\n"
        f"for name in {modules!r}:\n"
        "    importlib.import_module(name)\n"
        "print(sorted(m for m in sys.modules if m == 'bpy' or m.startswith('bpy.') or m == 'mathutils'))\n"
    )
    result = subprocess.run([sys.executable, "-c", script], cwd=REPOSITORY_ROOT, capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"
