"""Attention-weighted mean-shift clustering of the joint network's votes.

Every vertex, moved by the network toward its joint, is a vote weighted by
its attention; the modes of the weighted kernel density are the joints
(RigNet's clustering). The kernel is a Gaussian whose width is the
*bandwidth*: wide kernels merge nearby votes into few joints, narrow ones
keep more (the level of detail). Seeds are the weighted centres of cubic
bins half a bandwidth wide, so the cost grows with the character's extent
over the bandwidth, not with the vote count, and re-clustering at a new
bandwidth takes a fraction of a second.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

#: Votes with less attention than this are left out (they would move the
#: modes by less than the iteration tolerance but cost time).
ATTENTION_FLOOR = 0.05
#: Mean-shift steps at most, and the step (share of the bandwidth) below
#: which a seed has converged.
MAX_ITERATIONS = 60
CONVERGED_STEP = 1e-3
#: Votes farther than this many bandwidths from a seed are left out of its
#: kernel mean (their Gaussian weight is below 1e-4 of the nearest's).
KERNEL_REACH = 4.0
#: Seeds closer than this share of the bandwidth are merged while they move
#: (they would converge to the same mode), so the work shrinks as they do.
SEED_MERGE_SHARE = 0.05


def _kernel_step(seeds: np.ndarray, tree: cKDTree, points: np.ndarray, weights: np.ndarray, bandwidth: float):
    """Weighted kernel means at ``seeds`` and the kernel density there.

    The kernel's pairs are summed per seed with ``bincount``: a sparse
    matrix would sort them first, which took 60 % of the clustering."""
    near = cKDTree(seeds).sparse_distance_matrix(tree, KERNEL_REACH * bandwidth, output_type="ndarray")
    values = np.exp(-0.5 * (near["v"] / bandwidth) ** 2) * weights[near["j"]]
    density = np.bincount(near["i"], values, minlength=len(seeds))
    sums = np.stack([np.bincount(near["i"], values * points[near["j"], axis], minlength=len(seeds))
                     for axis in range(3)], axis=1)
    means = np.divide(sums, density[:, None], out=seeds.copy(), where=density[:, None] > 0)
    return means, density


def _merged(seeds: np.ndarray, spacing: float) -> np.ndarray:
    """One seed per cell of a grid of ``spacing``: seeds that met."""
    _, first = np.unique(np.floor(seeds / spacing).astype(np.int64), axis=0, return_index=True)
    return seeds[np.sort(first)]


def mean_shift_modes(points: np.ndarray, weights: np.ndarray, bandwidth: float,
                     density_threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """The modes of the votes, strongest first.

    Parameters
    ----------
    points : (n, 3) float array, the votes
    weights : (n,) float array >= 0, their attention
    bandwidth : float > 0, the kernel's standard deviation
    density_threshold : float in [0, 1], modes whose density is below this
        share of the strongest mode's are dropped

    Returns
    -------
    modes : (m, 3) float64
    density : (m,) float64, kernel density at each mode (sum of weights)
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    weights = np.asarray(weights, dtype=np.float64).reshape(-1)
    kept = weights > ATTENTION_FLOOR * max(float(weights.max(initial=0.0)), 1e-12)
    points, weights = points[kept], weights[kept]
    if not len(points):
        return np.zeros((0, 3)), np.zeros(0)
    tree = cKDTree(points)
    bins = np.floor(points / (0.5 * bandwidth)).astype(np.int64)
    _, label = np.unique(bins, axis=0, return_inverse=True)
    label = label.reshape(-1)
    bin_weight = np.bincount(label, weights)
    seeds = np.stack([np.bincount(label, weights * points[:, axis]) for axis in range(3)], axis=1) / bin_weight[:, None]
    for _ in range(MAX_ITERATIONS):
        moved, _ = _kernel_step(seeds, tree, points, weights, bandwidth)
        step = np.linalg.norm(moved - seeds, axis=1).max()
        seeds = _merged(moved, SEED_MERGE_SHARE * bandwidth)
        if step < CONVERGED_STEP * bandwidth:
            break
    _, density = _kernel_step(seeds, tree, points, weights, bandwidth)
    modes, mode_density = [], []
    # Strongest first; densities within a millionth of the strongest's tie and
    # go by position, so mirrored joints (equal density up to rounding, which
    # differs with the number of BLAS threads) come in the same order on every
    # machine.
    rounded = np.round(density / max(float(density.max(initial=0.0)), 1e-300), 6)
    for index in np.lexsort((seeds[:, 2], seeds[:, 1], seeds[:, 0], -rounded)):
        if all(np.linalg.norm(seeds[index] - mode) > bandwidth for mode in modes):
            modes.append(seeds[index])
            mode_density.append(density[index])
    modes, mode_density = np.array(modes), np.array(mode_density)
    strong = mode_density >= density_threshold * mode_density.max()
    return modes[strong], mode_density[strong]
