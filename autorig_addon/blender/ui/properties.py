"""Scene settings of the add-on (``scene.autorig``).

The transfer options live in :class:`TransferOptionProperties`, a mixin
shared by the scene settings and the operator, so the operator exposes the
same options to scripts and copies the scene's values when run from the UI.

Defaults and bounds come from the core (``core.transfer.options``,
``core.transfer.combine``, ``core.skinning.geometric``, ``core.skinning.methods``,
``core.distances.grid``, ``core.weights``, ``core.geometry.smoothing``,
``core.rigging.predict``),
where the command line takes them too; only the slider ranges (``soft_*``)
and the absolute distance, which the panel alone offers, are declared here.
"""

import math

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ...core.distances.grid import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION
from ...core.geometry.smoothing import DEFAULT_SMOOTHING_STRENGTH, MAX_SMOOTHING_ITERATIONS
from ...core.rigging import predict
from ...core.skinning import geometric as skinning
from ...core.skinning.methods import DEFAULT_SKIN_METHOD, SKIN_METHOD_DESCRIPTIONS, SKIN_METHOD_LABELS, SKIN_METHODS
from ...core.transfer import combine
from ...core.transfer import options as transfer_options
from ...core.weights import MAX_INFLUENCES
from ..jobs.rig import RigSettings, on_rig_setting_changed
from ..jobs.skin import SkinSettings

#: Default absolute match distance, metres, used only when "Absolute Distance" is on.
DEFAULT_MAX_DISTANCE = 0.05
#: Slider end of the match distance fraction (larger values can be typed in).
SOFT_MAX_DISTANCE_FRACTION = 0.25
#: Slider end of the absolute match distance, metres.
SOFT_MAX_DISTANCE = 1.0
#: Slider range of the voxel resolution, cells along the longest side.
SOFT_MIN_RESOLUTION, SOFT_MAX_RESOLUTION = 16, 256
#: Slider end of the skinning falloff (unitless).
SOFT_MAX_FALLOFF = 16.0

REPLACE_MODE_ITEMS = (
    (combine.REPLACE, "Replace", "Clear the vertex groups of the transferred bones and fill them anew; other groups stay"),
    (combine.MIX, "Mix", "Blend the transferred weights into the existing ones by the mix factor"),
    (combine.REPLACE_ALL, "Replace All", "Remove every vertex group of the target before writing the transferred weights"),
)
BONE_SUBSET_ITEMS = (
    ("ALL", "All Deform Bones", "Transfer the weights of every bone with Deform enabled"),
    ("SELECTED", "Selected Pose Bones", "Transfer only the weights of the selected pose bones; other bones keep the target's weights"),
)


class TransferOptionProperties:
    """Transfer options shared by :class:`AutoRigSceneSettings` and the operator."""

    distance_fraction: FloatProperty(
        name="Max Distance",
        description="Largest distance from the target vertex to the source surface for a direct copy, "
        "as a fraction of the target's bounding-box diagonal",
        subtype="FACTOR",
        min=transfer_options.MIN_DISTANCE_FRACTION,
        max=transfer_options.MAX_DISTANCE_FRACTION,
        soft_max=SOFT_MAX_DISTANCE_FRACTION,
        default=transfer_options.DEFAULT_DISTANCE_FRACTION,
    )
    use_absolute_distance: BoolProperty(
        name="Absolute Distance",
        description="Give the match distance in scene units instead of a fraction of the target size",
        default=False,
    )
    max_distance: FloatProperty(
        name="Distance",
        description="Largest distance from the target vertex to the source surface for a direct copy, in scene units",
        subtype="DISTANCE",
        unit="LENGTH",
        min=0.0,
        soft_max=SOFT_MAX_DISTANCE,
        default=DEFAULT_MAX_DISTANCE,
    )
    max_normal_angle: FloatProperty(
        name="Normal Angle",
        description="Largest angle between the target normal and the source normal for a direct copy",
        subtype="ANGLE",
        min=math.radians(transfer_options.MIN_MAX_NORMAL_ANGLE),
        max=math.radians(transfer_options.MAX_MAX_NORMAL_ANGLE),
        default=math.radians(transfer_options.DEFAULT_MAX_NORMAL_ANGLE),
    )
    accept_flipped_normals: BoolProperty(
        name="Flipped Normals",
        description="Also copy where the normals point the opposite way (inner layers, inward-facing cloth)",
        default=transfer_options.DEFAULT_ACCEPT_FLIPPED_NORMALS,
    )
    smoothing_length: FloatProperty(
        name="Smoothing Length",
        description="Reach of the smoothing of all transferred weights, as a fraction of the source's "
        "bounding-box diagonal (0 = off; 0.005 is 1 cm on a 2 m body): less stretch where the body's "
        "weights change abruptly",
        subtype="FACTOR",
        min=transfer_options.MIN_SMOOTHING_LENGTH,
        max=transfer_options.MAX_SMOOTHING_LENGTH,
        precision=4,
        step=0.05,
        default=transfer_options.DEFAULT_SMOOTHING_LENGTH,
    )
    smoothing_iterations: IntProperty(
        name="Smoothing",
        description="Number of smoothing passes over the inpainted vertices (0 = off)",
        min=0,
        max=MAX_SMOOTHING_ITERATIONS,
        default=transfer_options.DEFAULT_SMOOTHING_ITERATIONS,
    )
    smoothing_strength: FloatProperty(
        name="Strength",
        description="How far each smoothing pass moves a weight toward its neighbours' mean (0 to 1)",
        subtype="FACTOR",
        min=0.0,
        max=1.0,
        default=DEFAULT_SMOOTHING_STRENGTH,
    )
    max_influences: IntProperty(
        name="Max Influences",
        description="Keep only this many largest bone weights per vertex (0 = no limit; 4 for most game engines)",
        min=0,
        max=MAX_INFLUENCES,
        default=transfer_options.DEFAULT_MAX_INFLUENCES,
    )
    allow_poor_match: BoolProperty(
        name="Allow Poor Match",
        description="Transfer even when almost nothing matches, another unit scale fits much better, or matches "
        "are far from the body (otherwise refused: usually a unit mix-up or a garment off the body)",
        default=transfer_options.DEFAULT_ALLOW_POOR_MATCH,
    )
    mask_group: StringProperty(
        name="Inpaint Mask",
        description="Vertex group on the target whose vertices (weight "
        f"{transfer_options.GROUP_MEMBER_THRESHOLD:g} or more) are always inpainted, never copied",
        default=transfer_options.DEFAULT_MASK_GROUP,
    )
    protect_group: StringProperty(
        name="Protect",
        description=f"Vertex group on the target whose vertices (weight {transfer_options.GROUP_MEMBER_THRESHOLD:g} or more) "
        "keep their current weights",
        default="",
    )
    bone_subset: EnumProperty(
        name="Bones",
        description="Which bones' weights to transfer",
        items=BONE_SUBSET_ITEMS,
        default="ALL",
    )
    replace_mode: EnumProperty(
        name="Write",
        description="How the transferred weights combine with the target's existing vertex groups",
        items=REPLACE_MODE_ITEMS,
        default=combine.DEFAULT_REPLACE_MODE,
    )
    mix_factor: FloatProperty(
        name="Mix",
        description="Share of the transferred weights when mixing with the existing ones (0 to 1)",
        subtype="FACTOR",
        min=0.0,
        max=1.0,
        default=combine.DEFAULT_MIX_FACTOR,
    )


#: The option names shared by the scene settings and the operator.
TRANSFER_OPTION_NAMES = tuple(TransferOptionProperties.__annotations__)

#: The skinning methods, identifiers upper-case (Blender's habit; the
#: operator lowers them), labels and tooltips from the core.
SKIN_METHOD_ITEMS = tuple((name.upper(), SKIN_METHOD_LABELS[name], SKIN_METHOD_DESCRIPTIONS[name])
                          for name in SKIN_METHODS)
SKIN_DISTANCE_ITEMS = (
    ("GEODESIC", "Volumetric Geodesic",
     "Shortest path through the inside of the mesh (RigNet, Geodesic Voxel Binding); for closed bodies"),
    ("HOLLOW", "HollowDist",
     "Paths through empty space around the mesh (HeterSkinNet); reaches bones outside the body and loose parts"),
)


class SkinOptionProperties:
    """Skinning options shared by :class:`AutoRigSceneSettings` and the skin operator."""

    skin_method: EnumProperty(
        name="Method", description="How the weights are computed: the geometric method or a trained network",
        items=SKIN_METHOD_ITEMS, default=DEFAULT_SKIN_METHOD.upper(),
    )
    skin_distance: EnumProperty(
        name="Distance", description="How the distance from a vertex to a bone is measured (geometric method only)",
        items=SKIN_DISTANCE_ITEMS, default=skinning.DEFAULT_DISTANCE.upper(),
    )
    skin_resolution: IntProperty(
        name="Resolution", description="Voxels along the mesh's longest side; higher follows thin parts "
        "(fingers, cloth) better and costs more time and memory",
        min=MIN_RESOLUTION, max=MAX_RESOLUTION, soft_min=SOFT_MIN_RESOLUTION, soft_max=SOFT_MAX_RESOLUTION,
        default=DEFAULT_RESOLUTION,
    )
    skin_falloff: FloatProperty(
        name="Falloff", description="Heat strength: how fast a bone's influence falls off away from the "
        "surface it is nearest to (unitless); higher gives sharper joints, lower softer blends",
        min=skinning.MIN_FALLOFF, max=skinning.MAX_FALLOFF, soft_max=SOFT_MAX_FALLOFF, default=skinning.DEFAULT_FALLOFF,
    )
    skin_max_influences: IntProperty(
        name="Max Influences", description="Bones per vertex to keep (0 = no limit; 4 for most game engines)",
        min=0, max=MAX_INFLUENCES, default=skinning.DEFAULT_MAX_INFLUENCES,
    )
    skin_smoothing_iterations: IntProperty(
        name="Smoothing", description="Extra smoothing passes of the weights over the surface "
        "(the heat diffusion is already smooth)",
        min=0, max=MAX_SMOOTHING_ITERATIONS, default=skinning.DEFAULT_SMOOTHING_ITERATIONS,
    )
    skin_smoothing_strength: FloatProperty(
        name="Smoothing Strength", description="Blend factor of one smoothing pass",
        subtype="FACTOR", min=0.0, max=1.0, default=DEFAULT_SMOOTHING_STRENGTH,
    )
    skin_replace_all: BoolProperty(
        name="Replace All Groups", description="Remove every existing vertex group of the meshes first "
        "(otherwise only the deform bones' groups are replaced)",
        default=False,
    )


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

    rig_bandwidth: FloatProperty(
        name="Bandwidth", description="Level of detail: reach of the clustering of the joint votes, as a share of "
        "the character's largest side; smaller gives more joints",
        min=predict.MIN_BANDWIDTH, max=predict.MAX_BANDWIDTH, default=predict.DEFAULT_BANDWIDTH,
        precision=3, step=0.1, update=_update_live_prediction,
    )
    rig_density_threshold: FloatProperty(
        name="Density Threshold", description="Joints whose vote mass is below this share of the strongest "
        "are dropped; higher keeps only well-supported joints",
        subtype="FACTOR", min=predict.MIN_DENSITY_THRESHOLD, max=predict.MAX_DENSITY_THRESHOLD,
        default=predict.DEFAULT_DENSITY_THRESHOLD, precision=3, step=0.1, update=_update_live_prediction,
    )
    rig_symmetry: BoolProperty(
        name="Symmetry", description="When the character is left-right symmetric, mirror the joint votes and pair "
        "the joints, so the skeleton is symmetric with .L/.R names",
        default=predict.DEFAULT_SYMMETRY, update=_update_live_prediction,
    )


#: Names of the rig options, as declared on :class:`RigOptionProperties`.
RIG_OPTION_NAMES = tuple(RigOptionProperties.__annotations__)
#: What Auto-Rig's Replace Binding does, for the scene setting and the operator's option.
REPLACE_BINDING_DESCRIPTION = ("Meshes already bound to an armature lose that binding (its Armature modifier and "
                               "bone groups) and are bound to the new skeleton; otherwise they are refused")


def _is_weighted_mesh(_self, obj) -> bool:
    return obj.type == "MESH" and len(obj.vertex_groups) > 0


def _is_mesh(_self, obj) -> bool:
    return obj.type == "MESH"


class AutoRigSceneSettings(TransferOptionProperties, SkinOptionProperties, RigOptionProperties,
                           bpy.types.PropertyGroup):
    """Settings of the AutoRig panels, stored per scene."""

    rig_replace: BoolProperty(name="Replace Binding", description=REPLACE_BINDING_DESCRIPTION, default=False)

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


def skin_settings_from(props) -> SkinSettings:
    """SkinSettings from the ``skin_*`` properties of the operator or scene settings."""
    values = {name[len("skin_"):]: getattr(props, name) for name in SKIN_OPTION_NAMES}
    values["distance"] = values["distance"].lower()
    values["method"] = values["method"].lower()
    return SkinSettings(**values)


def rig_settings_from(props) -> RigSettings:
    """RigSettings from the ``rig_*`` properties of an operator or the scene settings."""
    return RigSettings(**{name[len("rig_"):]: getattr(props, name) for name in RIG_OPTION_NAMES})


classes = (AutoRigSceneSettings,)


def register_scene_properties() -> None:
    bpy.types.Scene.autorig = PointerProperty(type=AutoRigSceneSettings)


def unregister_scene_properties() -> None:
    if hasattr(bpy.types.Scene, "autorig"):
        del bpy.types.Scene.autorig
