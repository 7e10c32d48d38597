"""Options of the robust weight transfer: defaults and the bounds the panel
and the command line offer, declared once.

:class:`TransferOptions` carries the algorithm's settings;
:data:`TRANSFER_OPTIONS` declares each option of a transfer job (those and
how the result is written: vertex groups, bones, write mode) with its
label and help, and the Blender properties, the operator and
``python -m autorig_addon transfer`` are made from it (``core.options``).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..geometry.smoothing import DEFAULT_SMOOTHING_STRENGTH, MAX_SMOOTHING_ITERATIONS
from ..options import DEGREES, FRACTION, LENGTH, Choice, Option, option_table
from ..skinning.rigid_parts import RIGID_SHARE
from ..weights import MAX_INFLUENCES
from . import combine

#: Default match distance ``D``, as a fraction of the target's bounding-box diagonal (paper: 0.05).
DEFAULT_DISTANCE_FRACTION = 0.05
#: Match distances offered, fractions of the target's diagonal: from a
#: skin-tight layer to the whole target size.
MIN_DISTANCE_FRACTION = 0.0001
MAX_DISTANCE_FRACTION = 1.0
#: Slider end of the match distance fraction (larger values can be typed in).
SOFT_MAX_DISTANCE_FRACTION = 0.25
#: Absolute match distance the panel starts from, scene units (metres),
#: used only when its "Absolute Distance" is on.
DEFAULT_MAX_DISTANCE = 0.05
#: Slider end of the absolute match distance, scene units.
SOFT_MAX_DISTANCE = 1.0
#: Default largest angle between target and source normals for a match, degrees (paper: 30).
DEFAULT_MAX_NORMAL_ANGLE = 30.0
#: Normal angles offered, degrees: 180 accepts any direction.
MIN_MAX_NORMAL_ANGLE = 0.1
MAX_MAX_NORMAL_ANGLE = 180.0
#: By default a second matching pass accepts opposite normals (inner layers).
DEFAULT_ACCEPT_FLIPPED_NORMALS = True
#: Default Laplacian smoothing passes over inpainted vertices (0: none; the
#: surface smoothing below already smooths them).
DEFAULT_SMOOTHING_ITERATIONS = 0
#: Default reach of the surface smoothing of the transferred weights, as a
#: fraction of the source's bounding-box diagonal (0: off): detail of the
#: weights finer than this is damped over the whole target, copied rows
#: included. 0.005 is 1 cm on a 2 m body: on the makehuman garments it puts
#: both the edge stretch under random poses and the deformation error below
#: the published implementation's, on average for tight garments, loose
#: garments and shoes (docs/transfer.md, Evaluation).
DEFAULT_SMOOTHING_LENGTH = 0.005
#: Smoothing lengths offered, fractions of the source's diagonal: from off to
#: 10 cm on a 2 m body (beyond it weights blur across whole limbs).
MIN_SMOOTHING_LENGTH = 0.0
MAX_SMOOTHING_LENGTH = 0.05
#: Default bones kept per vertex (0: no limit).
DEFAULT_MAX_INFLUENCES = 0
#: Default name of the target's vertex group whose members are always
#: inpainted, never copied (an artist-painted mask).
DEFAULT_MASK_GROUP = "AutoRig Inpaint"
#: Vertices with at least this weight in the mask or protect vertex group
#: count as its members (weights are in [0, 1]).
GROUP_MEMBER_THRESHOLD = 0.5
#: By default a transfer where almost nothing matches, or where matches are
#: far from the body, is refused (a unit mix-up or a garment off the body).
DEFAULT_ALLOW_POOR_MATCH = False
#: By default a target whose weights lie almost wholly on one bone (a hat on
#: the head) is bound wholly to it (``transfer.rigid_accessory_bone``).
DEFAULT_RIGID_ACCESSORY = True


@dataclass(frozen=True)
class TransferOptions:
    """Settings of :func:`~autorig_addon.core.transfer.transfer.transfer_weights`.

    Attributes
    ----------
    distance_fraction : float
        Match distance ``D`` as a fraction of the target bounding-box diagonal.
    max_distance : float or None
        Absolute ``D`` in scene units; overrides ``distance_fraction``.
    max_normal_angle : float
        Largest angle, in degrees, between the target normal and the source
        normal at the closest point for a match.
    accept_flipped_normals : bool
        Second matching pass that accepts opposite normals (inner layers,
        single-sided cloth modelled facing inwards).
    smoothing_length : float
        Reach of the heat smoothing of every transferred row after
        inpainting, as a fraction of the source's bounding-box diagonal
        (0: off); see :func:`~autorig_addon.core.geometry.smoothing.smooth_over_surface`.
    smoothing_iterations : int
        Uniform Laplacian smoothing passes over inpainted vertices, after the
        surface smoothing.
    smoothing_strength : float
        Blend factor in [0, 1] of each smoothing pass.
    max_influences : int
        Keep this many largest weights per vertex (0: no limit; 4 for most
        game engines).
    allow_poor_match : bool
        Transfer even when almost nothing matches or matches are far from
        the body (see ``transfer.check_match_quality``), instead of refusing.
    rigid_accessory : bool
        Bind a target whose transferred weights lie mostly on one bone (a
        hat, a helmet, a bracer) wholly to that bone, so that it moves as one
        piece, unless where it touches the body the body's weights lie
        mostly on another bone (see ``transfer.rigid_accessory_bone``).
    """

    distance_fraction: float = DEFAULT_DISTANCE_FRACTION
    max_distance: float | None = None
    max_normal_angle: float = DEFAULT_MAX_NORMAL_ANGLE
    accept_flipped_normals: bool = DEFAULT_ACCEPT_FLIPPED_NORMALS
    smoothing_length: float = DEFAULT_SMOOTHING_LENGTH
    smoothing_iterations: int = DEFAULT_SMOOTHING_ITERATIONS
    smoothing_strength: float = DEFAULT_SMOOTHING_STRENGTH
    max_influences: int = DEFAULT_MAX_INFLUENCES
    allow_poor_match: bool = DEFAULT_ALLOW_POOR_MATCH
    rigid_accessory: bool = DEFAULT_RIGID_ACCESSORY


#: Which bones' weights the panel transfers (``bone_subset``; from a script
#: or the command line, bones are named instead).
ALL_BONES, SELECTED_BONES = "ALL", "SELECTED"

#: Every option of a transfer job, in the panel's order: the
#: :class:`TransferOptions` fields and how the result is written
#: (``blender.jobs.transfer.TransferSettings``).
TRANSFER_OPTIONS = option_table(
    Option("distance_fraction", float, DEFAULT_DISTANCE_FRACTION, "Max Distance",
           "Largest distance from the target vertex to the source surface for a direct copy, "
           "as a fraction of the target's bounding-box diagonal",
           low=MIN_DISTANCE_FRACTION, high=MAX_DISTANCE_FRACTION, soft_high=SOFT_MAX_DISTANCE_FRACTION, unit=FRACTION),
    Option("use_absolute_distance", bool, False, "Absolute Distance",
           "Give the match distance in scene units instead of a fraction of the target size", flag=None),
    Option("max_distance", float, DEFAULT_MAX_DISTANCE, "Distance",
           "Largest distance from the target vertex to the source surface for a direct copy, in scene units",
           low=0.0, low_is_open=True, soft_high=SOFT_MAX_DISTANCE, unit=LENGTH),
    Option("max_normal_angle", float, DEFAULT_MAX_NORMAL_ANGLE, "Normal Angle",
           "Largest angle between the target normal and the source normal for a direct copy",
           low=MIN_MAX_NORMAL_ANGLE, high=MAX_MAX_NORMAL_ANGLE, unit=DEGREES),
    Option("accept_flipped_normals", bool, DEFAULT_ACCEPT_FLIPPED_NORMALS, "Flipped Normals",
           "Also copy where the normals point the opposite way (inner layers, inward-facing cloth)",
           flag="--flipped-normals"),
    Option("smoothing_length", float, DEFAULT_SMOOTHING_LENGTH, "Smoothing Length",
           "Reach of the smoothing of all transferred weights, as a fraction of the source's bounding-box "
           "diagonal (0 = off; 0.005 is 1 cm on a 2 m body): less stretch where the body's weights change abruptly",
           low=MIN_SMOOTHING_LENGTH, high=MAX_SMOOTHING_LENGTH, unit=FRACTION, precision=4, step=0.05),
    Option("smoothing_iterations", int, DEFAULT_SMOOTHING_ITERATIONS, "Smoothing",
           "Number of smoothing passes over the inpainted vertices (0 = off)", low=0, high=MAX_SMOOTHING_ITERATIONS),
    Option("smoothing_strength", float, DEFAULT_SMOOTHING_STRENGTH, "Strength",
           "How far each smoothing pass moves a weight toward its neighbours' mean", low=0.0, high=1.0, unit=FRACTION),
    Option("max_influences", int, DEFAULT_MAX_INFLUENCES, "Max Influences",
           "Keep only this many largest bone weights per vertex (0 = no limit; 4 for most game engines)",
           low=0, high=MAX_INFLUENCES),
    Option("allow_poor_match", bool, DEFAULT_ALLOW_POOR_MATCH, "Allow Poor Match",
           "Transfer even when almost nothing matches, another unit scale fits much better, or matches are far "
           "from the body (otherwise refused: usually a unit mix-up or a garment off the body)"),
    Option("rigid_accessory", bool, DEFAULT_RIGID_ACCESSORY, "Rigid Accessory",
           f"Bind a target with a share of {RIGID_SHARE:g} or more of its weight on one bone (a hat, a helmet, a "
           "bracer) wholly to that bone, so that it moves as one piece, unless where it touches the body the body's "
           "weights lie mostly on another bone"),
    Option("mask_group", str, DEFAULT_MASK_GROUP, "Inpaint Mask",
           f"Vertex group on the target whose vertices (weight {GROUP_MEMBER_THRESHOLD:g} or more) are always "
           "inpainted, never copied"),
    Option("protect_group", str, "", "Protect",
           f"Vertex group on the target whose vertices (weight {GROUP_MEMBER_THRESHOLD:g} or more) keep their "
           "current weights"),
    Option("bone_subset", str, ALL_BONES, "Bones", "Which bones' weights to transfer", flag=None, choices=(
        Choice(ALL_BONES, "All Deform Bones", "Transfer the weights of every bone with Deform enabled"),
        Choice(SELECTED_BONES, "Selected Pose Bones",
               "Transfer only the weights of the selected pose bones; other bones keep the target's weights"),
    )),
    Option("replace_mode", str, combine.DEFAULT_REPLACE_MODE, "Write",
           "How the transferred weights combine with the target's existing vertex groups", flag="--replace", choices=(
               Choice(combine.REPLACE, "Replace",
                      "Clear the vertex groups of the transferred bones and fill them anew; other groups stay",
                      word="transfer"),
               Choice(combine.MIX, "Mix", "Blend the transferred weights into the existing ones by the mix factor"),
               Choice(combine.REPLACE_ALL, "Replace All",
                      "Remove every vertex group of the target before writing the transferred weights", word="all"),
           )),
    Option("mix_factor", float, combine.DEFAULT_MIX_FACTOR, "Mix",
           "Share of the transferred weights when mixing with the existing ones", low=0.0, high=1.0, unit=FRACTION,
           flag="--mix"),
)
