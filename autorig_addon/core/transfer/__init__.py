"""Skin weight transfer from a skinned body onto garments and props.

:mod:`.matching` copies weights where the closest source point is near and
its normal agrees, :mod:`.inpainting` fills the rest smoothly, and
:mod:`.transfer` runs both (:func:`transfer_weights`) with :mod:`.options`
(:class:`TransferOptions`, the defaults and the bounds the panel and the
command line offer). :mod:`.source` checks and indexes the skinned source
once (:class:`TransferSource`) for transfers onto many targets.
"""

from .options import (
    DEFAULT_DISTANCE_FRACTION,
    DEFAULT_MAX_NORMAL_ANGLE,
    DEFAULT_SMOOTHING_ITERATIONS,
    DEFAULT_SMOOTHING_STRENGTH,
    TransferOptions,
)
from .source import TransferSource
from .transfer import TransferResult, VertexStatus, transfer_weights

__all__ = [
    "DEFAULT_DISTANCE_FRACTION",
    "DEFAULT_MAX_NORMAL_ANGLE",
    "DEFAULT_SMOOTHING_ITERATIONS",
    "DEFAULT_SMOOTHING_STRENGTH",
    "TransferOptions",
    "TransferResult",
    "TransferSource",
    "VertexStatus",
    "transfer_weights",
]
