"""AutoRig: automatic rigging, skinning and robust weight transfer for Blender.

The package imports without Blender: ``core`` is plain numpy/scipy and
``blender`` (operators, panels, conversion) is imported only by ``register``.
"""

__version__ = "0.1.0"


def register():
    from .blender import register as register_blender

    register_blender()


def unregister():
    from .blender import unregister as unregister_blender

    unregister_blender()
