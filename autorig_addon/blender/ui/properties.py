"""Scene settings of the add-on (``scene.autorig``).

The transfer options live in :class:`TransferOptionProperties`, a mixin
shared by the scene settings and the operator, so the operator exposes the
same options to scripts and copies the scene's values when run from the UI.
"""

import math

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ...core.transfer.transfer import (  # the transfer defaults live with the algorithm
    DEFAULT_DISTANCE_FRACTION,
    DEFAULT_SMOOTHING_ITERATIONS,
    DEFAULT_SMOOTHING_STRENGTH,
)
from ...core.transfer.transfer import DEFAULT_MAX_NORMAL_ANGLE as DEFAULT_MAX_NORMAL_ANGLE_DEGREES

#: Default absolute match distance, metres, used only when "Absolute Distance" is on.
DEFAULT_MAX_DISTANCE = 0.05
#: Most smoothing passes the UI offers.
MAX_SMOOTHING_ITERATIONS = 100
#: Most influences per vertex the UI offers (0 = no limit).
MAX_INFLUENCES_LIMIT = 16
#: Default name of the vertex group that forces inpainting.
DEFAULT_MASK_GROUP = "AutoRig Inpaint"
#: Vertices with at least this weight in the mask / protect group count as members.
GROUP_MEMBER_THRESHOLD = 0.5

REPLACE_MODE_ITEMS = (
    ("REPLACE", "Replace", "Clear the vertex groups of the transferred bones and fill them anew; other groups stay"),
    ("MIX", "Mix", "Blend the transferred weights into the existing ones by the mix factor"),
    ("REPLACE_ALL", "Replace All", "Remove every vertex group of the target before writing the transferred weights"),
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
        min=0.0001,
        max=1.0,
        soft_max=0.25,
        default=DEFAULT_DISTANCE_FRACTION,
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
        soft_max=1.0,
        default=DEFAULT_MAX_DISTANCE,
    )
    max_normal_angle: FloatProperty(
        name="Normal Angle",
        description="Largest angle between the target normal and the source normal for a direct copy",
        subtype="ANGLE",
        min=math.radians(0.1),
        max=math.pi,
        default=math.radians(DEFAULT_MAX_NORMAL_ANGLE_DEGREES),
    )
    accept_flipped_normals: BoolProperty(
        name="Flipped Normals",
        description="Also copy where the normals point the opposite way (inner layers, inward-facing cloth)",
        default=True,
    )
    smoothing_iterations: IntProperty(
        name="Smoothing",
        description="Number of smoothing passes over the inpainted vertices (0 = off)",
        min=0,
        max=MAX_SMOOTHING_ITERATIONS,
        default=DEFAULT_SMOOTHING_ITERATIONS,
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
        max=MAX_INFLUENCES_LIMIT,
        default=0,
    )
    mask_group: StringProperty(
        name="Inpaint Mask",
        description="Vertex group on the target whose vertices (weight 0.5 or more) are always inpainted, never copied",
        default=DEFAULT_MASK_GROUP,
    )
    protect_group: StringProperty(
        name="Protect",
        description="Vertex group on the target whose vertices (weight 0.5 or more) keep their current weights",
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
        default="REPLACE",
    )
    mix_factor: FloatProperty(
        name="Mix",
        description="Share of the transferred weights when mixing with the existing ones (0 to 1)",
        subtype="FACTOR",
        min=0.0,
        max=1.0,
        default=1.0,
    )


#: The option names shared by the scene settings and the operator.
TRANSFER_OPTION_NAMES = tuple(TransferOptionProperties.__annotations__)



from ...core.skinning.geometric import (  # noqa: E402  (defaults shared with the core)
    DEFAULT_FALLOFF,
    DEFAULT_METHOD,
    DEFAULT_MAX_INFLUENCES,
)
from ...core.skinning.geometric import DEFAULT_SMOOTHING_ITERATIONS as DEFAULT_SKIN_SMOOTHING_ITERATIONS  # noqa: E402
from ...core.skinning.geometric import DEFAULT_SMOOTHING_STRENGTH as DEFAULT_SKIN_SMOOTHING_STRENGTH  # noqa: E402
from ...core.distances.voxelize import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION  # noqa: E402

SKIN_DISTANCE_ITEMS = (
    ("GEODESIC", "Volumetric Geodesic",
     "Shortest path through the inside of the mesh (RigNet, Geodesic Voxel Binding); for closed bodies"),
    ("HOLLOW", "HollowDist",
     "Paths through empty space around the mesh (HeterSkinNet); reaches bones outside the body and loose parts"),
)


class SkinOptionProperties:
    """Skinning options shared by :class:`AutoRigSceneSettings` and the skin operator."""

    skin_distance: EnumProperty(
        name="Distance", description="How the distance from a vertex to a bone is measured",
        items=SKIN_DISTANCE_ITEMS, default=DEFAULT_METHOD.upper(),
    )
    skin_resolution: IntProperty(
        name="Resolution", description="Voxels along the mesh's longest side; higher follows thin parts "
        "(fingers, cloth) better and costs more time and memory",
        min=MIN_RESOLUTION, max=MAX_RESOLUTION, soft_min=16, soft_max=256, default=DEFAULT_RESOLUTION,
    )
    skin_falloff: FloatProperty(
        name="Falloff", description="Heat strength: how fast a bone's influence falls off away from the "
        "surface it is nearest to (unitless); higher gives sharper joints, lower softer blends",
        min=0.1, max=64.0, soft_max=16.0, default=DEFAULT_FALLOFF,
    )
    skin_max_influences: IntProperty(
        name="Max Influences", description="Bones per vertex to keep (0 = no limit; 4 for most game engines)",
        min=0, max=MAX_INFLUENCES_LIMIT, default=DEFAULT_MAX_INFLUENCES,
    )
    skin_smoothing_iterations: IntProperty(
        name="Smoothing", description="Extra smoothing passes of the weights over the surface "
        "(the heat diffusion is already smooth)",
        min=0, max=MAX_SMOOTHING_ITERATIONS, default=DEFAULT_SKIN_SMOOTHING_ITERATIONS,
    )
    skin_smoothing_strength: FloatProperty(
        name="Smoothing Strength", description="Blend factor of one smoothing pass",
        subtype="FACTOR", min=0.0, max=1.0, default=DEFAULT_SKIN_SMOOTHING_STRENGTH,
    )
    skin_replace_all: BoolProperty(
        name="Replace All Groups", description="Remove every existing vertex group of the meshes first "
        "(otherwise only the deform bones' groups are replaced)",
        default=False,
    )


#: Names of the skin options, as declared on :class:`SkinOptionProperties`.
SKIN_OPTION_NAMES = tuple(SkinOptionProperties.__annotations__)


def _is_weighted_mesh(_self, obj) -> bool:
    return obj.type == "MESH" and len(obj.vertex_groups) > 0


def _is_mesh(_self, obj) -> bool:
    return obj.type == "MESH"


class AutoRigSceneSettings(TransferOptionProperties, SkinOptionProperties, bpy.types.PropertyGroup):
    """Settings of the AutoRig panels, stored per scene."""

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


classes = (AutoRigSceneSettings,)


def register_scene_properties() -> None:
    bpy.types.Scene.autorig = PointerProperty(type=AutoRigSceneSettings)


def unregister_scene_properties() -> None:
    if hasattr(bpy.types.Scene, "autorig"):
        del bpy.types.Scene.autorig
