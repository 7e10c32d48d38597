"""A simplified proxy of a big mesh, and carrying values from it back to every vertex.

Jobs whose cost grows with the vertex count (skin weights from bone
distances, the skinning networks) run on a proxy of a few thousand vertices
and carry the result back. Two halves, both numpy/scipy only:

**Simplification** is vertex clustering (Rossignac & Borrel 1993) made safe
for characters. The seams are welded first (:func:`.weld.weld_mesh`), then
vertices are grouped by the cell of a regular grid they fall in *and* by
the axis direction their normal is closest to (six directions, so the two
sides of a finger or of an ear, thinner than a cell, stay apart), and a
group is split further into the pieces its own edges connect (so a loose
button, or two fingers sharing a cell, are never merged). Each cluster
becomes one proxy vertex at the mean of its members; triangles keep their
corners' clusters, and those that collapse (two corners in one cluster,
zero area) or repeat another are dropped. The cell size is searched for so
the proxy has about the vertex count asked for. Every connected part of the
mesh keeps proxy vertices of its own, however small (lone vertices, in no
triangle, share one per cell).

**Carrying back** is barycentric interpolation at the closest point of the
proxy *surface*, not a copy from the nearest proxy vertex (which leaves
blocky seams along cluster borders). A vertex looks only at the proxy
triangles around its own cluster's vertex and, where its closest point
there lies on their outer rim, around the clusters joined to its own by an
edge: that is the surface it was simplified into, so a loose part never
takes values from a body it touches and a finger never takes them from the
finger beside it. A vertex whose neighbourhood kept no triangle (a loose
part smaller than a cell) takes its cluster's value. The carry-back is one
sparse ``(n, p)`` matrix with at most three entries per row, non-negative
and summing to one: linear functions of position are carried exactly
wherever the vertex lies on the proxy surface, and everywhere within
``|gradient|`` times the vertex's distance to its closest proxy point (at
most a cell diagonal when its cluster's vertex is in a triangle).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..types import Mesh
from .closest_point import closest_points_on_triangles
from .normals import triangle_double_areas, vertex_normals
from .topology import edges
from .weld import weld_mesh

#: The proxy's vertex count may miss the target by this share (the cell
#: size search stops there).
COUNT_TOLERANCE = 0.1
#: Cell sizes tried at most when searching for the target vertex count.
MAX_SIZE_STEPS = 8
#: Cells along each axis at most (keeps cell keys within int64).
MAX_CELLS_PER_AXIS = 1 << 18
#: A proxy triangle whose doubled area is below this fraction of the
#: squared cell size is degenerate and dropped.
DEGENERATE_AREA_FRACTION = 1e-10
#: Vertex-triangle pairs tested per batch when carrying values back (bounds
#: memory: about 400 bytes per pair).
CARRY_PAIRS_PER_BATCH = 1 << 18
#: Rows carried back per batch by :meth:`Proxy.carry` (bounds the memory of
#: the dense rows a ``finish`` step sees).
CARRY_ROWS_PER_BATCH = 1 << 14
#: Normal direction classes: the six axis directions, plus one for vertices
#: without a normal (in no triangle, or only in degenerate ones).
_DIRECTION_CLASSES = 7


@dataclass(frozen=True)
class Proxy:
    """A simplified mesh and the map from it back to the original vertices.

    Attributes
    ----------
    mesh : Mesh
        The proxy: ``p`` vertices, one object named after the original's first.
    interpolation : (n, p) scipy.sparse.csr_matrix
        Row ``i`` holds the barycentric coordinates of original vertex
        ``i``'s closest proxy surface point (at most three non-zeros,
        non-negative, summing to one): ``interpolation @ values`` carries
        per-proxy-vertex values back.
    cluster : (n,) int64 array
        The proxy vertex each original vertex was merged into.
    cell_size : float
        Edge of the clustering grid's cells, scene units (0 when the proxy
        is the welded mesh itself).
    """

    mesh: Mesh
    interpolation: sp.csr_matrix
    cluster: np.ndarray
    cell_size: float

    def average(self, values: np.ndarray) -> np.ndarray:
        """(p, k) mean of per-original-vertex ``values`` (n, k) over each
        proxy vertex's cluster (to give the proxy values measured on the
        original, e.g. distances)."""
        values = np.asarray(values, dtype=np.float64)
        counts = np.bincount(self.cluster, minlength=self.mesh.vertex_count)
        pooling = sp.csr_matrix(
            (1.0 / counts[self.cluster], (self.cluster, np.arange(len(self.cluster)))),
            shape=(self.mesh.vertex_count, len(self.cluster)),
        )
        return np.asarray(pooling @ values).reshape((self.mesh.vertex_count,) + values.shape[1:])

    def carry(self, values: np.ndarray, finish: Callable[[slice, np.ndarray], np.ndarray] | None = None) -> np.ndarray:
        """Per-proxy-vertex ``values`` (p, k) interpolated at every original vertex.

        Parameters
        ----------
        values : (p, k) float array
        finish : callable, optional
            ``finish(rows, carried)`` turns each batch of carried rows (a
            slice of the original vertices and their ``(r, k)`` values) into
            the rows to return (same shape), e.g. an influence limit and
            normalisation applied last, on the full mesh. Batches of
            :data:`CARRY_ROWS_PER_BATCH` rows bound the memory it sees.

        Returns
        -------
        (n, k) float64 array
        """
        values = np.asarray(values, dtype=np.float64).reshape(self.mesh.vertex_count, -1)
        if finish is None:
            return np.asarray(self.interpolation @ values)
        n = self.interpolation.shape[0]
        out = np.empty((n, values.shape[1]))
        for start in range(0, n, CARRY_ROWS_PER_BATCH):
            rows = slice(start, min(start + CARRY_ROWS_PER_BATCH, n))
            out[rows] = finish(rows, np.asarray(self.interpolation[rows] @ values))
        return out


def simplified_proxy(mesh: Mesh, target_vertices: int) -> Proxy:
    """A proxy of ``mesh`` with about ``target_vertices`` vertices (see the
    module docstring).

    Parameters
    ----------
    mesh : Mesh with n >= 1 vertices (any number of objects and parts)
    target_vertices : int >= 1, the proxy vertex count wanted; a mesh whose
        welded vertex count is at most this is its own proxy (welded)

    Returns
    -------
    Proxy; its vertex count is within :data:`COUNT_TOLERANCE` of the target
    when the search converges, and never below the number of connected
    parts of the welded mesh.
    """
    welded, to_welded = weld_mesh(mesh)
    V, F = welded.vertices, welded.triangles
    if welded.vertex_count <= target_vertices:
        labels, size = np.arange(welded.vertex_count), 0.0
    else:
        labels, size = _cluster_for_count(V, F, int(target_vertices))
    count = int(labels.max()) + 1
    members = np.bincount(labels, minlength=count)
    proxy_V = (np.stack([np.bincount(labels, V[:, axis], minlength=count) for axis in range(3)], axis=1)
               / members[:, None])
    proxy_F = _proxy_triangles(proxy_V, labels[F], size)
    proxy = Mesh(proxy_V, proxy_F, object_names=mesh.object_names[:1])
    welded_rows = _interpolation(V, F, labels, proxy)
    return Proxy(proxy, welded_rows[to_welded].tocsr(), labels[to_welded], size)


def _direction_classes(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(n,) int in [0, 7): the axis direction (+x, -x, +y, ...) closest to
    each vertex normal; 6 for vertices without one."""
    normals = vertex_normals(V, F)
    axis = np.abs(normals).argmax(axis=1)
    negative = normals[np.arange(len(V)), axis] < 0
    classes = 2 * axis + negative
    classes[~normals.any(axis=1)] = _DIRECTION_CLASSES - 1
    return classes


def _cluster_for_count(V: np.ndarray, F: np.ndarray, target: int) -> tuple[np.ndarray, float]:
    """Cluster labels whose count is near ``target``, and the cell size used.

    The count falls roughly as the square of the cell size (a surface), so
    each step scales the size by the square root of count over target.
    """
    low, high = V.min(axis=0), V.max(axis=0)
    extent = float(np.max(high - low))
    directions = _direction_classes(V, F)
    unique_edges = edges(F) if len(F) else np.zeros((0, 2), np.int64)
    in_triangle = np.zeros(len(V), dtype=bool)
    in_triangle[F.ravel()] = True
    area = 0.5 * float(triangle_double_areas(V, F).sum()) if len(F) else 0.0
    size = np.sqrt(area / target) if area > 0 else extent / max(target, 1)
    best = None
    for _ in range(MAX_SIZE_STEPS):
        size = max(size, extent / MAX_CELLS_PER_AXIS, 1e-300)
        labels = _clusters(V, low, size, directions, unique_edges, in_triangle)
        count = int(labels.max()) + 1
        if best is None or abs(np.log(count / target)) < abs(np.log(best[2] / target)):
            best = (labels, size, count)
        if abs(count / target - 1.0) <= COUNT_TOLERANCE:
            break
        size *= float(np.clip(np.sqrt(count / target), 0.5, 2.0))
    return best[0], best[1]


def _clusters(V, low, size, directions, unique_edges, in_triangle) -> np.ndarray:
    """(n,) int64 contiguous cluster labels for cells of edge ``size``.

    A cluster is a piece of (cell, normal direction) joined by its own
    edges; vertices in no triangle are grouped by cell alone.
    """
    n = len(V)
    cells = np.floor((V - low) / size).astype(np.int64)
    dims = cells.max(axis=0) + 1
    key = np.ravel_multi_index(tuple(cells.T), tuple(dims)) * _DIRECTION_CLASSES + directions
    inside = unique_edges[key[unique_edges[:, 0]] == key[unique_edges[:, 1]]]
    graph = sp.coo_matrix((np.ones(len(inside)), (inside[:, 0], inside[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    loose = ~in_triangle
    if loose.any():
        _, loose_group = np.unique(key[loose], return_inverse=True)
        labels = labels.copy()
        labels[loose] = labels.max() + 1 + loose_group
    return np.unique(labels, return_inverse=True)[1].astype(np.int64)


def _proxy_triangles(proxy_V: np.ndarray, F: np.ndarray, size: float) -> np.ndarray:
    """(t, 3) int64: the clustered triangles ``F`` without collapsed,
    zero-area or repeated ones (the first orientation of a repeat is kept)."""
    distinct = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])
    F = F[distinct]
    if not len(F):
        return np.zeros((0, 3), np.int64)
    _, first = np.unique(np.sort(F, axis=1), axis=0, return_index=True)
    F = F[np.sort(first)]
    floor = DEGENERATE_AREA_FRACTION * size**2
    return F[triangle_double_areas(proxy_V, F) > floor].astype(np.int64)


def _interpolation(V: np.ndarray, F: np.ndarray, labels: np.ndarray, proxy: Mesh) -> sp.csr_matrix:
    """(n, p) barycentric rows of each welded vertex's closest point on the
    proxy surface near its own cluster.

    First among the triangles around the cluster's vertex (its star); where
    that point lies on the star's outer rim, or the star is empty, again
    among the triangles around every cluster joined to it by an edge; the
    cluster's own vertex where those hold no triangle either. Starting from
    the star keeps a vertex on the surface it was simplified into where a
    fold of the same part (the next finger) comes closer.
    """
    n, p = len(V), proxy.vertex_count
    PF = proxy.triangles
    pairs = labels[edges(F)] if len(F) else np.zeros((0, 2), np.int64)
    joined = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(p, p))
    joined = ((joined + joined.T + sp.identity(p)) > 0).astype(np.float64)
    star = sp.csr_matrix((np.ones(PF.size), (PF.ravel(), np.repeat(np.arange(len(PF)), 3))), shape=(p, len(PF)))
    star.sum_duplicates()
    ring = ((joined.tocsr() @ star) > 0).tocsr()
    ring.sort_indices()

    triangle = np.full(n, -1, dtype=np.int64)
    barycentric = np.zeros((n, 3))
    first = np.flatnonzero(np.diff(star.indptr)[labels] > 0)
    triangle[first], barycentric[first] = _closest_in_lists(V[first], labels[first], star, proxy)
    own_weight = np.where(PF[triangle[first]] == labels[first, None], barycentric[first], 0.0).sum(axis=1)
    again = np.concatenate([np.flatnonzero(np.diff(star.indptr)[labels] == 0), first[own_weight <= 0.0]])
    again = again[np.diff(ring.indptr)[labels[again]] > 0]
    triangle[again], barycentric[again] = _closest_in_lists(V[again], labels[again], ring, proxy)

    found = triangle >= 0
    # Round-off can leave a coordinate at -1e-16: clamp, so carried weights stay non-negative.
    barycentric = np.maximum(barycentric[found], 0.0)
    barycentric /= barycentric.sum(axis=1, keepdims=True)
    alone = np.flatnonzero(~found)
    rows = np.concatenate([np.repeat(np.flatnonzero(found), 3), alone])
    columns = np.concatenate([PF[triangle[found]].ravel(), labels[alone]])
    values = np.concatenate([barycentric.ravel(), np.ones(len(alone))])
    matrix = sp.csr_matrix((values, (rows, columns)), shape=(n, p))
    matrix.eliminate_zeros()
    return matrix


def _closest_in_lists(points: np.ndarray, clusters: np.ndarray, lists: sp.csr_matrix, proxy: Mesh):
    """Closest point of each of ``points`` (q, 3) on the proxy triangles of
    row ``clusters[i]`` of ``lists`` (p, t) (every such row non-empty),
    in batches of :data:`CARRY_PAIRS_PER_BATCH` pairs.

    Returns
    -------
    triangle : (q,) int64 array
    barycentric : (q, 3) float64 array
    """
    counts = np.diff(lists.indptr)[clusters]
    cumulative = np.cumsum(counts)
    triangle, barycentric = np.empty(len(points), dtype=np.int64), np.empty((len(points), 3))
    start = 0
    while start < len(points):
        # The most points whose pairs fit the budget (at least one).
        base = cumulative[start - 1] if start else 0
        stop = max(int(np.searchsorted(cumulative, base + CARRY_PAIRS_PER_BATCH, side="right")), start + 1)
        batch = slice(start, stop)
        triangle[batch], barycentric[batch] = _closest_pairs(points[batch], clusters[batch], counts[batch], lists,
                                                              proxy)
        start = stop
    return triangle, barycentric


def _closest_pairs(points, clusters, counts, lists, proxy):
    """:func:`_closest_in_lists` for one batch: every (point, triangle) pair at once."""
    owner = np.repeat(np.arange(len(points)), counts)
    starts = np.cumsum(counts) - counts
    triangle = lists.indices[np.repeat(lists.indptr[clusters] - starts, counts) + np.arange(len(owner))]
    corners = proxy.triangles[triangle]
    P = points[owner]
    closest, barycentric = closest_points_on_triangles(P, *(proxy.vertices[corners[:, k]] for k in range(3)))
    squared = np.einsum("ij,ij->i", closest - P, closest - P)
    # Per point, the first pair of least distance (pairs are grouped by point).
    least = np.minimum.reduceat(squared, starts)
    ties = np.flatnonzero(squared <= least[owner])
    pick = ties[np.concatenate([[True], owner[ties[1:]] != owner[ties[:-1]]])]
    return triangle[pick], barycentric[pick]
