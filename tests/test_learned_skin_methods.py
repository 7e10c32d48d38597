"""The skinning method choice (``core.skinning.methods``): the dispatcher,
the Skin operator and panel, ``skin --method`` and ``eval``'s network
methods, for the geometric method and each shipped network.

Every network must give every vertex weights summing to 1 with at most
``max_influences`` bones, and send the lower end of a two-bone tube to the
lower bone (:data:`LOWER_END_SHARE`): what a trained network must do on the
plainest input there is.
"""

import argparse
import json
import re
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from autorig_addon.cli import evaluation_methods
from autorig_addon.cli import skin as cli_skin
from autorig_addon.core.errors import Cancelled, InputError
from autorig_addon.core.geometry.proxy import simplified_proxy
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.skinning import geometric
from autorig_addon.core.skinning.learned.ensemble import ENSEMBLE, ENSEMBLE_MEMBERS
from autorig_addon.core.skinning.learned.networks import NETWORK_NAMES, SKIN_NETWORKS
from autorig_addon.core.skinning.learned.predict import (
    NETWORK_PROXY_VERTICES,
    finished_weights,
    learned_weights,
    proxy_weights,
)
from autorig_addon.core.skinning.methods import (
    DEFAULT_SKIN_METHOD,
    GEOMETRIC,
    GEOMETRIC_OPTIONS,
    SKIN_METHOD_LABELS,
    SKIN_METHODS,
    skin_weights,
)
from autorig_addon.core.skinning.options import SkinningOptions, ignored_options
from autorig_addon.core.skinning.rigid_parts import rigid_weights
from geometry_fixtures import cylinder, two_bone_skeleton

#: The trained methods: each network and their ensemble.
LEARNED_METHODS = NETWORK_NAMES + (ENSEMBLE,)

#: Height of the test tube; its two bones meet at half of it.
TUBE_HEIGHT = 2.0
#: Vertices below this height are "well below the joint" (at 1.0): 40 % of
#: the lower bone's length away from it.
LOWER_END_HEIGHT = 0.6
#: ... and above this well above it.
UPPER_END_HEIGHT = TUBE_HEIGHT - LOWER_END_HEIGHT
#: Mean weight those vertices must give their own bone.
LOWER_END_SHARE = 0.8
#: Voxel resolution of the tests (coarse, fast; the tube is a plain shape).
RESOLUTION = 32
#: Influence limit below the generated character's bone count, so it binds.
MAX_INFLUENCES = 2
#: Seed and kind of the generated character (2,150 vertices, 24 deform bones).
CHARACTER_SEED, CHARACTER_KIND = 3, "biped"
#: What every refusal of an unknown method says.
UNKNOWN_METHOD = ("Unknown skinning method 'magic': use one of geometric, rignet, heterskinnet, skinningnet, "
                  "ensemble.")


def tube():
    return cylinder(radius=0.15, height=TUBE_HEIGHT, segments=24, rings=21)


def assert_valid_weights(matrix: np.ndarray, max_influences: int) -> None:
    """Every row non-negative, summing to 1 (1e-6), with 1 to ``max_influences`` non-zeros."""
    assert (matrix >= 0).all()
    np.testing.assert_allclose(matrix.sum(axis=1), 1.0, atol=1e-6)
    counts = (matrix > 0).sum(axis=1)
    assert counts.min() >= 1 and counts.max() <= max_influences


def assert_ends_on_their_bones(matrix: np.ndarray, heights: np.ndarray) -> None:
    """(n, 2) weights (lower, upper) of the tube: each end mostly on its own bone."""
    lower, upper = heights < LOWER_END_HEIGHT, heights > UPPER_END_HEIGHT
    assert lower.sum() > 100 and upper.sum() > 100
    assert matrix[lower, 0].mean() > LOWER_END_SHARE, matrix[lower, 0].mean()
    assert matrix[upper, 1].mean() > LOWER_END_SHARE, matrix[upper, 1].mean()


# --------------------------------------------------------------------------- core: names, dispatcher


def test_the_methods_are_the_geometric_one_the_networks_and_their_ensemble():
    assert SKIN_METHODS == ("geometric", "rignet", "heterskinnet", "skinningnet", "ensemble")
    assert SKIN_METHODS == (GEOMETRIC,) + LEARNED_METHODS
    assert DEFAULT_SKIN_METHOD == "heterskinnet" and ENSEMBLE_MEMBERS == ("heterskinnet", "skinningnet")
    assert set(SKIN_METHOD_LABELS) == set(SKIN_METHODS)


def test_an_unknown_method_is_refused_with_the_choices():
    with pytest.raises(InputError, match=f"^{re.escape(UNKNOWN_METHOD)}$"):
        skin_weights(tube(), two_bone_skeleton(TUBE_HEIGHT), SkinningOptions(method="magic"))


def test_an_option_no_method_has_is_a_programming_error():
    with pytest.raises(TypeError, match="unexpected keyword argument 'heat'"):
        skin_weights(tube(), two_bone_skeleton(TUBE_HEIGHT), SkinningOptions(method=GEOMETRIC, heat=2.0))


def test_geometric_runs_geometric_weights_with_every_option():
    mesh, skeleton = tube(), two_bone_skeleton(TUBE_HEIGHT)
    chosen = skin_weights(mesh, skeleton, SkinningOptions(GEOMETRIC, max_influences=1, resolution=RESOLUTION,
                                                          distance="geodesic", falloff=8.0, smoothing_iterations=2,
                                                          smoothing_strength=0.3, rigid_parts=False))
    direct = geometric.geometric_weights(mesh, skeleton, distance="geodesic", resolution=RESOLUTION, falloff=8.0,
                                         max_influences=1, smoothing_iterations=2, smoothing_strength=0.3)
    assert chosen.bone_names == direct.bone_names
    np.testing.assert_array_equal(chosen.matrix, direct.matrix)


@pytest.mark.parametrize("network", LEARNED_METHODS)
def test_a_network_runs_learned_weights_and_ignores_the_geometric_options(network):
    character = generate_character(CHARACTER_SEED, CHARACTER_KIND)
    mesh, skeleton = character.mesh, character.skeleton
    options = SkinningOptions(network, max_influences=1, resolution=RESOLUTION, distance="geodesic", falloff=8.0,
                              smoothing_iterations=2, smoothing_strength=0.3, rigid_parts=False)
    chosen = skin_weights(mesh, skeleton, options)
    direct = learned_weights(mesh, skeleton, network, max_influences=1, resolution=RESOLUTION)
    deform_names = tuple(name for name, deforms in zip(skeleton.names, skeleton.deform) if deforms)
    assert chosen.bone_names == direct.bone_names == deform_names
    np.testing.assert_array_equal(chosen.matrix, direct.matrix)
    # By default each loose part weighted mostly to one bone is then bound wholly to it.
    rigid = skin_weights(mesh, skeleton, replace(options, rigid_parts=True))
    expected, count = rigid_weights(mesh, direct.matrix)
    assert count > 0 and not np.array_equal(expected, direct.matrix)
    np.testing.assert_array_equal(rigid.matrix, expected)


def test_the_ensemble_averages_its_networks_before_pruning_and_sharpening():
    # The mean of the two networks' raw weights on the proxy, finished once: not the mean of two finished results.
    mesh, skeleton = tube(), two_bone_skeleton(TUBE_HEIGHT)
    ensemble = learned_weights(mesh, skeleton, ENSEMBLE, resolution=RESOLUTION).matrix
    proxy = simplified_proxy(mesh, NETWORK_PROXY_VERTICES)
    raw = [proxy_weights(proxy.mesh, skeleton, SKIN_NETWORKS[name], resolution=RESOLUTION) for name in ENSEMBLE_MEMBERS]
    expected = proxy.carry(0.5 * (raw[0] + raw[1]),
                           lambda rows, carried: finished_weights(carried, geometric.DEFAULT_MAX_INFLUENCES))
    np.testing.assert_allclose(ensemble, expected, atol=1e-12)
    # ... and it is neither network's own result.
    for name in ENSEMBLE_MEMBERS:
        assert np.abs(ensemble - learned_weights(mesh, skeleton, name, resolution=RESOLUTION).matrix).max() > 0.01


def test_rignet_weights_a_skeleton_smaller_than_it_needs_through_cut_bones():
    # RigNet needs 3 deform bones: it sees the two cut in two each, and each
    # bone gets the sum of its halves.
    assert SKIN_NETWORKS["rignet"].min_deform_bones == 3
    mesh = tube()
    weights = skin_weights(mesh, two_bone_skeleton(TUBE_HEIGHT), SkinningOptions("rignet", resolution=RESOLUTION))
    assert weights.bone_names == two_bone_skeleton(TUBE_HEIGHT).names
    assert_valid_weights(weights.matrix, geometric.DEFAULT_MAX_INFLUENCES)
    assert_ends_on_their_bones(weights.matrix, mesh.vertices[:, 2])


@pytest.mark.parametrize("method", SKIN_METHODS)
def test_each_method_sends_each_end_of_a_two_bone_tube_to_its_bone(method):
    mesh = tube()
    weights = skin_weights(mesh, two_bone_skeleton(TUBE_HEIGHT), SkinningOptions(method, resolution=RESOLUTION))
    assert_valid_weights(weights.matrix, geometric.DEFAULT_MAX_INFLUENCES)
    assert_ends_on_their_bones(weights.matrix, mesh.vertices[:, 2])


@pytest.mark.parametrize("method", SKIN_METHODS)
def test_each_method_weights_every_vertex_of_a_generated_character_within_the_limit(method):
    character = generate_character(CHARACTER_SEED, CHARACTER_KIND)
    weights = skin_weights(character.mesh, character.skeleton,
                           SkinningOptions(method, max_influences=MAX_INFLUENCES, resolution=RESOLUTION))
    assert weights.matrix.shape == (character.mesh.vertex_count, int(character.skeleton.deform.sum()))
    assert_valid_weights(weights.matrix, MAX_INFLUENCES)


def test_ignored_options_are_the_changed_geometric_ones_with_a_network():
    defaults = SkinningOptions(method="rignet")
    assert defaults.distance == geometric.DEFAULT_DISTANCE
    assert defaults.falloff == geometric.DEFAULT_FALLOFF
    assert defaults.smoothing_iterations == geometric.DEFAULT_SMOOTHING_ITERATIONS
    changed = replace(defaults, falloff=8.0, distance="geodesic")
    assert ignored_options(changed) == ("distance", "falloff")
    assert ignored_options(defaults) == ()
    assert ignored_options(replace(changed, method=GEOMETRIC)) == ()


# --------------------------------------------------------------------------- eval


@pytest.mark.parametrize("network", LEARNED_METHODS)
def test_eval_scores_each_network_as_the_skin_job_gives_it(network):
    evaluation_methods.check_method("skin", network)  # accepted
    assert network in evaluation_methods.method_names("skin")
    character = generate_character(CHARACTER_SEED, CHARACTER_KIND)
    mesh, skeleton = character.mesh, character.skeleton
    predicted = evaluation_methods.SKIN_METHODS[network].predict(evaluation_methods.SkinInput(mesh, skeleton))
    # The network's weights with its rigid loose parts bound wholly to their bone, as a user gets them.
    expected, count = rigid_weights(mesh, learned_weights(mesh, skeleton, network).matrix)
    assert count > 0
    np.testing.assert_array_equal(predicted.matrix, expected)


# --------------------------------------------------------------------------- command line


def skin_parser_actions() -> dict:
    parser = argparse.ArgumentParser()
    cli_skin.add_arguments(parser)
    return {action.dest: action for action in parser._actions}


def test_cli_method_choices_and_default_are_the_cores():
    method = skin_parser_actions()["method"]
    assert tuple(method.choices) == SKIN_METHODS
    assert method.default == DEFAULT_SKIN_METHOD


def test_cli_notes_the_geometric_options_a_network_ignores():
    actions = skin_parser_actions()
    args = SimpleNamespace(**{name: actions[name].default for name in GEOMETRIC_OPTIONS})
    args.method = "heterskinnet"
    assert cli_skin.ignored_options_note(args) == ""
    args.falloff, args.smoothing_iterations = 8.0, 3
    assert cli_skin.ignored_options_note(args) == (
        "note: --method heterskinnet ignores --falloff, --smoothing-iterations, which only --method geometric uses.")
    args.method = GEOMETRIC
    assert cli_skin.ignored_options_note(args) == ""


# --------------------------------------------------------------------------- Blender: scenes


def tube_scene(deform=True):
    """The two-bone armature (Lower z 0..1, Upper 1..2) and an unbound closed
    tube of radius 0.3 around it, both selected, the armature active."""
    import bpy

    from blender_fixtures import BODY_HEIGHT, BODY_RADIUS, cylinder_geometry, make_armature, mesh_object, select_only

    armature = make_armature()
    for bone in armature.data.bones:
        bone.use_deform = deform
    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, BODY_HEIGHT, 24, 20, capped=True)
    body = mesh_object("Tube", vertices, faces)
    bpy.context.view_layer.update()
    select_only([armature, body], active=armature)
    return armature, body


def character_scene():
    """The generated character as a user would have it: its mesh and a new
    armature of its skeleton (every bone deforming), both selected."""
    import bpy

    from autorig_addon.blender.armature_builder import build_armature
    from blender_fixtures import mesh_object, select_only

    character = generate_character(CHARACTER_SEED, CHARACTER_KIND)
    armature = build_armature(character.skeleton, "Rig")
    body = mesh_object("Character", character.mesh.vertices, character.mesh.triangles.tolist())
    bpy.context.view_layer.update()
    select_only([armature, body], active=armature)
    return armature, body


def tube_heights(obj) -> np.ndarray:
    return np.array([vertex.co.z for vertex in obj.data.vertices])


# --------------------------------------------------------------------------- Blender: operator and panel


def test_the_panels_and_operators_method_items_and_default_are_the_cores(clean_scene):
    import bpy

    for rna in (clean_scene.autorig.bl_rna, bpy.ops.autorig.skin_weights.get_rna_type()):
        method = rna.properties["skin_method"]
        assert tuple(item.identifier.lower() for item in method.enum_items) == SKIN_METHODS
        assert tuple(item.name for item in method.enum_items) == tuple(SKIN_METHOD_LABELS[m] for m in SKIN_METHODS)
        assert method.default == DEFAULT_SKIN_METHOD.upper()


@pytest.mark.parametrize("network", LEARNED_METHODS)
def test_operator_skins_the_tube_with_each_network(clean_scene, capfd, network):
    import bpy

    from blender_fixtures import LOWER_BONE, UPPER_BONE, group_weights

    armature, body = tube_scene()
    capfd.readouterr()
    assert bpy.ops.autorig.skin_weights(skin_method=network.upper(), skin_resolution=RESOLUTION) == {"FINISHED"}
    assert (f"Info: Skinned 1 mesh(es) to 2 deform bones of 'Armature' with {SKIN_METHOD_LABELS[network]}."
            in capfd.readouterr().out)
    weights = group_weights(body, [LOWER_BONE, UPPER_BONE])
    assert_valid_weights(weights, geometric.DEFAULT_MAX_INFLUENCES)
    assert_ends_on_their_bones(weights, tube_heights(body))
    assert body.parent == armature and [m.type for m in body.modifiers] == ["ARMATURE"]


@pytest.mark.parametrize("network", NETWORK_NAMES)
def test_operator_skins_a_generated_character_with_each_network(clean_scene, network):
    import bpy

    from blender_fixtures import group_weights

    armature, body = character_scene()
    assert bpy.ops.autorig.skin_weights(skin_method=network.upper(), skin_resolution=RESOLUTION,
                                        skin_max_influences=MAX_INFLUENCES) == {"FINISHED"}
    bones = [bone.name for bone in armature.data.bones if bone.use_deform]
    assert sorted(group.name for group in body.vertex_groups) == sorted(bones)
    assert_valid_weights(group_weights(body, bones), MAX_INFLUENCES)


@pytest.mark.parametrize("network", LEARNED_METHODS)
def test_no_deform_bones_with_a_network_is_refused_and_the_scene_unchanged(clean_scene, network):
    import bpy

    from blender_fixtures import scene_state

    armature, body = tube_scene(deform=False)
    before = scene_state([armature, body])
    message = "The armature 'Armature' has no deform bones: enable Deform on the bones to weight."
    with pytest.raises(RuntimeError, match=f"^Error: {re.escape(message)}\n$"):
        bpy.ops.autorig.skin_weights(skin_method=network.upper(), skin_resolution=RESOLUTION)
    assert scene_state([armature, body]) == before


def test_an_unknown_method_from_python_is_refused_before_any_work(clean_scene):
    import bpy

    from autorig_addon.blender.jobs.skin import SkinSettings, plan_skin

    armature, body = tube_scene()
    with pytest.raises(InputError, match=f"^{re.escape(UNKNOWN_METHOD)}$"):
        plan_skin(armature, [body], SkinSettings(SkinningOptions(method="magic")),
                  bpy.context.evaluated_depsgraph_get())


def test_a_network_run_reports_progress_and_stops_on_esc(clean_scene):
    import bpy

    from autorig_addon.blender.jobs.skin import SkinJob, SkinSettings, compute_skin, plan_skin
    from blender_fixtures import scene_state

    armature, body = tube_scene()
    before = scene_state([armature, body])
    plan = plan_skin(armature, [body], SkinSettings(SkinningOptions(method="heterskinnet", resolution=RESOLUTION)),
                     bpy.context.evaluated_depsgraph_get())
    reports = []
    compute_skin(plan, lambda fraction, message: reports.append((fraction, message)))
    fractions = [fraction for fraction, _ in reports]
    assert fractions == sorted(fractions) and 0.0 <= fractions[0] and reports[-1] == (1.0, "Weights done")
    assert "Running heterskinnet" in [message for _, message in reports]
    # Esc: the worker stops at the network's first progress report; nothing is written.
    job = SkinJob(plan, cancel=True)
    job.run()
    assert job.weights is None and isinstance(job.error, Cancelled) and str(job.error) == "Skinning cancelled."
    assert scene_state([armature, body]) == before


class RecordingLayout:
    """Stands in for bpy.types.UILayout: records each property drawn and
    whether it can be edited (its own and every enclosing layout's
    ``enabled``)."""

    def __init__(self, drawn: dict, parent=None):
        self.drawn, self.parent = drawn, parent
        self.enabled = self.active = True

    def column(self, align=False):
        return RecordingLayout(self.drawn, self)

    row = column

    def label(self, **_):
        pass

    def operator(self, *_, **__):
        pass

    def prop(self, _data, name):
        self.drawn[name] = self.editable()

    def editable(self) -> bool:
        return self.enabled and (self.parent is None or self.parent.editable())


@pytest.mark.parametrize("method", SKIN_METHODS)
def test_the_panel_disables_the_geometric_options_for_a_network(clean_scene, method):
    from autorig_addon.blender.ui.panels import VIEW3D_PT_autorig_skin

    settings = clean_scene.autorig
    settings.skin_method = method.upper()
    drawn = {}
    VIEW3D_PT_autorig_skin.draw_settings(None, RecordingLayout(drawn), settings, SimpleNamespace(selected_objects=[]))
    geometric_only = {"skin_" + name for name in GEOMETRIC_OPTIONS}
    assert geometric_only < set(drawn) and "skin_method" in drawn
    assert {name for name, editable in drawn.items() if not editable} == (
        set() if method == GEOMETRIC else geometric_only)


# --------------------------------------------------------------------------- Blender: the skin command


def saved_scene(path, deform=True):
    import bpy

    tube_scene(deform)
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return path


@pytest.mark.parametrize("network", NETWORK_NAMES)
def test_skin_command_skins_the_tube_with_each_network(clean_scene, tmp_path, capsys, network):
    import bpy

    from autorig_addon.cli.main import main
    from blender_fixtures import LOWER_BONE, UPPER_BONE, group_weights

    source, out = saved_scene(tmp_path / "rig.blend"), tmp_path / "skinned.blend"
    capsys.readouterr()
    assert main(["skin", str(source), "--out", str(out), "--method", network, "--resolution", str(RESOLUTION),
                 "--quiet"]) == 0
    (entry,) = json.loads(capsys.readouterr().out)["succeeded"]
    assert entry["method"] == network and entry["bones"] == 2
    bpy.ops.wm.open_mainfile(filepath=str(out))
    body = bpy.data.objects["Tube"]
    weights = group_weights(body, [LOWER_BONE, UPPER_BONE])
    assert_valid_weights(weights, geometric.DEFAULT_MAX_INFLUENCES)
    assert_ends_on_their_bones(weights, tube_heights(body))


def test_skin_command_notes_ignored_options_and_refuses_no_deform_bones(clean_scene, tmp_path, capsys):
    from autorig_addon.cli.main import main

    source, out = saved_scene(tmp_path / "rig.blend", deform=False), tmp_path / "skinned.blend"
    capsys.readouterr()
    assert main(["skin", str(source), "--out", str(out), "--method", "skinningnet", "--falloff", "8",
                 "--resolution", str(RESOLUTION), "--quiet"]) == 1
    captured = capsys.readouterr()
    assert captured.err.startswith(
        "note: --method skinningnet ignores --falloff, which only --method geometric uses.\n")
    (failed,) = json.loads(captured.out)["failed"]
    assert failed["error"] == "The armature 'Armature' has no deform bones: enable Deform on the bones to weight."
    assert not out.exists()
