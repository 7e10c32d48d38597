"""Shared pytest fixtures.

Blender-backed fixtures import ``bpy`` lazily, so test modules that only
exercise ``core`` never load Blender.
"""

import os
import sys
from pathlib import Path

import pytest

REPOSITORY_ROOT = Path(__file__).resolve().parent.parent

#: (major, minor) of the bpy modules that do not exit cleanly after the tests:
#: bpy 4.2 crashes when the interpreter exits once a class with a Python
#: property callback (``update``, ``poll``) has been registered, even after
#: unregistering it: its static destructors free Python objects after Python
#: has shut down (``bpy_class_free`` in ``~SpaceType``, segmentation fault; a
#: one-property group with an ``update`` callback does it, and the add-on's
#: scene settings have such callbacks). bpy 4.5 never finishes exiting once
#: Rigify has generated a rig (a plain script that generates one and returns
#: hangs the same way, with only the main Python thread left). Bugs of the
#: modules, not the add-on's; bpy 5.0 exits cleanly.
BPY_CRASHING_AT_EXIT = {(4, 2), (4, 5)}
_EXIT_STATUS = pytest.StashKey[int]()


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session, exitstatus):
    session.config.stash[_EXIT_STATUS] = int(exitstatus)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    """Under a bpy of :data:`BPY_CRASHING_AT_EXIT`, end the process with the
    session's exit status once everything is reported, before that crash
    would replace it."""
    bpy = sys.modules.get("bpy")
    if bpy is None or tuple(bpy.app.version[:2]) not in BPY_CRASHING_AT_EXIT or _EXIT_STATUS not in config.stash:
        return
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(config.stash[_EXIT_STATUS])


@pytest.fixture(scope="session")
def repository_root() -> Path:
    """The repository's top folder (the working directory of subprocess tests)."""
    return REPOSITORY_ROOT


@pytest.fixture(scope="session")
def registered_addon():
    """The add-on registered once for the whole session (bpy imported here)."""
    import bpy  # noqa: F401  (loads Blender before the add-on's modules)

    import autorig_addon

    autorig_addon.register()
    yield autorig_addon
    autorig_addon.unregister()


@pytest.fixture
def clean_scene(registered_addon):
    """An empty factory-settings scene, with the add-on registered."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy.context.scene
    bpy.ops.wm.read_factory_settings(use_empty=True)


@pytest.fixture(autouse=True)
def one_torch_thread(request):
    """Tests marked ``torch`` run torch on one thread: their inputs are
    small, and two threads on a busy 2-core machine are many times slower
    than one. Other tests never load torch here; where torch cannot be
    imported (the suite's second pass) a torch test is skipped here, before
    its body could skip itself."""
    if request.node.get_closest_marker("torch") is None:
        yield
        return
    torch = pytest.importorskip("torch")

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


@pytest.fixture
def read_as_other(monkeypatch):
    """The landmark network's points, but every body read as "other" (as
    Kenney's chibi minis are, up to 100 % sure): what a body's nearest known
    body then tells is the only kind it has."""
    from dataclasses import replace

    from autorig_addon.core.rigging import predict

    network = predict.predict_landmarks
    monkeypatch.setattr(predict, "predict_landmarks", lambda graph: replace(
        network(graph), kind_probabilities={"biped": 0.05, "quadruped": 0.05, "other": 0.9}))
