"""Shared pytest fixtures.

Blender-backed fixtures import ``bpy`` lazily, so test modules that only
exercise ``core`` never load Blender.
"""

from pathlib import Path

import pytest

REPOSITORY_ROOT = Path(__file__).resolve().parent.parent


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
