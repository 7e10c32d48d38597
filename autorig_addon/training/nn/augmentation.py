"""The augmentation every network's training shares: the character turned by
a small random angle about the up axis and mirrored left-right with
probability one half, applied to the 3-vector columns of its feature tables
(a turn or a mirror changes no distance, so no example has to be rebuilt);
and the range the training sets stretch characters by.

The random numbers are drawn in a fixed order (the angle, then the mirror
coin), so a run with a given seed reproduces.
"""

from __future__ import annotations

import math

import numpy as np

from ...core.nn.operations import Array, Operations

#: Largest turn about the up axis applied to a training character (degrees):
#: inputs are normalised to face -y, so only small deviations remain.
TURN_DEGREES = 15.0
#: Probability that a training character is mirrored left-right (x -> -x).
MIRROR_PROBABILITY = 0.5
#: Range of the per-axis factors the training sets stretch characters by
#: (thin and stout, tall and short; each variant is normalised again, so
#: its distances are computed anew and it is built once, not on the fly).
STRETCH_RANGE = (0.8, 1.25)


def turn_and_mirror(rng: np.random.Generator) -> np.ndarray:
    """A random (3, 3) matrix: a turn about z within :data:`TURN_DEGREES`,
    then, with probability :data:`MIRROR_PROBABILITY`, a mirror of x
    (applied first to a point: ``turn @ mirror``).

    Draws ``rng.uniform`` once (the angle), then ``rng.random`` once (the mirror).
    """
    angle = math.radians(rng.uniform(-TURN_DEGREES, TURN_DEGREES))
    cosine, sine = math.cos(angle), math.sin(angle)
    matrix = np.array([[cosine, -sine, 0.0], [sine, cosine, 0.0], [0.0, 0.0, 1.0]])
    if rng.random() < MIRROR_PROBABILITY:
        matrix = matrix @ np.diag([-1.0, 1.0, 1.0])
    return matrix


def turned_columns(ops: Operations, columns: Array, starts: tuple, matrix: Array) -> Array:
    """``columns`` with each 3-vector starting at a column of ``starts`` turned by ``matrix``.

    Parameters
    ----------
    ops : Operations of ``columns``' kind (numpy or torch)
    columns : (..., c) array, a feature table (the last axis is the features)
    starts : tuple of int, increasing first columns of the 3-vectors (positions, normals, ...)
    matrix : (3, 3) array of ``columns``' kind, dtype and device

    Returns
    -------
    (..., c) array: the vectors ``v @ matrix.T``, every other column as it was.
    """
    pieces, position = [], 0
    for start in starts:
        pieces.append(columns[..., position:start])
        pieces.append(columns[..., start:start + 3] @ matrix.T)
        position = start + 3
    pieces.append(columns[..., position:])
    return ops.concat(pieces, -1)
