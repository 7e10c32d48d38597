"""Import guards: ``autorig_addon.core`` never loads Blender, and nothing the
add-on loads when Blender registers it loads torch.

torch is for training only: the torch-importing modules are those of the
training package ``autorig_addon.training``, which imports from ``core``
and never the reverse. Every module Blender may load (``core``,
``blender``) must import without torch and must not name torch or the
training package in any import (a lazy import inside a function included),
and the extension zip leaves the training package out.

Each import check runs in a fresh interpreter, so modules this test session
already imported cannot hide an import.
"""

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

from autorig_addon import packaging

#: The training package, as an absolute module name (the one folder the zip leaves out).
TRAINING_MODULE = "autorig_addon.training"
#: Its modules that need numpy alone (training sets built without torch).
NUMPY_TRAINING_MODULES = ("autorig_addon.training.rigging.training_set",
                          "autorig_addon.training.skinning.learned.training_set")

# Imports every module of some packages, recursively, except the skipped
# sub-packages (not even their __init__), then prints which of the watched
# top-level modules got loaded.
IMPORT_ALL_SCRIPT = """
import importlib, json, pkgutil, sys

packages, watched, register = sys.argv[1].split(","), sys.argv[2].split(","), sys.argv[3] == "register"
skipped = set(filter(None, sys.argv[4].split(",")))
names = []

def import_tree(package_name):
    package = importlib.import_module(package_name)
    names.append(package_name)
    for info in pkgutil.iter_modules(package.__path__, package_name + "."):
        if info.name in skipped:
            continue
        if info.ispkg:
            import_tree(info.name)
        else:
            importlib.import_module(info.name)
            names.append(info.name)

for package_name in packages:
    import_tree(package_name)
if register:
    import autorig_addon
    autorig_addon.register()
loaded = sorted(name for name in sys.modules if name.split(".")[0] in watched)
print(json.dumps({"modules": names, "loaded": loaded}))
"""


def import_everything(repository_root, packages, watched, register=False, skipped=()) -> dict:
    result = subprocess.run(
        [sys.executable, "-c", IMPORT_ALL_SCRIPT, ",".join(packages), ",".join(watched),
         "register" if register else "-", ",".join(skipped)],
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
            "autorig_addon.core.errors", "autorig_addon.core.nn.graph",
            "autorig_addon.core.skinning.learned.networks.heterskinnet"} <= set(outcome["modules"])


@pytest.mark.torch
def test_every_training_module_imports_without_bpy(repository_root):
    pytest.importorskip("torch")
    outcome = import_everything(repository_root, [TRAINING_MODULE], ["bpy", "mathutils", "bmesh"])
    assert outcome["loaded"] == []
    assert {TRAINING_MODULE + ".nn.torch_kernels", TRAINING_MODULE + ".rigging.train",
            TRAINING_MODULE + ".command"} <= set(outcome["modules"])


def test_core_blender_and_register_never_import_torch(repository_root):
    outcome = import_everything(repository_root, ["autorig_addon.core", "autorig_addon.blender"], ["torch"],
                                register=True)
    assert outcome["loaded"] == []
    assert {"autorig_addon.blender.operators.transfer", "autorig_addon.blender.ui.properties",
            "autorig_addon.blender.ui.panels", "autorig_addon.core.nn.aggregation",
            "autorig_addon.core.nn.weights_io"} <= set(outcome["modules"])
    assert not [name for name in outcome["modules"] if name.startswith(TRAINING_MODULE)]


def imported_modules(path: Path, module_name: str) -> set:
    """Absolute names of every module an ``import`` in the file names, at any
    depth (imports inside functions included); for ``from X import a`` both
    ``X`` and ``X.a``."""
    is_package = path.name == "__init__.py"
    package_parts = module_name.split(".") if is_package else module_name.split(".")[:-1]
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base_parts = package_parts[: len(package_parts) - node.level + 1] if node.level else []
            base = ".".join(base_parts + ([node.module] if node.module else []))
            names.add(base)
            names.update(f"{base}.{alias.name}" for alias in node.names)
    return names


def addon_modules_blender_may_load(repository_root):
    """(path, module name) of every add-on source Blender may import: all but
    the command line and the training package."""
    addon = Path(repository_root) / "autorig_addon"
    for path in sorted(addon.rglob("*.py")):
        parts = path.relative_to(addon.parent).with_suffix("").parts
        module_name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        if module_name.startswith(("autorig_addon.cli", TRAINING_MODULE)):
            continue
        yield path, module_name


def test_no_module_outside_training_names_torch_or_the_training_package(repository_root):
    offenders = {}
    checked = 0
    for path, module_name in addon_modules_blender_may_load(repository_root):
        checked += 1
        bad = sorted(name for name in imported_modules(path, module_name)
                     if name.split(".")[0] == "torch" or name == TRAINING_MODULE
                     or name.startswith(TRAINING_MODULE + "."))
        if bad:
            offenders[module_name] = bad
    assert offenders == {}
    assert checked > 50


def test_import_scan_resolves_relative_imports(tmp_path):
    # The scan above must see a lazy relative import of the training package.
    module = tmp_path / "layers.py"
    module.write_text("def f():\n    from ...training.nn import fit\n    import torch.nn\n")
    names = imported_modules(module, "autorig_addon.core.nn.layers")
    assert {TRAINING_MODULE + ".nn", TRAINING_MODULE + ".nn.fit", "torch.nn"} <= names
    names = imported_modules(module, "autorig_addon.core.nn.sub.layers")
    assert "autorig_addon.core.training.nn" in names


def test_the_extension_leaves_the_training_package_out(tmp_path):
    assert "autorig_addon." + packaging.EXCLUDED_SOURCE_FOLDERS[0] == TRAINING_MODULE
    packaging.copy_addon_sources(str(tmp_path))
    assert (tmp_path / "core" / "nn" / "graph.py").is_file()
    assert (tmp_path / "core" / "nn" / "__init__.py").is_file()
    assert not (tmp_path / "training").exists()
    shipped = {path.relative_to(tmp_path).as_posix() for path in tmp_path.rglob("*.py")}
    sources = {path.relative_to(packaging.ADDON_DIR).as_posix() for path in packaging.ADDON_DIR.rglob("*.py")}
    assert sources - shipped == {name for name in sources if name.startswith("training/")}
    assert {"training/command.py", "training/nn/fit.py"} <= sources - shipped
    assert not list(tmp_path.rglob("__pycache__"))


def test_the_training_package_and_its_training_sets_import_without_torch(repository_root):
    # Listing the package (its __init__) must not load torch, nor building training examples.
    script = (f"import json, sys, {TRAINING_MODULE}, {', '.join(NUMPY_TRAINING_MODULES)}; "
              "print(json.dumps('torch' in sys.modules))")
    result = subprocess.run([sys.executable, "-c", script], cwd=repository_root, capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout.strip().splitlines()[-1]) is False


def test_command_line_help_imports_neither_bpy_nor_torch(repository_root):
    script = (
        "import json, sys\n"
        "from autorig_addon.cli.main import main\n"
        "names = ('transfer', 'skin', 'eval', 'package', 'train')\n"
        "codes = [main(['--help'])] + [main([name, '--help']) for name in names]\n"
        "loaded = sorted(m for m in sys.modules if m.split('.')[0] in ('bpy', 'torch'))\n"
        "print(json.dumps({'codes': codes, 'loaded': loaded}))\n"
    )
    result = subprocess.run([sys.executable, "-c", script], cwd=repository_root, capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    outcome = json.loads(result.stdout.strip().splitlines()[-1])
    assert outcome == {"codes": [0, 0, 0, 0, 0, 0], "loaded": []}
