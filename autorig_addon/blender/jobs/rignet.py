"""RigNet's plain-text rig files as jobs: importing one as an armature
(binding a mesh with its weights), exporting an armature and a mesh's
weights, in world space, so rigs move between this add-on and RigNet's data
and scripts. The File > Import / Export operators are
``operators.rignet``'s.
"""

from __future__ import annotations

import os

import numpy as np

from ...core.errors import InputError
from ...core.io.rignet_rig import read_rignet_rig, write_rignet_rig
from ...core.types import Weights
from ...core.weights import normalize_rows
from .. import convert
from ..armature_binding import remove_armature
from ..armature_builder import build_armature
from ..object_roles import give_own_mesh
from ..snapshot import restored_on_failure
from ..weight_writer import write_weights

#: Importing onto a mesh is refused when the file would leave more than this
#: share of its vertices without weight: the rig was made for another mesh.
#: (Fewer unweighted vertices are legal: the format has no line for a vertex
#: without weight, so a file cannot say how many trailing vertices it skips.)
MAX_UNWEIGHTED_SHARE = 0.5
#: A file's vertex whose weights sum further than this from 1 is counted as
#: normalised in the report (RigNet's own files round weights, so their sums
#: are off by about 1e-4).
WEIGHT_SUM_TOLERANCE = 1e-3


def import_rignet_rig(context, filepath: str, mesh_obj=None) -> tuple[object, list[str]]:
    """Build the armature of a RigNet file; bind ``mesh_obj`` with its weights.

    Returns the armature object and notes for the report (weights the file
    did not normalise: see :func:`normalised_file_weights`). ``mesh_obj``
    (optional) must have more vertices than the file's largest ``skin``
    index, and the file must weight at least ``1 - MAX_UNWEIGHTED_SHARE`` of
    them (vertices without a ``skin`` line stay unweighted: see
    :func:`unweighted_vertex_count`).
    All-or-nothing: on failure nothing is left in the scene and the mesh is
    unchanged. A mesh shared with other objects (linked duplicates) gets
    its own copy first.
    """
    vertex_count = len(mesh_obj.data.vertices) if mesh_obj is not None else None
    skeleton, weights = read_rignet_rig(filepath, vertex_count=vertex_count)
    bind = mesh_obj is not None and weights is not None
    notes = []
    if bind:
        _check_weights_cover_mesh(weights, mesh_obj)
        weights, notes = normalised_file_weights(weights)
    name = os.path.splitext(os.path.basename(filepath))[0] or "RigNet"
    armature = build_armature(skeleton, name, context)
    if not bind:
        return armature, notes
    try:
        with restored_on_failure([mesh_obj]):
            # A linked duplicate gets its own mesh, or the weights would land
            # on every object sharing it (as skinning and transfer do).
            give_own_mesh(mesh_obj)
            write_weights(mesh_obj, weights, armature)
    except BaseException:
        remove_armature(armature)
        raise
    return armature, notes


def normalised_file_weights(weights: Weights) -> tuple[Weights, list[str]]:
    """A file's weights with each vertex's row scaled to sum to 1, and a
    note counting the vertices whose sum was off by more than
    :data:`WEIGHT_SUM_TOLERANCE`. The format does not require sums of 1, but
    Blender cuts a vertex group's weight to at most 1 (a row of 5.0 and 0.5
    would become 1.0 and 0.5, other proportions) and what reads the weights
    back (our export, glTF, game engines) expects rows summing to 1. A row
    of zeros stays unweighted (the report counts those)."""
    sums = weights.matrix.sum(axis=1)
    off = (sums > 0) & (np.abs(sums - 1.0) > WEIGHT_SUM_TOLERANCE)
    normalised = Weights(normalize_rows(weights.matrix), weights.bone_names)
    if not off.any():
        return normalised, []
    return normalised, [f"the weights of {np.count_nonzero(off)} vertices did not sum to 1 in the file (sums "
                        f"from {sums[off].min():g} to {sums[off].max():g}); each was scaled to sum to 1"]


def unweighted_vertex_count(weights) -> int:
    """Vertices a file's weights leave without any weight (no ``skin`` line)."""
    return int(np.count_nonzero(~weights.matrix.any(axis=1)))


def _check_weights_cover_mesh(weights, mesh_obj) -> None:
    """Refuse a mesh the file leaves mostly unweighted: it is not the mesh
    the rig was made for (a larger index than the mesh has is refused while
    reading the file)."""
    vertex_count = len(mesh_obj.data.vertices)
    unweighted = unweighted_vertex_count(weights)
    if unweighted > MAX_UNWEIGHTED_SHARE * vertex_count:
        raise InputError(
            f"The file weights {vertex_count - unweighted} of the {vertex_count} vertices of '{mesh_obj.name}' "
            "and leaves the rest without weight: it is not the mesh the rig was made for. "
            "Import without a mesh selected to get the armature alone."
        )


def export_rignet_rig(filepath: str, armature_obj, mesh_obj=None) -> None:
    """Write the armature's deform bones (and ``mesh_obj``'s weights) to ``filepath``.

    An object in Edit Mode stays in it: its unsaved edits (moved bones,
    weights edited in Edit Mode) are first copied to its data, which is
    what is read, so the file holds what the user sees."""
    for obj in (armature_obj, mesh_obj):
        if obj is not None and obj.mode == "EDIT":
            obj.update_from_editmode()
    skeleton = convert.read_skeleton(armature_obj).deform_subset()
    if skeleton.bone_count == 0:
        raise InputError(f"'{armature_obj.name}' has no deform bones to export.")
    weights = convert.read_weights(mesh_obj, skeleton.names) if mesh_obj is not None else None
    write_rignet_rig(filepath, skeleton, weights)
