"""Blender glue: operators, panels, properties and conversion to core arrays.

Imported only from ``autorig_addon.register`` (or by tests and the command
line), never from ``core``. Each UI module exposes a ``classes`` tuple,
registered in :data:`_MODULE_NAMES` order and unregistered in reverse; later
features add their module name to that list. A module may also define
``register_extras()`` / ``unregister_extras()`` (menu entries and the like).
"""

import importlib

import bpy

#: Modules with a ``classes`` tuple, in registration order (property groups
#: before the operators and panels that use them).
_MODULE_NAMES = ("ui.properties", "operators.transfer", "operators.skin", "operators.rignet", "operators.rig",
                 "operators.bone_names", "ui.panels")


def _modules():
    return [importlib.import_module(f".{name}", __name__) for name in _MODULE_NAMES]


def _all_classes():
    return [cls for module in _modules() for cls in module.classes]


def register() -> None:
    """Register every class and ``Scene.autorig``; calling it twice is harmless."""
    for cls in _all_classes():
        if not getattr(cls, "is_registered", False):
            bpy.utils.register_class(cls)
    from .ui.properties import register_scene_properties

    register_scene_properties()
    for module in _modules():
        if hasattr(module, "register_extras") and not getattr(module, "_extras_registered", False):
            module.register_extras()
            module._extras_registered = True


def unregister() -> None:
    """Undo :func:`register`; calling it when not registered is harmless."""
    from .ui.properties import unregister_scene_properties

    unregister_scene_properties()
    for module in reversed(_modules()):
        if getattr(module, "_extras_registered", False):
            module.unregister_extras()
            module._extras_registered = False
    for cls in reversed(_all_classes()):
        if getattr(cls, "is_registered", False):
            bpy.utils.unregister_class(cls)
