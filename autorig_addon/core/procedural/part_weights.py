"""Weights of generated parts, derived from how each part was built.

* Along a bone chain (body shells, driven garments, hair), a vertex belongs
  to the bone it lies along and blends linearly into the neighbouring bone
  near a joint (:func:`joint_blend_weights`).
* A cloth vertex takes the body's weights at its closest body point
  (:func:`closest_point_weights`).
* Each part keeps weights over its own few bones: a block of columns with
  their bone names. :func:`stack_weight_blocks` and :func:`sum_weight_blocks`
  combine such blocks into one matrix over the union of the names.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..geometry.closest_point import closest_points_on_triangles

#: Body triangles examined per cloth vertex when looking for the closest body point.
CLOSEST_POINT_CANDIDATES = 8
#: Distances equal within this (relative to 1 + the distance) count as ties.
TIE_TOLERANCE = 1e-9


def joint_blend_weights(arc, joint_arc, blend, with_parent, with_child):
    """Weights along a chain: each bone owns its stretch, blending linearly
    into its neighbour within ``blend`` x (shorter bone) of each joint.

    Parameters
    ----------
    arc : (n,) float64 array
        Arc length of each sample along the chain.
    joint_arc : (k + 1,) float64 array
        Arc length of each joint (0 first, chain length last).
    blend : float
        Half-width of a joint region as a fraction of the shorter bone (< 0.5).
    with_parent, with_child : bool
        Whether the chain blends into a bone before its first joint / after
        its last joint.

    Returns
    -------
    (n, k + with_parent + with_child) float64 array
        Columns: [parent], bones in chain order, [child]; rows sum to one.
    """
    lengths = np.maximum(np.diff(joint_arc), 1e-12)
    count = len(lengths)
    shorter = np.concatenate([[lengths[0]], np.minimum(lengths[:-1], lengths[1:]), [lengths[-1]]])
    half_width = blend * shorter
    rise = np.clip((arc[:, None] - joint_arc[None, :]) / (2.0 * half_width[None, :]) + 0.5, 0.0, 1.0)
    if not with_parent:
        rise[:, 0] = 1.0
    if not with_child:
        rise[:, count] = 0.0
    columns = [rise[:, :count] - rise[:, 1:]]
    if with_parent:
        columns.insert(0, 1.0 - rise[:, :1])
    if with_child:
        columns.append(rise[:, count:])
    return np.concatenate(columns, axis=1)


def closest_point_weights(points, body_vertices, body_triangles, body_weights):
    """Body weights interpolated at the closest body point of each point.

    The closest point is searched among the :data:`CLOSEST_POINT_CANDIDATES`
    triangles whose centroids are nearest, which finds the true closest
    point on the smooth, evenly meshed shells built here. A point at the
    same distance from several distinct places takes their mean.

    Parameters
    ----------
    points : (m, 3) float64 array
    body_vertices : (n, 3) float64 array
    body_triangles : (t, 3) int64 array
    body_weights : (n, b) float64 array

    Returns
    -------
    (m, b) float64 array
    """
    corners = body_vertices[body_triangles]
    tree = cKDTree(corners.mean(axis=1))
    count = min(CLOSEST_POINT_CANDIDATES, len(body_triangles))
    _, candidates = tree.query(points, k=count)
    candidates = candidates.reshape(len(points), count)
    flat = candidates.reshape(-1)
    repeated = np.repeat(points, count, axis=0)
    closest, bary = closest_points_on_triangles(repeated, corners[flat, 0], corners[flat, 1], corners[flat, 2])
    distance = np.linalg.norm(closest - repeated, axis=1).reshape(len(points), count)
    closest = closest.reshape(len(points), count, 3)
    # Points equally far from several places (a skirt's midline between the
    # legs) average them, so symmetric bodies give symmetric cloth weights.
    tolerance = TIE_TOLERANCE * (1.0 + distance.min(axis=1, keepdims=True))
    tied = distance <= distance.min(axis=1, keepdims=True) + tolerance
    same_place = np.linalg.norm(closest[:, :, None, :] - closest[:, None, :, :], axis=3) <= tolerance[:, :, None]
    earlier_twin = (np.tril(same_place, k=-1) & tied[:, None, :]).any(axis=2)
    use = tied & ~earlier_twin
    candidate_weights = np.einsum("mkc,mkcb->mkb", bary.reshape(len(points), count, 3),
                                  body_weights[body_triangles[candidates]])
    return (use[:, :, None] * candidate_weights).sum(axis=1) / use.sum(axis=1, keepdims=True)


def _union_columns(blocks):
    """Bone names of all ``(names, weights)`` blocks, first seen first, and
    the column of each name."""
    names = []
    for block_names, _ in blocks:
        for name in block_names:
            if name not in names:
                names.append(name)
    return tuple(names), {name: k for k, name in enumerate(names)}


def _add_block(matrix, column, block_names, block):
    for k, name in enumerate(block_names):
        matrix[:, column[name]] += block[:, k]


def stack_weight_blocks(blocks):
    """Weight blocks of successive rows -> one matrix over the union of names.

    Parameters
    ----------
    blocks : sequence of (names, (n_i, k_i) float64 array)
        Each block's rows are its own vertices; its columns are the bones
        ``names`` (k_i str).

    Returns
    -------
    names : tuple of b str
        Every name once, in first-seen order.
    weights : (sum n_i, b) float64 array
        The blocks one under the other; a name repeated within a block adds up.
    """
    names, column = _union_columns(blocks)
    matrix = np.zeros((sum(len(w) for _, w in blocks), len(names)))
    row = 0
    for block_names, block in blocks:
        _add_block(matrix[row:row + len(block)], column, block_names, block)
        row += len(block)
    return names, matrix


def sum_weight_blocks(blocks):
    """Weight blocks over the same rows, added up by bone name.

    Parameters
    ----------
    blocks : sequence of (names, (n, k_i) float64 array)

    Returns
    -------
    names : tuple of b str
        Every name once, in first-seen order.
    weights : (n, b) float64 array
    """
    names, column = _union_columns(blocks)
    matrix = np.zeros((len(blocks[0][1]), len(names)))
    for block_names, block in blocks:
        _add_block(matrix, column, block_names, block)
    return names, matrix
