"""Edge stretch: how much a skinned mesh's edges change length when posed.

Judges weights that have no reference to compare with (a weight transfer
onto a garment): good weights move neighbouring vertices together, so edges
keep their length.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..geometry.bounding_box import bounding_box_diagonal
from ..skeleton.posing import posed_vertices, random_poses
from ..types import Skeleton
from .deform_weights import deform_weight_matrix

#: Rest edges shorter than this share of the mesh size are skipped by
#: :func:`edge_stretch`: their relative change is numerically meaningless.
DEGENERATE_EDGE_FRACTION = 1e-9

#: Percentile of the pooled stretches reported as ``p99``.
STRETCH_PERCENTILE = 99.0


def edge_stretch(vertices: np.ndarray, edges: np.ndarray, posed: np.ndarray) -> dict:
    """Relative change of edge lengths between rest and posed meshes.

    The stretch of an edge is ``|l_posed - l_rest| / l_rest``; shrinking
    counts like stretching. Edges whose rest length is below
    :data:`DEGENERATE_EDGE_FRACTION` of the rest bounding-box diagonal are
    skipped. Stretches of all edges in all poses are pooled.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions.
    edges : (e, 2) int64 array
        Vertex index pairs, e.g. :func:`~..geometry.topology.edges` of the
        triangles.
    posed : (n, 3) or (p, n, 3) float64 array
        One or several posed copies of ``vertices``.

    Returns
    -------
    dict with float values
        ``p99``: :data:`STRETCH_PERCENTILE` th percentile (linear
        interpolation) and ``max`` of the relative stretch (a ratio, 0.1 =
        10 %). Both 0 when no edge counts.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    posed = np.asarray(posed, dtype=np.float64)
    posed = posed.reshape((-1,) + vertices.shape) if posed.size else posed.reshape(0, *vertices.shape)
    if len(edges) and (edges.min() < 0 or edges.max() >= len(vertices)):
        raise InputError("An edge refers to a vertex that does not exist.")
    rest_length = np.linalg.norm(vertices[edges[:, 1]] - vertices[edges[:, 0]], axis=1)
    valid = rest_length > DEGENERATE_EDGE_FRACTION * bounding_box_diagonal(vertices)
    edges, rest_length = edges[valid], rest_length[valid]
    if not len(edges) or not len(posed):
        return {"p99": 0.0, "max": 0.0}
    posed_length = np.linalg.norm(posed[:, edges[:, 1]] - posed[:, edges[:, 0]], axis=2)
    stretch = np.abs(posed_length - rest_length) / rest_length
    return {"p99": float(np.percentile(stretch, STRETCH_PERCENTILE)), "max": float(stretch.max())}


def posed_edge_stretch(
    vertices: np.ndarray,
    edges: np.ndarray,
    weights,
    skeleton: Skeleton,
    poses: np.ndarray | None = None,
) -> dict:
    """Edge stretch of a mesh skinned with ``weights`` over several poses.

    Parameters
    ----------
    vertices : (n, 3) float64 array
    edges : (e, 2) int64 array
    weights : (n, d) float64 array or Weights
        See :func:`~.deform_weights.deform_weight_matrix`.
    skeleton : Skeleton
    poses : (p, d, 3, 3) float64 array, optional
        Default :func:`~..skeleton.posing.random_poses` with its defaults.

    Returns
    -------
    dict with float values
        ``p99`` and ``max`` as in :func:`edge_stretch`.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    matrix = deform_weight_matrix(weights, skeleton, len(vertices))
    if poses is None:
        poses = random_poses(skeleton)
    return edge_stretch(vertices, edges, posed_vertices(vertices, matrix, skeleton, poses))
