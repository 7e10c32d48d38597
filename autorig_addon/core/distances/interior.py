"""The cells a voxelised surface encloses.

Stage 2 of the vertex-to-bone distances (see :mod:`.bone_distances`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import ndimage

from .grid import VoxelGrid


def fill_interior(grid: VoxelGrid) -> VoxelGrid:
    """Mark the cells enclosed by the surface.

    A non-surface cell is outside when a 6-connected path of non-surface
    cells joins it to the border of the grid; every other non-surface cell
    is inside. Open parts (cloth, a body with an open neck) enclose nothing,
    so their interior stays empty: that is the honest answer.

    Parameters
    ----------
    grid : VoxelGrid with ``surface`` set

    Returns
    -------
    A new VoxelGrid with ``inside`` set.
    """
    empty = ~grid.surface
    labels, _ = ndimage.label(empty)  # default structure: 6-connectivity
    border = np.concatenate(
        [labels[[0, -1], :, :].ravel(), labels[:, [0, -1], :].ravel(), labels[:, :, [0, -1]].ravel()]
    )
    outside_labels = np.unique(border[border > 0])
    outside = np.isin(labels, outside_labels)
    return replace(grid, inside=empty & ~outside)
