"""Options of skinning: :class:`SkinningOptions`, which
:func:`.methods.skin_weights` takes, and :data:`SKINNING_OPTIONS`, the
table the Skin panel, the Skin and Auto-Rig operators and
``python -m autorig_addon skin`` are made from (``core.options``).

Defaults and bounds are the algorithms' (``.methods``, ``.geometric``,
``core.distances.grid``, ``core.geometry.smoothing``, ``core.weights``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..distances.grid import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION
from ..geometry.smoothing import DEFAULT_SMOOTHING_STRENGTH, MAX_SMOOTHING_ITERATIONS
from ..options import CELLS, FRACTION, Choice, Option, option_table
from ..weights import MAX_INFLUENCES
from . import geometric
from .methods import (
    DEFAULT_SKIN_METHOD,
    GEOMETRIC,
    GEOMETRIC_OPTIONS,
    SKIN_METHOD_DESCRIPTIONS,
    SKIN_METHOD_LABELS,
    SKIN_METHODS,
)

#: Slider range of the voxel resolution, cells along the longest side (others can be typed in).
SOFT_MIN_RESOLUTION, SOFT_MAX_RESOLUTION = 16, 256
#: Slider end of the heat falloff (unitless).
SOFT_MAX_FALLOFF = 16.0


@dataclass(frozen=True)
class SkinningOptions:
    """Settings of :func:`.methods.skin_weights`.

    Attributes
    ----------
    method : one of ``.methods.SKIN_METHODS``
    distance : "geodesic" (volumetric geodesic, RigNet) or "hollow"
        (HollowDist, HeterSkinNet); geometric method only
    resolution : int, voxel cells along the mesh's longest side
    falloff : float > 0, heat strength (higher: sharper blends); geometric method only
    max_influences : int >= 0, bones kept per vertex (0: no limit)
    smoothing_iterations : int >= 0, extra surface smoothing passes; geometric method only
    smoothing_strength : float in [0, 1], blend factor of one pass; geometric method only
    rigid_parts : bool, bind each loose part whose weights lie mostly on one bone wholly to it,
        and cards hanging from the head (hair) to the head (:mod:`.rigid_parts`); every method
    """

    method: str = DEFAULT_SKIN_METHOD
    distance: str = geometric.DEFAULT_DISTANCE
    resolution: int = DEFAULT_RESOLUTION
    falloff: float = geometric.DEFAULT_FALLOFF
    max_influences: int = geometric.DEFAULT_MAX_INFLUENCES
    smoothing_iterations: int = geometric.DEFAULT_SMOOTHING_ITERATIONS
    smoothing_strength: float = DEFAULT_SMOOTHING_STRENGTH
    rigid_parts: bool = True


def ignored_options(options: SkinningOptions) -> tuple[str, ...]:
    """The :data:`.methods.GEOMETRIC_OPTIONS` of ``options`` set to something
    other than their default, which a network ignores: none for the
    geometric method, in ``GEOMETRIC_OPTIONS`` order."""
    if options.method == GEOMETRIC:
        return ()
    defaults = SkinningOptions()
    return tuple(name for name in GEOMETRIC_OPTIONS if getattr(options, name) != getattr(defaults, name))


def _saying_geometric_only(option: Option) -> Option:
    """``option`` whose help says so when the networks ignore it."""
    if option.name not in GEOMETRIC_OPTIONS:
        return option
    return replace(option, help=f"{option.help} ({GEOMETRIC} method only)")


#: Every option of a skinning job, in the panel's order: the
#: :class:`SkinningOptions` fields and how the result is written
#: (``replace_all``, ``blender.jobs.skin.SkinSettings``).
SKINNING_OPTIONS = option_table(*map(_saying_geometric_only, (
    Option("method", str, DEFAULT_SKIN_METHOD, "Method",
           "How the weights are computed: the geometric method or a trained network",
           choices=tuple(Choice(name, SKIN_METHOD_LABELS[name], SKIN_METHOD_DESCRIPTIONS[name])
                         for name in SKIN_METHODS)),
    Option("distance", str, geometric.DEFAULT_DISTANCE, "Distance",
           "How the distance from a vertex to a bone is measured", choices=(
               Choice("geodesic", "Volumetric Geodesic",
                      "Shortest path through the inside of the mesh (RigNet, Geodesic Voxel Binding); "
                      "for closed bodies"),
               Choice("hollow", "HollowDist",
                      "Paths through empty space around the mesh (HeterSkinNet); reaches bones outside the body "
                      "and loose parts"),
           )),
    Option("resolution", int, DEFAULT_RESOLUTION, "Resolution",
           "Voxels along the mesh's longest side; higher follows thin parts (fingers, cloth) better and costs "
           "more time and memory",
           low=MIN_RESOLUTION, high=MAX_RESOLUTION, soft_low=SOFT_MIN_RESOLUTION, soft_high=SOFT_MAX_RESOLUTION,
           unit=CELLS),
    Option("falloff", float, geometric.DEFAULT_FALLOFF, "Falloff",
           "Heat strength: how fast a bone's influence falls off away from the surface it is nearest to "
           "(unitless); higher gives sharper joints, lower softer blends",
           low=geometric.MIN_FALLOFF, high=geometric.MAX_FALLOFF, soft_high=SOFT_MAX_FALLOFF),
    Option("max_influences", int, geometric.DEFAULT_MAX_INFLUENCES, "Max Influences",
           "Bones per vertex to keep (0 = no limit; 4 for most game engines)", low=0, high=MAX_INFLUENCES),
    Option("smoothing_iterations", int, geometric.DEFAULT_SMOOTHING_ITERATIONS, "Smoothing",
           "Extra smoothing passes of the weights over the surface (the heat diffusion is already smooth)",
           low=0, high=MAX_SMOOTHING_ITERATIONS),
    Option("smoothing_strength", float, DEFAULT_SMOOTHING_STRENGTH, "Smoothing Strength",
           "Blend factor of one smoothing pass", low=0.0, high=1.0, unit=FRACTION),
    Option("rigid_parts", bool, True, "Rigid Loose Parts",
           "Bind each separate piece of the mesh whose weights lie mostly on one bone wholly to that bone "
           "(a robot's plates, armour pieces, eyes), and hair cards hanging from the head wholly to the head; "
           "pieces that span a joint keep their blend"),
    Option("replace_all", bool, False, "Replace All Groups",
           "Remove every existing vertex group of the meshes first (otherwise only the deform bones' groups "
           "are replaced)"),
)))
