"""The augmentation every network's training shares: the character turned by
a small random angle about the up axis and mirrored left-right with
probability one half, applied to the 3-vector columns of its feature tables
(a turn or a mirror changes no distance, so no example has to be rebuilt).

The random numbers are drawn in a fixed order (the angle, then the mirror
coin), so a run with a given seed reproduces.
"""

from __future__ import annotations

import math

import numpy as np
import torch

#: Largest turn about the up axis applied to a training character (degrees):
#: inputs are normalised to face -y, so only small deviations remain.
TURN_DEGREES = 15.0
#: Probability that a training character is mirrored left-right (x -> -x).
MIRROR_PROBABILITY = 0.5


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


def turned_columns(columns: torch.Tensor, starts: tuple, matrix: torch.Tensor) -> torch.Tensor:
    """``columns`` with each 3-vector starting at a column of ``starts`` turned by ``matrix``.

    Parameters
    ----------
    columns : (..., c) tensor, a feature table (the last axis is the features)
    starts : tuple of int, increasing first columns of the 3-vectors (positions, normals, ...)
    matrix : (3, 3) tensor of ``columns``' dtype and device

    Returns
    -------
    (..., c) tensor: the vectors ``v @ matrix.T``, every other column as it was.
    """
    pieces, position = [], 0
    for start in starts:
        pieces.append(columns[..., position:start])
        pieces.append(columns[..., start:start + 3] @ matrix.T)
        position = start + 3
    pieces.append(columns[..., position:])
    return torch.cat(pieces, dim=-1)
