"""The skinned source of a transfer, checked and indexed once.

Dressing a body means transferring from one source onto many garments. The
work that depends on the source alone (checking every row of its weight
matrix, cleaning them, the closest-point index of its surface, its normals)
costs more than transferring onto a small garment, so it is done once here
and reused by every :func:`~.transfer.transfer_weights` call given the same
:class:`TransferSource`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..errors import InputError
from ..geometry.closest_point import SurfacePoints, TriangleMeshQuery
from ..geometry.normals import vertex_normals
from ..geometry.outliers import require_finite_positions
from ..types import Mesh, Weights
from ..weights import invalid_rows, normalize_rows, usable_rows

#: A closest point drawing more than this share of its (barycentric) weight
#: from source vertices without usable weights does not count as a match.
MAX_UNWEIGHTED_SHARE = 1e-3


@dataclass(frozen=True, eq=False)
class TransferSource:
    """A skinned surface ready to transfer from (:meth:`prepare`).

    Attributes
    ----------
    mesh : Mesh, world space, with triangles and finite positions
    weights : Weights, (n_s, b), as given (raw)
    usable : (n_s,) bool array, rows with usable weights
        (:func:`~autorig_addon.core.weights.usable_rows`); at least one
    invalid_count : int, rows with NaN, infinite or negative entries
    clean_weights : (n_s, b) scipy.sparse.csr_matrix, usable rows normalised,
        others empty (a body's rows hold a few bones each: interpolating
        them sparsely costs a fraction of the dense rows)
    query : TriangleMeshQuery of the surface
    normals : (n_s, 3) float64 array, unit vertex normals
    diagonal : float, the bounding-box diagonal
    """

    mesh: Mesh
    weights: Weights
    usable: np.ndarray
    invalid_count: int
    clean_weights: sp.csr_matrix
    query: TriangleMeshQuery
    normals: np.ndarray
    diagonal: float

    @classmethod
    def prepare(cls, mesh: Mesh, weights: Weights) -> "TransferSource":
        """Check ``mesh`` and ``weights`` and index them.

        Raises
        ------
        InputError when the source has no faces or a non-finite vertex, the
        rows do not match the vertices, or no row is usable (saying whether
        the weights are missing or corrupt).
        """
        name = mesh.object_names[0]
        if not len(mesh.triangles):
            raise InputError(f"The source '{name}' has no faces; weights are transferred from a surface.")
        if weights.vertex_count != mesh.vertex_count:
            raise InputError("The source weights do not have one row per source vertex.")
        matrix = np.asarray(weights.matrix, dtype=np.float64)
        invalid = invalid_rows(matrix) if weights.bone_names else np.zeros(mesh.vertex_count, bool)
        usable = usable_rows(matrix) if weights.bone_names else np.zeros(mesh.vertex_count, bool)
        if not usable.any():
            invalid_count = int(np.count_nonzero(invalid))
            if invalid_count:
                raise InputError(
                    f"The source '{name}' has no usable weights: {invalid_count} of its {mesh.vertex_count} vertices "
                    "have NaN, infinite or negative weights and the others none. Clean the weights (Weights > Clean) "
                    "or skin the body again."
                )
            raise InputError(f"The source '{name}' carries no bone weights to transfer.")
        require_finite_positions(mesh.vertices, mesh.object_names, mesh.object_offsets)
        rows, columns = np.nonzero((matrix > 0) & usable[:, None])  # row by row, as CSR stores them
        values = matrix[rows, columns]
        values /= np.bincount(rows, weights=values, minlength=mesh.vertex_count)[rows]
        row_starts = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=mesh.vertex_count))])
        clean = sp.csr_matrix((values, columns, row_starts), shape=matrix.shape)
        return cls(
            mesh=mesh,
            weights=weights,
            usable=usable,
            invalid_count=int(np.count_nonzero(invalid)),
            clean_weights=clean,
            query=TriangleMeshQuery(mesh.vertices, mesh.triangles),
            normals=vertex_normals(mesh.vertices, mesh.triangles),
            diagonal=mesh.bounding_box_diagonal,
        )

    @property
    def name(self) -> str:
        return self.mesh.object_names[0]

    def weights_at(self, surface: SurfacePoints, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Source weights at ``surface``'s closest points of the (q, 3) ``points``.

        Returns
        -------
        weights : (q, b) float64 array, rows normalised and never empty: those
            at the closest point where it carries usable weight, else those of
            the nearest source vertex that does
        weighted : (q,) bool array, the closest point carries usable weight
        """
        triangles = self.mesh.triangles
        count = len(surface.triangles)
        corners = triangles[surface.triangles]
        interpolation = sp.csr_matrix(
            (surface.barycentric.ravel(), (np.repeat(np.arange(count), 3), corners.ravel())),
            shape=(count, self.mesh.vertex_count),
        )
        weights = normalize_rows((interpolation @ self.clean_weights).toarray())
        share = surface.interpolate(triangles, self.usable.astype(np.float64))
        weighted = share >= 1.0 - MAX_UNWEIGHTED_SHARE
        if not weighted.all():
            candidates, tree = self._nearest_usable_index
            _, nearest = tree.query(points[~weighted])
            weights[~weighted] = self.clean_weights[candidates[nearest]].toarray()
        return weights, weighted

    def interpolated_normals(self, surface: SurfacePoints) -> np.ndarray:
        """(q, 3) float64 array: the source's vertex normals interpolated at
        the closest points (not unit length)."""
        return surface.interpolate(self.mesh.triangles, self.normals)

    @cached_property
    def _nearest_usable_index(self) -> tuple[np.ndarray, cKDTree]:
        # Built on first need: most bodies are weighted everywhere.
        candidates = np.flatnonzero(self.usable)
        return candidates, cKDTree(self.mesh.vertices[candidates])


def prepared_source(source: Mesh, source_weights: Weights, prepared: TransferSource | None) -> TransferSource:
    """``prepared`` when it was made from these very ``source`` and
    ``source_weights`` objects, else a new :class:`TransferSource`.

    Raises
    ------
    ValueError when ``prepared`` belongs to other objects (a caller's bug:
    its weights would be transferred instead of the ones passed).
    """
    if prepared is None:
        return TransferSource.prepare(source, source_weights)
    if prepared.mesh is not source or prepared.weights is not source_weights:
        raise ValueError("The prepared source was made from another mesh or weights than the ones passed.")
    return prepared
