"""What the weighting jobs (skin, transfer) check in the same way.

- Modes: weights and rest shapes are read from the object data, so Object,
  Pose and Weight Paint Mode are all fine; Edit and Sculpt Mode keep their
  changes outside the data until left, so they are refused, by the
  operators' ``poll`` with the reason Blender shows, and per object.
- Far stray vertices (``core.geometry.outliers``): left out of the
  computation, weighted like their nearest kept vertex, named in the report.
"""

from __future__ import annotations

import numpy as np

from ...core.errors import InputError
from ...core.geometry.outliers import stray_vertices, without_vertices
from ...core.types import Mesh

#: Object modes in which weights cannot be written (the edits live outside
#: the mesh or armature data until the mode is left).
BLOCKING_OBJECT_MODES = {"EDIT", "SCULPT"}
#: ``context.mode`` values of those modes (``EDIT_MESH``, ``EDIT_ARMATURE``, ...).
BLOCKING_CONTEXT_MODE_PREFIXES = ("EDIT", "SCULPT")


def check_mode(obj, action: str) -> None:
    """Refuse an object in Edit or Sculpt Mode; Object, Pose and Weight
    Paint Mode are fine (weights and rest shapes are read from the data).

    Parameters
    ----------
    obj : bpy.types.Object
    action : str, the verb ending the message ("skin", "transfer")
    """
    if obj.mode in BLOCKING_OBJECT_MODES:
        raise InputError(f"'{obj.name}' is in {obj.mode.replace('_', ' ').title()} Mode: switch to Object Mode "
                         f"so its edits are saved, then {action}.")


def mode_poll(cls, context, label: str) -> bool:
    """An operator's ``poll``: False, with the reason shown by Blender, in
    Edit and Sculpt Mode."""
    if context.mode.startswith(BLOCKING_CONTEXT_MODE_PREFIXES):
        mode = context.mode.split("_")[0].title()
        cls.poll_message_set(f"{label} needs Object, Pose or Weight Paint Mode: leave {mode} Mode first")
        return False
    return True


def stray_notes(mesh: Mesh, strays: np.ndarray, action: str, *, reweighted: bool = True) -> dict:
    """{object name: note} for each object of ``mesh`` with stray vertices
    (``action``: what they are left out of). ``reweighted``: the strays take
    the weights of their nearest kept vertex (a target's); otherwise (a
    source's) they keep theirs and no weight is copied from them."""
    notes = {}
    for index, name in enumerate(mesh.object_names):
        count = int(np.count_nonzero(strays[mesh.object_slice(index)]))
        if count:
            what = f"{count} stray vertices" if count > 1 else "1 stray vertex"
            if reweighted:
                fate = " and weighted like the nearest kept vertex"
            else:
                fate = f": no weight is copied from {'them' if count > 1 else 'it'}"
            notes[name] = f"{what} far from the rest of the mesh left out of {action}{fate}"
    return notes


def split_strays(mesh: Mesh, left_out: np.ndarray | None = None) -> tuple[Mesh, np.ndarray | None]:
    """``mesh`` without its far stray vertices (and their triangles), and the
    stray mask, or ``mesh`` and None when it has none; vertices must be finite.
    ``left_out``: (n,) bool, vertices also taken out, among which no stray is
    looked for (they do not count toward the bulk either), or None."""
    if left_out is None or not left_out.any():
        strays = stray_vertices(mesh.vertices)
        drop = strays
    else:
        strays = np.zeros(mesh.vertex_count, dtype=bool)
        strays[~left_out] = stray_vertices(mesh.vertices[~left_out])
        drop = strays | left_out
    if not drop.any():
        return mesh, None
    _, vertices, triangles = without_vertices(mesh.vertices, mesh.triangles, drop)
    # The offsets of several objects no longer hold: one object, named after all of them.
    return Mesh(vertices, triangles, object_names=(", ".join(mesh.object_names),)), strays if strays.any() else None
