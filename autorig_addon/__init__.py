"""AutoRig: automatic rigging, skinning and robust weight transfer for Blender.

The package imports without Blender: ``core`` is plain numpy/scipy and
``blender`` (operators, panels, conversion) is imported only by ``register``.
"""


def _manifest_version() -> str:
    """The ``version`` of ``blender_manifest.toml``, the one place it is
    written: the manifest sits next to this file inside the installed
    extension and one folder up in a source checkout (an editable install
    too); a wheel install has neither and reads its installed metadata."""
    import tomllib
    from pathlib import Path

    here = Path(__file__).resolve().parent
    for manifest in (here / "blender_manifest.toml", here.parent / "blender_manifest.toml"):
        if manifest.is_file():
            with manifest.open("rb") as handle:
                return tomllib.load(handle)["version"]
    import importlib.metadata

    try:
        return importlib.metadata.version("autorig_addon")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


__version__ = _manifest_version()


def register():
    from .blender import register as register_blender

    register_blender()


def unregister():
    from .blender import unregister as unregister_blender

    unregister_blender()
