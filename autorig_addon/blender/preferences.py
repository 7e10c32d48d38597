"""Add-on preferences (Edit > Preferences > Add-ons > AutoRig)."""

import bpy
from bpy.props import EnumProperty

#: The add-on's root module name: "autorig_addon" when imported from the
#: repository, "bl_ext.<repository>.autorig_addon" when installed as an extension.
ADDON_MODULE = __package__.rpartition(".")[0]

DEVICE_ITEMS = (
    ("CPU", "CPU", "Run the neural networks on the processor"),
    ("GPU", "GPU if Available", "Run the neural networks on a CUDA or Metal GPU when one is present, else on the CPU"),
)


class AutoRigPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_MODULE

    device: EnumProperty(
        name="Device",
        description="Where the rigging and skinning networks run",
        items=DEVICE_ITEMS,
        default="CPU",
    )

    def draw(self, context):
        self.layout.prop(self, "device")


def get_preferences(context=None):
    """The add-on's :class:`AutoRigPreferences`, or None when the add-on was
    registered without being enabled in the preferences (tests, CLI)."""
    context = context or bpy.context
    addon = context.preferences.addons.get(ADDON_MODULE)
    return addon.preferences if addon is not None else None


classes = (AutoRigPreferences,)
