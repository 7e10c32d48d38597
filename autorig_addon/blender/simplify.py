"""A skinned mesh resampled to a target vertex count, weights carried along.

Training samples and proxies want 1k to 5k vertices whatever the source
resolution; Blender's Decimate modifier interpolates point attributes like
positions, so weights stored as attributes follow the surface through the
collapse.
"""

from __future__ import annotations

from typing import Sequence

import bpy
import numpy as np

from ..core import dataset
from ..core.errors import InputError
from ..core.geometry.subdivision import subdivide_midpoints
from ..core.geometry.weld import weld_seams
from ..core.types import Mesh, Weights
from ..core.weights import normalize_rows
from .scratch_objects import remove_scratch_object, scratch_object

#: The simplified mesh may miss the target vertex count by this share.
SIMPLIFY_COUNT_TOLERANCE = 0.05
#: Decimation ratio refinements tried to hit the target vertex count.
SIMPLIFY_MAX_STEPS = 6
#: Name prefix of the point attributes that carry weights through decimation.
WEIGHT_ATTRIBUTE_PREFIX = "autorig_weight_"


def _decimated(obj, ratio: float, columns: Sequence[int]) -> tuple:
    """Vertices, triangles and the weight attributes ``columns`` of ``obj`` collapsed to ``ratio``."""
    modifier = obj.modifiers.get("Decimate") or obj.modifiers.new("Decimate", "DECIMATE")
    modifier.decimate_type = "COLLAPSE"
    modifier.use_collapse_triangulate = True
    modifier.ratio = float(min(max(ratio, 1e-4), 1.0))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    data = evaluated.to_mesh()
    try:
        count = len(data.vertices)
        positions = np.empty(count * 3, dtype=np.float32)
        data.vertices.foreach_get("co", positions)
        data.calc_loop_triangles()
        triangles = np.empty(len(data.loop_triangles) * 3, dtype=np.int32)
        data.loop_triangles.foreach_get("vertices", triangles)
        values = np.zeros((count, len(columns)), dtype=np.float32)
        for index, column in enumerate(columns):
            data.attributes[f"{WEIGHT_ATTRIBUTE_PREFIX}{column}"].data.foreach_get("value", values[:, index])
    finally:
        evaluated.to_mesh_clear()
    return positions.reshape(-1, 3).astype(np.float64), triangles.reshape(-1, 3).astype(np.int64), values


def simplify(mesh: Mesh, weights: Weights, target_vertices: int) -> tuple:
    """Resample a skinned mesh to about ``target_vertices`` vertices.

    Seams are welded first (:func:`weld_seams`). A welded mesh smaller than
    the target is first refined by midpoint subdivision
    (:func:`core.geometry.subdivision.subdivide_midpoints`, the shape is unchanged) until
    it is larger. Then Blender's Decimate modifier (COLLAPSE) runs with every
    bone's weights stored as a point attribute, which the collapse
    interpolates like positions, so each new vertex carries the weights of
    the surface it came from (no closest-point lookup that could jump
    between touching limbs). Rows are renormalised.

    Parameters
    ----------
    mesh : Mesh
    weights : Weights (n, b)
    target_vertices : int, at least :data:`core.dataset.MIN_TARGET_VERTICES`

    Returns
    -------
    mesh : Mesh, one object, within :data:`SIMPLIFY_COUNT_TOLERANCE` of the
        target (a welded mesh already that close is returned as it is)
    weights : Weights (n', b)
    """
    if target_vertices < dataset.MIN_TARGET_VERTICES:
        raise InputError(f"Simplify to at least {dataset.MIN_TARGET_VERTICES} vertices, not {target_vertices}.")
    welded, welded_weights = weld_seams(mesh, weights)
    if abs(welded.vertex_count - target_vertices) <= SIMPLIFY_COUNT_TOLERANCE * target_vertices:
        return welded, welded_weights
    vertices, triangles, matrix = welded.vertices, welded.triangles, welded_weights.matrix
    while len(vertices) < target_vertices:
        vertices, triangles, matrix = subdivide_midpoints(vertices, triangles, matrix)
    refined = Mesh(vertices, triangles, object_names=welded.object_names)
    columns = np.flatnonzero(matrix.max(axis=0) > 0.0)
    obj = scratch_object(refined)
    try:
        for column in columns:
            attribute = obj.data.attributes.new(f"{WEIGHT_ATTRIBUTE_PREFIX}{column}", "FLOAT", "POINT")
            attribute.data.foreach_set("value", matrix[:, column].astype(np.float32))
        ratio = target_vertices / refined.vertex_count
        for _ in range(SIMPLIFY_MAX_STEPS):
            vertices, triangles, values = _decimated(obj, ratio, columns)
            if abs(len(vertices) - target_vertices) <= SIMPLIFY_COUNT_TOLERANCE * target_vertices:
                break
            ratio *= target_vertices / max(len(vertices), 1)
    finally:
        remove_scratch_object(obj)
    result = np.zeros((len(vertices), matrix.shape[1]))
    result[:, columns] = values
    return (Mesh(vertices, triangles, object_names=welded.object_names),
            Weights(normalize_rows(result), weights.bone_names))
