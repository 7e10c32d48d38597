"""The transfer status attribute and its colours (autorig_addon.blender.status_attribute), real bpy."""

import re

import numpy as np
import pytest

from autorig_addon.blender import status_attribute
from autorig_addon.core.errors import InputError
from autorig_addon.core.transfer.transfer import VertexStatus
from blender_fixtures import box_geometry, mesh_object

GREEN, RED, BLUE = [0.05, 0.80, 0.10, 1.0], [0.90, 0.05, 0.05, 1.0], [0.10, 0.25, 1.00, 1.0]
GREY = [0.5, 0.5, 0.5, 1.0]


def test_status_colors_per_status_and_grey_for_unknown_values():
    colours = status_attribute.status_colors([VertexStatus.COPIED, VertexStatus.INPAINTED, VertexStatus.PROTECTED,
                                              6, -1])
    np.testing.assert_allclose(colours, [GREEN, RED, BLUE, GREY, GREY], atol=1e-7)
    assert colours.dtype == np.float32


def test_status_attribute_values_and_colours(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    status = np.array([0, 1, 2, 3, 4, 5, 0, 2], dtype=np.int8)
    status_attribute.write_status_attribute(box, status)
    status_attribute.write_status_attribute(box, status)  # rewriting replaces, never duplicates
    np.testing.assert_array_equal(status_attribute.read_status_attribute(box), status)
    colours = box.data.color_attributes[status_attribute.STATUS_COLOR_ATTRIBUTE]
    assert colours.data_type == "FLOAT_COLOR" and colours.domain == "POINT"
    values = np.empty(8 * 4, dtype=np.float32)
    colours.data.foreach_get("color", values)
    np.testing.assert_allclose(values.reshape(8, 4)[[0, 2, 4]], [GREEN, RED, BLUE], atol=1e-6)
    np.testing.assert_allclose(values.reshape(8, 4), status_attribute.STATUS_COLORS[status], atol=1e-6)
    assert box.data.color_attributes.active_color_name == status_attribute.STATUS_COLOR_ATTRIBUTE
    assert sum(a.name == status_attribute.STATUS_ATTRIBUTE for a in box.data.attributes) == 1
    assert sum(a.name == status_attribute.STATUS_COLOR_ATTRIBUTE for a in box.data.attributes) == 1


def test_status_attribute_refuses_a_wrong_length_and_reads_none_when_absent(clean_scene):
    vertices, faces = box_geometry((0.0, 0.0, 0.0), 0.5)
    box = mesh_object("Box", vertices, faces)
    assert status_attribute.read_status_attribute(box) is None
    with pytest.raises(InputError, match=re.escape("'Box' has 8 vertices but 3 status values.")):
        status_attribute.write_status_attribute(box, [0, 1, 2])
    assert status_attribute.read_status_attribute(box) is None
