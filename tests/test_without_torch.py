"""tests/without_torch/sitecustomize.py, which hides torch for the first
pass of scripts/test.sh: with that folder on PYTHONPATH a Python process,
and the processes it starts, behave as if torch were not installed, and
nothing else changes."""

import json
import os
import subprocess
import sys

WITHOUT_TORCH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "without_torch")

# Prints what the process sees of torch, its own and its child's.
PROBE = r"""
import importlib.metadata, importlib.util, json, subprocess, sys

def import_error(name):
    try:
        __import__(name)
    except ModuleNotFoundError as error:
        return [type(error).__name__, str(error), error.name]
    return None

def version(name):
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None

import numpy, scipy.sparse, autorig_addon
CHILD = "import importlib.util; print(importlib.util.find_spec('torch') is None)"
child = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, check=True)
print(json.dumps({
    "import_torch": import_error("torch"),
    "import_torch_nn": import_error("torch.nn"),
    "find_spec": [importlib.util.find_spec(name) is None for name in ("torch", "functorch", "torchgen")],
    "torch_version": version("torch"),
    "torch_listed": any(d.metadata["Name"] == "torch" for d in importlib.metadata.distributions()),
    "torch_loaded": sorted(m for m in sys.modules if m.split(".")[0] == "torch"),
    "scipy_version": version("scipy"),
    "numpy": numpy.__version__,
    "child_finds_no_torch": child.stdout.strip() == "True",
}))
"""


def _probe(pythonpath):
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    completed = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, env=env,
                               stdin=subprocess.DEVNULL, timeout=120)
    assert completed.returncode == 0, completed.stderr
    return json.loads(completed.stdout)


def test_torch_is_missing_where_the_folder_is_on_pythonpath():
    seen = _probe(WITHOUT_TORCH)
    assert seen["import_torch"] == ["ModuleNotFoundError", "No module named 'torch'", "torch"]
    assert seen["import_torch_nn"] == ["ModuleNotFoundError", "No module named 'torch'", "torch"]
    assert seen["find_spec"] == [True, True, True]
    assert seen["torch_version"] is None and not seen["torch_listed"]
    assert seen["torch_loaded"] == []
    assert seen["child_finds_no_torch"], "a subprocess with the same environment found torch"
    # Everything else is there: numpy, scipy and its metadata, the package.
    assert seen["numpy"] and seen["scipy_version"]


def test_without_the_folder_nothing_is_hidden():
    seen = _probe(None)
    # The same answers as the hidden run wherever torch is not installed.
    installed = seen["torch_version"] is not None
    assert (seen["import_torch"] is None) == installed
    assert seen["find_spec"][0] == (not installed)
    assert seen["child_finds_no_torch"] == (not installed)
    assert seen["numpy"] and seen["scipy_version"]
