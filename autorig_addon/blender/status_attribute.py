"""The per-vertex transfer status, stored on the mesh and shown as colours.

A transfer records for every target vertex how it got its weights
(``core.transfer.VertexStatus``). :func:`write_status_attribute` keeps the
values in an INT point attribute and a FLOAT_COLOR attribute made the
active colour, so Solid shading > Attribute shows at a glance which
vertices were copied and which were inpainted.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import InputError
from .convert import require_mesh_object

#: Name of the INT point attribute holding each vertex's transfer status.
STATUS_ATTRIBUTE = "autorig_transfer_status"
#: Name of the FLOAT_COLOR point attribute that visualises the status.
STATUS_COLOR_ATTRIBUTE = "AutoRig Transfer"
#: Every attribute :func:`write_status_attribute` writes (what a snapshot keeps).
STATUS_ATTRIBUTE_NAMES = (STATUS_ATTRIBUTE, STATUS_COLOR_ATTRIBUTE)

#: RGBA (linear) per transfer status, indexed by ``core.transfer.VertexStatus`` value:
#: copied green, copied through flipped normals teal, inpainted red,
#: masked orange, protected blue, part with no match magenta.
STATUS_COLORS = np.array(
    [
        [0.05, 0.80, 0.10, 1.0],
        [0.00, 0.60, 0.60, 1.0],
        [0.90, 0.05, 0.05, 1.0],
        [1.00, 0.45, 0.00, 1.0],
        [0.10, 0.25, 1.00, 1.0],
        [0.90, 0.00, 0.90, 1.0],
    ],
    dtype=np.float32,
)
#: Colour of a status value outside the table (should not happen; grey shows it).
UNKNOWN_STATUS_COLOR = np.array([0.5, 0.5, 0.5, 1.0], dtype=np.float32)


def status_colors(status: np.ndarray) -> np.ndarray:
    """(n, 4) float32 RGBA of each status value (see :data:`STATUS_COLORS`)."""
    status = np.asarray(status, dtype=np.int64).reshape(-1)
    colors = np.tile(UNKNOWN_STATUS_COLOR, (len(status), 1))
    known = (status >= 0) & (status < len(STATUS_COLORS))
    colors[known] = STATUS_COLORS[status[known]]
    return colors


def remove_status_attributes(mesh_data) -> None:
    """Remove the attributes named in :data:`STATUS_ATTRIBUTE_NAMES` from a mesh datablock."""
    for name in STATUS_ATTRIBUTE_NAMES:
        existing = mesh_data.attributes.get(name)
        if existing is not None:
            mesh_data.attributes.remove(existing)


def write_status_attribute(obj, status: np.ndarray) -> None:
    """Store the per-vertex transfer status on ``obj``'s mesh.

    Parameters
    ----------
    obj : bpy.types.Object of type 'MESH'
    status : (n,) int array of ``core.transfer.VertexStatus`` values

    Writes the INT point attribute :data:`STATUS_ATTRIBUTE` and the
    FLOAT_COLOR point attribute :data:`STATUS_COLOR_ATTRIBUTE`, made the
    active colour so Solid shading > Attribute displays it. Rewriting
    replaces both. Not all-or-nothing by itself: callers that write several
    things wrap them in :func:`~.snapshot.restored_on_failure`.
    """
    require_mesh_object(obj)
    mesh_data = obj.data
    status = np.asarray(status).reshape(-1)
    if len(status) != len(mesh_data.vertices):
        raise InputError(f"'{obj.name}' has {len(mesh_data.vertices)} vertices but {len(status)} status values.")
    remove_status_attributes(mesh_data)
    attribute = mesh_data.attributes.new(STATUS_ATTRIBUTE, "INT", "POINT")
    attribute.data.foreach_set("value", status.astype(np.int32))
    colors = mesh_data.color_attributes.new(STATUS_COLOR_ATTRIBUTE, "FLOAT_COLOR", "POINT")
    colors.data.foreach_set("color", status_colors(status).ravel())
    mesh_data.color_attributes.active_color_name = STATUS_COLOR_ATTRIBUTE
    mesh_data.update()


def read_status_attribute(obj) -> np.ndarray | None:
    """(n,) int32 status values written by :func:`write_status_attribute`, or None."""
    attribute = obj.data.attributes.get(STATUS_ATTRIBUTE)
    if attribute is None:
        return None
    values = np.empty(len(attribute.data), dtype=np.int32)
    attribute.data.foreach_get("value", values)
    return values
