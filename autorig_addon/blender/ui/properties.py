"""Scene settings of the add-on (``scene.autorig``) and the option mix-ins
the operators share with them.

Each mix-in (:class:`TransferOptionProperties`, :class:`SkinOptionProperties`,
:class:`RigOptionProperties`) is made from a core option table
(``core.transfer.options``, ``core.skinning.options``,
``core.rigging.options``; :mod:`.option_properties`), where the command line
takes its options too; the scene settings and the operators both inherit
it, so scripts pass the same names and the panel's buttons copy the scene's
values into the operators (:func:`scene_values`). The ``*_settings_from``
functions read either back into a job's settings.
"""

from dataclasses import fields

import bpy
from bpy.props import PointerProperty

from ...core.rigging.options import KEEP_POOR, REPLACE_BINDING, RIG_OPTIONS, RIGIFY
from ...core.skinning.options import SKINNING_OPTIONS, SkinningOptions
from ...core.transfer.options import TRANSFER_OPTIONS, TransferOptions
from ..jobs.rig import RigSettings, on_rig_setting_changed
from ..jobs.skin import SkinSettings
from ..jobs.transfer import TransferSettings
from .option_properties import option_properties, option_property, option_values

#: Prefixes of the skin and rig options' property names (``skin_method``,
#: ``rig_bandwidth``); the transfer options have none (``distance_fraction``).
SKIN_PREFIX, RIG_PREFIX = "skin_", "rig_"


class TransferOptionProperties:
    """Transfer options shared by :class:`AutoRigSceneSettings` and the operator."""

    __annotations__ = option_properties(TRANSFER_OPTIONS)


#: The option names shared by the scene settings and the operator.
TRANSFER_OPTION_NAMES = tuple(TransferOptionProperties.__annotations__)


class SkinOptionProperties:
    """Skinning options shared by :class:`AutoRigSceneSettings` and the Skin and Auto-Rig operators."""

    __annotations__ = option_properties(SKINNING_OPTIONS, SKIN_PREFIX)


#: Names of the skin options, as declared on :class:`SkinOptionProperties`.
SKIN_OPTION_NAMES = tuple(SkinOptionProperties.__annotations__)


def _update_live_prediction(self, context) -> None:
    """A Rig setting of the scene changed: re-cluster the predicted armature
    while it is unedited (``jobs.rig``); an operator's own copy of the
    option (no scene behind it) changes nothing."""
    if isinstance(getattr(self, "id_data", None), bpy.types.Scene):
        on_rig_setting_changed(context, rig_settings_from(self))


class RigOptionProperties:
    """Skeleton prediction options shared by :class:`AutoRigSceneSettings`
    and the Predict Skeleton and Auto-Rig operators; on the scene they update
    the predicted armature live."""

    __annotations__ = option_properties(RIG_OPTIONS, RIG_PREFIX, update=_update_live_prediction)


#: Names of the rig options, as declared on :class:`RigOptionProperties`.
RIG_OPTION_NAMES = tuple(RigOptionProperties.__annotations__)


def _is_weighted_mesh(_self, obj) -> bool:
    return obj.type == "MESH" and len(obj.vertex_groups) > 0


def _is_mesh(_self, obj) -> bool:
    return obj.type == "MESH"


class AutoRigSceneSettings(TransferOptionProperties, SkinOptionProperties, RigOptionProperties,
                           bpy.types.PropertyGroup):
    """Settings of the AutoRig panels, stored per scene."""

    rig_replace: option_property(REPLACE_BINDING)
    rig_rigify: option_property(RIGIFY)
    rig_keep_poor: option_property(KEEP_POOR)

    source: PointerProperty(
        name="Source",
        description="Skinned mesh (with vertex groups and an armature) to take the weights from",
        type=bpy.types.Object,
        poll=_is_weighted_mesh,
    )
    target: PointerProperty(
        name="Target",
        description="Extra mesh to weight, besides the selected meshes other than the source",
        type=bpy.types.Object,
        poll=_is_mesh,
    )


def scene_values(context, names, is_set) -> dict:
    """{name: value} of the scene settings' properties ``names`` that the
    caller has not set itself (``is_set(name)`` False): what a panel button
    hands its operator. Empty when the scene has no settings."""
    settings = getattr(context.scene, "autorig", None)
    if settings is None:
        return {}
    return {name: getattr(settings, name) for name in names if not is_set(name)}


def transfer_settings_from(props, bones: tuple | None = None) -> TransferSettings:
    """TransferSettings from the transfer options of the operator or scene
    settings; ``bones``: the bones to transfer (None: every deform bone),
    see ``selection.chosen_bone_names``. The absolute match distance counts
    only when its switch is on."""
    values = option_values(props, TRANSFER_OPTIONS)
    if not values["use_absolute_distance"]:
        values["max_distance"] = None
    return TransferSettings(
        options=TransferOptions(**{field.name: values[field.name] for field in fields(TransferOptions)}),
        mask_group=values["mask_group"],
        protect_group=values["protect_group"],
        bones=bones,
        replace_mode=values["replace_mode"],
        mix_factor=values["mix_factor"],
    )


def skin_settings_from(props) -> SkinSettings:
    """SkinSettings from the ``skin_*`` properties of an operator or the scene settings."""
    values = option_values(props, SKINNING_OPTIONS, SKIN_PREFIX)
    options = SkinningOptions(**{field.name: values[field.name] for field in fields(SkinningOptions)})
    return SkinSettings(options, replace_all=values["replace_all"])


def rig_settings_from(props) -> RigSettings:
    """RigSettings from the ``rig_*`` properties of an operator or the scene settings."""
    return RigSettings(**option_values(props, RIG_OPTIONS, RIG_PREFIX))


classes = (AutoRigSceneSettings,)


def register_scene_properties() -> None:
    bpy.types.Scene.autorig = PointerProperty(type=AutoRigSceneSettings)


def unregister_scene_properties() -> None:
    if hasattr(bpy.types.Scene, "autorig"):
        del bpy.types.Scene.autorig
