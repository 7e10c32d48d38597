"""Options of the robust weight transfer: defaults and the bounds the panel
and the command line offer, declared once.

:class:`TransferOptions` carries the algorithm's settings; the Blender
properties, the operator and ``python -m autorig_addon transfer`` take their
defaults, limits and units from the constants here.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..geometry.smoothing import DEFAULT_SMOOTHING_STRENGTH

#: Default match distance ``D``, as a fraction of the target's bounding-box diagonal (paper: 0.05).
DEFAULT_DISTANCE_FRACTION = 0.05
#: Match distances offered, fractions of the target's diagonal: from a
#: skin-tight layer to the whole target size.
MIN_DISTANCE_FRACTION = 0.0001
MAX_DISTANCE_FRACTION = 1.0
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
