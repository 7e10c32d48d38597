"""The transfer operator on bad input built in Blender as a user would make
it: a body left partly unpainted or with NaN weights, a garment in other
units, and an operator called from a script. Each ends in correct weights
with a report that says what happened, or a refusal with the scene unchanged.
"""

import json
import re

import bpy
import numpy as np
import pytest

from autorig_addon.blender import convert
from autorig_addon.blender.operators.transfer import scene_defaults
from autorig_addon.blender.selection import PICK_IN_PANEL, resolve_source, resolve_targets
from autorig_addon.blender.status_attribute import STATUS_ATTRIBUTE
from autorig_addon.core.errors import InputError
from autorig_addon.core.transfer.transfer import VertexStatus
from blender_fixtures import LOWER_BONE, UPPER_BONE, build_rig_scene, local_positions, scene_state, select_only

pytestmark = pytest.mark.all_blenders

BONES = [LOWER_BONE, UPPER_BONE]
#: Body vertices above this height lose their weights in the tests (the sleeve reaches z = 1.8).
UNPAINTED_ABOVE = 1.45


@pytest.fixture
def rig(clean_scene):
    return build_rig_scene(with_button=False)


def body_vertices_above(rig, height):
    return [int(i) for i in np.flatnonzero(local_positions(rig.body)[:, 2] > height)]


def refused_unchanged(rig, message, **arguments):
    """The operator refuses with a message matching the regular expression
    ``message`` and changes nothing (NaN weights compare equal as JSON)."""
    objects = [rig.body, rig.sleeve, rig.armature]
    before = json.dumps(scene_state(objects), sort_keys=True)
    with pytest.raises(RuntimeError, match=f"^Error: {message}\n$"):
        bpy.ops.autorig.transfer_weights(**arguments)
    assert json.dumps(scene_state(objects), sort_keys=True) == before


def status(obj):
    values = np.zeros(len(obj.data.vertices), dtype=np.int32)
    obj.data.attributes[STATUS_ATTRIBUTE].data.foreach_get("value", values)
    return values


@pytest.mark.parametrize("damage", ["unpainted", "nan"])
def test_a_partly_unpainted_or_nan_body_gives_full_rows_and_says_so(rig, damage, capfd):
    top = body_vertices_above(rig, UNPAINTED_ABOVE)
    for name in BONES:
        group = rig.body.vertex_groups[name]
        if damage == "unpainted":
            group.remove(top)  # never painted there
        else:
            group.add(top, float("nan"), "REPLACE")  # what a broken script or importer leaves
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}
    weights = convert.read_weights(rig.sleeve, BONES).matrix
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)  # no empty row, none unnormalised
    z = local_positions(rig.sleeve)[:, 2]
    over = z > UNPAINTED_ABOVE + 0.1  # closest body points all on the unpainted part
    assert np.all(status(rig.sleeve)[over] == VertexStatus.INPAINTED)
    np.testing.assert_allclose(weights[over], [[0.0, 1.0]] * int(over.sum()), atol=1e-3)  # the top is Upper's
    report = capfd.readouterr().out
    corrupt = f" ({len(top)} with NaN, infinite or negative weights)" if damage == "nan" else ""
    assert re.search(f"{len(top)} vertices of 'Body' have no usable weight{re.escape(corrupt)}; "
                     r"\d+ vertices near them were inpainted", report), report


def test_a_body_whose_weights_are_all_nan_is_refused_for_that_reason(rig):
    for name in BONES:
        rig.body.vertex_groups[name].add(list(range(len(rig.body.data.vertices))), float("nan"), "REPLACE")
    count = len(rig.body.data.vertices)
    refused_unchanged(rig, re.escape(
        f"The source 'Body' has no usable weights: {count} of its {count} vertices have NaN, infinite or negative "
        "weights and the others none. Clean the weights (Weights > Clean) or skin the body again."),
        source="Body", targets="Sleeve")


@pytest.mark.parametrize("scale, words", [
    (2.54, "'Sleeve' looks 2.54 times too large for 'Body' (inches and centimetres mixed up?): scaled by 1/2.54"),
    (1 / 2.54, "'Sleeve' looks 2.54 times too small for 'Body' (inches and centimetres mixed up?): scaled by 2.54"),
])
def test_a_garment_in_other_units_is_refused_unless_poor_matches_are_allowed(rig, scale, words):
    rig.sleeve.scale = (scale, scale, scale)  # imported from a file in other units, scale not applied
    bpy.context.view_layer.update()
    refused_unchanged(rig, ".*" + re.escape(words) + ".*" + re.escape(
        "To transfer anyway, turn on Allow Poor Match (--allow-poor-match on the command line)."),
        source="Body", targets="Sleeve")
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", allow_poor_match=True) == {"FINISHED"}
    np.testing.assert_allclose(convert.read_weights(rig.sleeve, BONES).matrix.sum(axis=1), 1.0, atol=1e-6)


def scale_sleeve_about_body_centre(rig, scale):
    """A wrong object scale: the sleeve scaled about the body's centre (not applied)."""
    centre = 0.5 * (local_positions(rig.body).min(axis=0) + local_positions(rig.body).max(axis=0))
    rig.sleeve.scale = (scale, scale, scale)
    rig.sleeve.location = centre - scale * centre
    bpy.context.view_layer.update()


@pytest.mark.parametrize("scale, size", [(1.8, "large"), (1 / 1.8, "small")])
def test_a_garment_at_another_scale_is_refused_like_one_in_other_units(rig, scale, size, capfd):
    scale_sleeve_about_body_centre(rig, scale)
    # A tube around the body's cylinder fits it over a range of scales, 2.54
    # about the origin among them: a unit factor, tried first, may be named.
    words = (rf"'Sleeve' looks (\d\.\d+) times too {size} for 'Body' "
             r"\((a wrong object scale|[a-z ]+ mixed up)\?\): scaled by (1/)?\1, \d+% of it would match the body\.")
    refused_unchanged(rig, ".*" + words + ".*" + re.escape(
        "To transfer anyway, turn on Allow Poor Match (--allow-poor-match on the command line)."),
        source="Body", targets="Sleeve")
    found = re.search(words, capfd.readouterr().out)
    if found.group(2) == "a wrong object scale":
        assert 1.2 <= float(found.group(1)) <= 2.2  # the scale that fits, not a unit factor
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve", allow_poor_match=True) == {"FINISHED"}
    np.testing.assert_allclose(convert.read_weights(rig.sleeve, BONES).matrix.sum(axis=1), 1.0, atol=1e-6)


@pytest.mark.parametrize("scale", [1.0, 1.05])
def test_a_garment_at_its_scale_or_a_loose_one_is_not_flagged(rig, scale, capfd):
    scale_sleeve_about_body_centre(rig, scale)
    assert bpy.ops.autorig.transfer_weights(source="Body", targets="Sleeve") == {"FINISHED"}
    assert "too large" not in capfd.readouterr().out
    assert np.all(status(rig.sleeve) != VertexStatus.INPAINTED)


def test_the_panels_allow_poor_match_reaches_the_operator(rig):
    rig.sleeve.scale = (2.54, 2.54, 2.54)
    bpy.context.view_layer.update()
    settings = bpy.context.scene.autorig
    settings.source, settings.target = rig.body, rig.sleeve
    select_only([], active=None)
    settings.allow_poor_match = True
    values = scene_defaults(bpy.context, lambda name: False)  # what the panel's button passes
    assert values["allow_poor_match"] is True
    assert bpy.ops.autorig.transfer_weights(**values) == {"FINISHED"}


def test_refusals_say_how_to_name_objects_the_way_the_operator_was_started(rig):
    select_only([], active=None)
    # From a script: the panel's settings are not read, so the message does not send the user there.
    refused_unchanged(rig, re.escape(
        "No source: make the skinned body the active object or pass it by name "
        "(bpy.ops.autorig.transfer_weights(source='Body', ...))."))
    refused_unchanged(rig, re.escape(
        "No target: select the meshes to weight together with the source, or pass them by name "
        "(bpy.ops.autorig.transfer_weights(targets='Shirt,Trousers', ...))."), source="Body")
    # From the panel's button (the operator's invoke, which needs a window, words them so).
    with pytest.raises(InputError, match=re.escape(
            "No source: make the skinned body the active object or pick it as Source in the AutoRig panel.")):
        resolve_source(bpy.context, "", PICK_IN_PANEL)
    with pytest.raises(InputError, match=re.escape(
            "No target: select the meshes to weight together with the source, or pick a Target in the AutoRig panel.")):
        resolve_targets(bpy.context, "", rig.body, how=PICK_IN_PANEL)
