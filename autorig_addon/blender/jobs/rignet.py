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


def import_rignet_rig(context, filepath: str, mesh_obj=None):
    """Build the armature of a RigNet file; bind ``mesh_obj`` with its weights.

    Returns the armature object. ``mesh_obj`` (optional) must have more
    vertices than the file's largest ``skin`` index, and the file must weight
    at least ``1 - MAX_UNWEIGHTED_SHARE`` of them (vertices without a ``skin``
    line stay unweighted: see :func:`unweighted_vertex_count`).
    All-or-nothing: on failure nothing is left in the scene and the mesh is
    unchanged. A mesh shared with other objects (linked duplicates) gets
    its own copy first.
    """
    vertex_count = len(mesh_obj.data.vertices) if mesh_obj is not None else None
    skeleton, weights = read_rignet_rig(filepath, vertex_count=vertex_count)
    bind = mesh_obj is not None and weights is not None
    if bind:
        _check_weights_cover_mesh(weights, mesh_obj)
    name = os.path.splitext(os.path.basename(filepath))[0] or "RigNet"
    armature = build_armature(skeleton, name, context)
    if not bind:
        return armature
    try:
        with restored_on_failure([mesh_obj]):
            # A linked duplicate gets its own mesh, or the weights would land
            # on every object sharing it (as skinning and transfer do).
            give_own_mesh(mesh_obj)
            write_weights(mesh_obj, weights, armature)
    except BaseException:
        remove_armature(armature)
        raise
    return armature


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
    """Write the armature's deform bones (and ``mesh_obj``'s weights) to ``filepath``."""
    skeleton = convert.read_skeleton(armature_obj).deform_subset()
    if skeleton.bone_count == 0:
        raise InputError(f"'{armature_obj.name}' has no deform bones to export.")
    weights = convert.read_weights(mesh_obj, skeleton.names) if mesh_obj is not None else None
    write_rignet_rig(filepath, skeleton, weights)
