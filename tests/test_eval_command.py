"""The ``eval`` subcommand (autorig_addon.cli.evaluate) on scenes built in code.

Expected scores are computed independently of the subcommand: by hand, or
by the core metrics on the fixture's own arrays (the subcommand must report
exactly what the core measures on the file's content).
"""

import argparse
import json
import math

import bpy
import numpy as np
import pytest

from autorig_addon.blender import convert, scene_io
from autorig_addon.cli import evaluate, evaluation_methods
from autorig_addon.cli.main import main
from autorig_addon.core.dataset.split import collect_data
from autorig_addon.core.errors import InputError
from autorig_addon.core.evaluation.self_transfer import self_transfer_target
from autorig_addon.core.evaluation.skin_metrics import evaluate_skin, evaluate_transfer
from autorig_addon.core.geometry.topology import edges
from autorig_addon.core.io.rignet_rig import write_rignet_rig
from autorig_addon.core.types import Mesh, Skeleton
from blender_fixtures import (
    BODY_HEIGHT,
    BODY_RADIUS,
    LOWER_BONE,
    UPPER_BONE,
    box_geometry,
    build_rig_scene,
    cylinder_geometry,
    expected_body_weights,
    make_sleeve,
    mesh_object,
    reset_scene,
)

BODY_SIZE = math.sqrt((2 * BODY_RADIUS) ** 2 * 2 + BODY_HEIGHT ** 2)
#: ``eval rig``'s unit (RigNet's): the largest side of the body's bounding box, its height.
BODY_LARGEST_SIDE = max(2 * BODY_RADIUS, BODY_HEIGHT)
#: The reference skeleton of the fixture body, as the subcommand reads it.
SKELETON = Skeleton([[0, 0, 0], [0, 0, 1]], [-1, 0], (LOWER_BONE, UPPER_BONE), [[0, 0, 1], [0, 0, 2]])
SKIN_KEYS = {"name", "category", "path", "l1", "precision", "recall", "deform_mean", "deform_max", "unweighted",
             "seconds", "vertices", "reference_unweighted", "notes"}
RIG_KEYS = {"name", "category", "path", "cd_j2j", "cd_j2b", "cd_b2b", "iou", "precision", "recall", "tree_edit",
            "seconds", "notes"}
NO_ARMATURE = ("No armature in this file deforms a mesh: a rigged character needs a mesh with an Armature modifier "
               "(or armature parenting) and vertex groups.")


def body_arrays():
    """The fixture body's vertices (506, 3), triangles and reference weights (506, 2)."""
    vertices, faces = cylinder_geometry(BODY_RADIUS, 0.0, BODY_HEIGHT, 24, 20, capped=True)
    triangles = np.array([triangle for face in faces
                          for triangle in ([face] if len(face) == 3 else [face[:3], (face[0], face[2], face[3])])])
    return vertices, triangles, expected_body_weights(vertices[:, 2])


def parse(arguments):
    parser = argparse.ArgumentParser()
    evaluate.add_arguments(parser)
    return parser.parse_args(arguments)


def run_eval(arguments, tmp_path, capsys):
    """Run ``eval`` with a JSON report; returns (exit code, report, stdout)."""
    out = tmp_path / "report.json"
    capsys.readouterr()
    code = evaluate.run(parse(arguments + ["--out", str(out), "--split-file", str(tmp_path / "no_split.json"),
                                           "--quiet"]))
    stdout = capsys.readouterr().out
    return code, json.loads(out.read_text()), stdout


def save_body(path):
    """Armature + skinned cylinder (506 vertices), without the sleeve."""
    reset_scene()
    rig = build_rig_scene(with_button=False)
    bpy.data.objects.remove(rig.sleeve)
    scene_io.save_scene(path)


def test_reference_method_scores_perfectly(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "data" / "body.blend")
    code, report, stdout = run_eval(["skin", str(tmp_path / "data"), "--method", "reference"], tmp_path, capsys)
    assert code == 0
    assert (report["task"], report["method"]) == ("skin", "reference")
    (entry,) = report["characters"]
    assert set(entry) == SKIN_KEYS
    assert entry == {
        "name": "body", "category": "data", "path": str(tmp_path / "data" / "body.blend"),
        "l1": 0.0, "precision": 1.0, "recall": 1.0, "deform_mean": 0.0, "deform_max": 0.0, "unweighted": 0,
        "seconds": 0.0, "vertices": 506, "reference_unweighted": 0, "notes": [
            "stored bone tails used: the stored bones are real (median length 46 % of the character, "
            "reaching 100 % of the way to their child)"
        ],
    }
    statistics = {"count": 1, "failed": 0,
                  "mean": {"l1": 0.0, "precision": 1.0, "recall": 1.0, "deform_mean": 0.0, "deform_max": 0.0,
                           "unweighted": 0.0, "seconds": 0.0}}
    statistics["median"] = dict(statistics["mean"])
    assert report["summary"] == {"categories": {"data": statistics}, "overall": statistics}
    assert "| body | 0 | 1 | 1 | 0 | 0 | 0 | 0 |" in stdout
    assert "| **overall** | 1 | 0 | 0 / 0 | 1 / 1 | 1 / 1 | 0 / 0 | 0 / 0 | 0 / 0 | 0 / 0 |" in stdout


def test_nearest_bone_has_the_hand_computed_error(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    code, report, _ = run_eval(["skin", str(tmp_path / "body.blend"), "--method", "nearest_bone"], tmp_path, capsys)
    assert code == 0
    (entry,) = report["characters"]
    # Rings every 0.1 in z, 24 vertices each, 506 vertices in all. Reference
    # Upper weights 0.25, 0.5, 0.75 at z = 0.9, 1.0, 1.1; nearest bone gives
    # Lower, Lower (tie, first bone), Upper: row errors 0.5, 1.0, 0.5.
    assert entry["l1"] == pytest.approx(24 * (0.5 + 1.0 + 0.5) / 506, abs=1e-12)
    # Every bone the vertex has is a reference bone; the blend rings lose one.
    assert entry["precision"] == 1.0
    assert entry["recall"] == pytest.approx(506 / (506 + 3 * 24), abs=1e-12)
    assert entry["unweighted"] == 0
    # The deformation error is the core's on the same one-hot weights
    # (Lower up to z = 1, Upper above), under the same seeded poses.
    vertices, _, reference = body_arrays()
    one_hot = np.column_stack([vertices[:, 2] <= 1.0, vertices[:, 2] > 1.0]).astype(float)
    expected = evaluate_skin(vertices, one_hot, reference, SKELETON)
    assert expected["deform_max"] > 10 * expected["deform_mean"] > 0  # the answer is not trivially zero
    assert entry["deform_mean"] == pytest.approx(expected["deform_mean"], rel=1e-6)
    assert entry["deform_max"] == pytest.approx(expected["deform_max"], rel=1e-6)


def test_boneheat_scores_blenders_own_automatic_weights(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    code, report, _ = run_eval(["skin", str(tmp_path / "body.blend"), "--method", "boneheat"], tmp_path, capsys)
    assert code == 0
    (entry,) = report["characters"]
    # The same mesh without any vertex group, parented with Automatic Weights here.
    scene_io.load_scene(tmp_path / "body.blend")
    vertices, triangles, reference = body_arrays()
    copy = mesh_object("Copy", vertices, triangles.tolist())
    armature = bpy.data.objects["Armature"]
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj in (copy, armature))
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    heat = convert.read_weights(copy, [LOWER_BONE, UPPER_BONE]).matrix
    expected = evaluate_skin(vertices, heat, reference, SKELETON)
    assert expected["l1"] > 0.01  # heat spreads the joint wider than the artist's band
    for key in ("l1", "precision", "recall", "deform_mean", "deform_max"):
        assert entry[key] == pytest.approx(expected[key], rel=1e-5), key
    assert entry["unweighted"] == expected["unweighted"] == 0
    # The file's own groups stayed out of it: the body still has the artist's weights.
    body = bpy.data.objects["Body"]
    np.testing.assert_allclose(convert.read_weights(body, [LOWER_BONE, UPPER_BONE]).matrix, reference, atol=1e-6)


def test_one_failure_does_not_stop_the_evaluation(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "data" / "a_body.blend")
    reset_scene()
    mesh_object("Rock", *box_geometry((0, 0, 0), 1.0))
    scene_io.save_scene(tmp_path / "data" / "b_rock.blend")
    code, report, stdout = run_eval(["skin", str(tmp_path / "data"), "--method", "nearest_bone"], tmp_path, capsys)
    assert code == 1
    body, rock = report["characters"]
    assert body["l1"] == pytest.approx(24 * 2.0 / 506, abs=1e-12) and "error" not in body
    assert rock == {"name": "b_rock", "category": "data", "path": str(tmp_path / "data" / "b_rock.blend"),
                    "error": NO_ARMATURE}
    assert report["summary"]["overall"]["count"] == 1 and report["summary"]["overall"]["failed"] == 1
    assert f"| b_rock | failed: {NO_ARMATURE} |" in stdout


def test_split_filters_the_data(clean_scene, tmp_path, capsys):
    for name in ("kept", "dropped"):
        save_body(tmp_path / "chars" / "pack" / f"{name}.blend")
    split = {"train": ["pack/dropped.blend"], "validation": ["pack/kept.blend"],
             "categories": {"biped": ["pack/kept.blend", "pack/dropped.blend"]}}
    (tmp_path / "split.json").write_text(json.dumps(split))
    arguments = ["skin", str(tmp_path / "chars"), "--method", "reference", "--split", "validation",
                 "--split-file", str(tmp_path / "split.json"), "--quiet"]
    out = tmp_path / "r.json"
    assert evaluate.run(parse(arguments + ["--out", str(out)])) == 0
    report = json.loads(out.read_text())
    assert [(c["name"], c["category"]) for c in report["characters"]] == [("pack/kept", "biped")]
    dropped = tmp_path / "chars" / "pack" / "dropped.blend"
    with pytest.raises(InputError, match=(
        rf"^No file under {dropped} is in the 'validation' split of split\.json \(its paths are relative to the "
        r"characters folder\): pass that folder, or use --split all\.$"
    )):
        collect_data([str(dropped)], "validation", str(tmp_path / "split.json"))


def test_rig_from_files_equal_to_the_reference(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    exact, shifted = tmp_path / "exact", tmp_path / "shifted"
    exact.mkdir()
    shifted.mkdir()
    skeleton = Skeleton([[0, 0, 0], [0, 0, 1]], [-1, 0], (LOWER_BONE, UPPER_BONE))
    write_rignet_rig(exact / "body.txt", skeleton)
    write_rignet_rig(shifted / "body_rig.txt", Skeleton(skeleton.joints + [0.05, 0, 0], [-1, 0], ("a", "b")))
    code, report, _ = run_eval(["rig", str(tmp_path / "body.blend"), "--method", f"file:{exact}"], tmp_path, capsys)
    assert code == 0
    (entry,) = report["characters"]
    assert set(entry) == RIG_KEYS
    assert (entry["cd_j2j"], entry["cd_j2b"], entry["iou"], entry["precision"], entry["recall"],
            entry["tree_edit"]) == (
        0.0, 0.0, 1.0, 1.0, 1.0, 0)
    _, report, _ = run_eval(["rig", str(tmp_path / "body.blend"), "--method", f"file:{shifted}"], tmp_path, capsys)
    (entry,) = report["characters"]
    # Every joint is 0.05 from its counterpart: the Chamfer distance is 0.05 / largest side (2.0), not / diagonal.
    assert entry["cd_j2j"] == pytest.approx(0.05 / BODY_LARGEST_SIDE, rel=1e-6)
    assert entry["iou"] == 1.0  # at the matching tolerance of 0.025 * 2.0 = 0.05
    code, report, _ = run_eval(["rig", str(tmp_path / "body.blend"), "--method", f"file:{tmp_path}"], tmp_path, capsys)
    assert code == 1
    assert report["characters"][0]["error"] == f"No predicted rig for 'body' in '{tmp_path}' (looked for body.txt)."


def test_transfer_onto_a_sleeve_and_self_transfer(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    reset_scene()
    sleeve, _, _ = make_sleeve(with_button=False)
    sleeve_vertices = np.array([v.co[:] for v in sleeve.data.vertices])
    sleeve_quads = np.array([p.vertices[:] for p in sleeve.data.polygons])
    scene_io.save_scene(tmp_path / "garments" / "sleeve.blend")
    code, report, _ = run_eval(
        ["transfer", str(tmp_path / "garments"), str(tmp_path / "body.blend"), "--method", "closest_point",
         "--source", str(tmp_path / "body.blend")], tmp_path, capsys,
    )
    assert code == 0
    garment, self_check = report["characters"]
    assert (garment["kind"], garment["vertices"]) == ("garment", len(sleeve_vertices)) and "deform_mean" not in garment
    # The sleeve's closest body points lie at its own heights, where the body's
    # weights are linear between rings: the transfer gives the exact blend.
    triangles = np.vstack([sleeve_quads[:, [0, 1, 2]], sleeve_quads[:, [0, 2, 3]]])
    expected = evaluate_transfer(sleeve_vertices, edges(triangles), expected_body_weights(sleeve_vertices[:, 2]),
                                 SKELETON)
    assert expected["stretch_max"] > 0.0
    assert garment["stretch_p99"] == pytest.approx(expected["stretch_p99"], rel=1e-4)
    assert garment["stretch_max"] == pytest.approx(expected["stretch_max"], rel=1e-4)
    # Self-transfer: the body pushed out along its normals gets its own weights back.
    assert (self_check["kind"], self_check["vertices"]) == ("self", 506)
    assert self_check["deform_mean"] == pytest.approx(0.0, abs=1e-6)
    assert self_check["deform_max"] == pytest.approx(0.0, abs=1e-5)


def test_robust_transfer_self_check(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    code, report, stdout = run_eval(["transfer", str(tmp_path / "body.blend"), "--method", "robust"], tmp_path, capsys)
    assert code == 0
    (entry,) = report["characters"]
    # Every vertex of the offset body is copied from the body: its own weights,
    # so the stretch is that of the reference weights on the offset surface.
    vertices, triangles, reference = body_arrays()
    target = self_transfer_target(Mesh(vertices, triangles), BODY_SIZE)
    expected = evaluate_transfer(target.vertices, edges(target.triangles), reference, SKELETON, reference)
    # The default surface smoothing damps weight detail finer than 0.5 % of the
    # body, copied rows included: the weights come back within a hair of the body's.
    assert entry["kind"] == "self"
    assert entry["deform_mean"] == pytest.approx(0.0, abs=2e-5)
    assert entry["deform_max"] == pytest.approx(0.0, abs=5e-4)
    assert entry["stretch_p99"] == pytest.approx(expected["stretch_p99"], rel=1e-2)
    assert entry["stretch_max"] == pytest.approx(expected["stretch_max"], rel=1e-2)
    assert "| character | stretch_p99 | stretch_max | deform_mean | deform_max | seconds |" in stdout
    assert (f"| body | {entry['stretch_p99']:.4g} | {entry['stretch_max']:.4g} | {entry['deform_mean']:.4g} | "
            f"{entry['deform_max']:.4g} |") in stdout


def test_garment_without_source_fails_alone(clean_scene, tmp_path, capsys):
    reset_scene()
    make_sleeve(with_button=False)
    scene_io.save_scene(tmp_path / "sleeve.blend")
    code, report, _ = run_eval(["transfer", str(tmp_path / "sleeve.blend"), "--method", "robust"], tmp_path, capsys)
    assert code == 1
    assert report["characters"][0]["error"] == ("'sleeve' is not rigged, so it is a garment: give the body with "
                                                "--source.")


@pytest.mark.parametrize(
    ("task", "method", "message"),
    [("skin", "magic", "Unknown skin method 'magic': use one of ['boneheat', 'ensemble', 'geometric', "
                       "'heterskinnet', 'nearest_bone', 'rignet', 'skinningnet', 'reference']."),
     ("rig", "file:/no/such/folder", "The folder of predicted rigs '/no/such/folder' does not exist."),
     ("rig", "oracle", "Unknown rig method 'oracle': use file:DIR or one of ['nearest_character', 'rignet', "
                       "'rignet_free_form']."),
     ("transfer", "copy", "Unknown transfer method 'copy': use one of ['closest_point', 'robust'].")],
)
def test_unknown_methods_are_usage_errors(task, method, message, tmp_path, capsys):
    with pytest.raises(InputError) as raised:
        evaluation_methods.check_method(task, method)
    assert str(raised.value) == message
    capsys.readouterr()
    # Through the command line: exit 2 before any file is read (the data need not exist).
    assert main(["eval", task, str(tmp_path / "nothing.blend"), "--method", method]) == 2
    assert capsys.readouterr().err == f"error: {message}\n"


def test_no_data_is_a_usage_error(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    capsys.readouterr()
    assert main(["eval", "skin", str(tmp_path / "empty"), "--method", "reference"]) == 2
    assert capsys.readouterr().err == f"error: No loadable file found in {tmp_path / 'empty'}.\n"
    assert main(["eval", "skin", str(tmp_path / "missing"), "--method", "reference"]) == 2
    assert capsys.readouterr().err == f"error: '{tmp_path / 'missing'}' is neither a file nor a folder.\n"


def test_registered_rig_method_sees_only_the_mesh(clean_scene, tmp_path, capsys, monkeypatch):
    save_body(tmp_path / "body.blend")
    seen = []

    def predict(mesh):
        seen.append(mesh)
        top = mesh.vertices[:, 2].max()
        return Skeleton([[0, 0, 0], [0, 0, top / 2]], [-1, 0], ("root", "mid"))

    monkeypatch.setitem(evaluation_methods.RIG_METHODS, "halves", evaluation_methods.Method(predict, "test"))
    code, report, _ = run_eval(["rig", str(tmp_path / "body.blend"), "--method", "halves"], tmp_path, capsys)
    assert code == 0 and len(seen) == 1 and seen[0].vertex_count == 506
    assert report["characters"][0]["cd_j2j"] == 0.0


def test_a_training_character_is_scored_without_its_own_rig_to_copy(clean_scene, tmp_path, capsys, monkeypatch):
    """Scored as a training character's file (a Quaternius horse, found by the split's path whatever folder
    ``eval`` is given), a rig method sees the shipped rig library without that character and its
    near-duplicate (the white horse), as for a character the project has never seen; the library is whole
    again after."""
    from autorig_addon.core.rigging import rig_library

    horses = {"quaternius_glb/animals_pack/Horse", "quaternius_glb/animals_pack/Horse_White"}
    whole = set(rig_library.shipped_library().names)
    assert horses <= whole
    save_body(tmp_path / "chars" / "quaternius_glb" / "animals_pack" / "Horse.glb")
    seen = []

    def predict(mesh):
        seen.append(set(rig_library.shipped_library().names))
        return SKELETON

    monkeypatch.setitem(evaluation_methods.RIG_METHODS, "library", evaluation_methods.Method(predict, "test"))
    code, report, _ = run_eval(["rig", str(tmp_path / "chars" / "quaternius_glb"), "--method", "library"], tmp_path,
                               capsys)

    assert code == 0 and report["characters"][0]["name"] == "animals_pack/Horse"
    assert seen == [whole - horses]
    assert set(rig_library.shipped_library().names) == whole


def test_a_file_the_split_does_not_name_or_no_split_leaves_nothing_out(tmp_path, monkeypatch):
    """A file outside the split, or an installed extension without data_split.json: the library stays whole;
    a listed character's file in another format is still found."""
    from autorig_addon.core.rigging import rig_library

    whole = list(rig_library.shipped_library().names)
    # The split names quaternius_glb/animals_pack/Horse.glb: only a path ending in all of that is it.
    for path in ("elsewhere/Body.glb", "other/Horse.glb", "animals_pack/Horse.glb",
                 "xquaternius_glb/animals_pack/Horse.glb"):
        with evaluation_methods.itself_left_out(tmp_path / path):
            assert list(rig_library.shipped_library().names) == whole, path
    # A .blend saved from it is the same character.
    with evaluation_methods.itself_left_out(tmp_path / "quaternius_glb" / "animals_pack" / "Horse.blend"):
        assert "quaternius_glb/animals_pack/Horse" not in set(rig_library.shipped_library().names)
    monkeypatch.setattr(evaluation_methods, "_repository_split", lambda: None)
    with evaluation_methods.itself_left_out(tmp_path / "quaternius_glb" / "animals_pack" / "Horse.glb"):
        assert list(rig_library.shipped_library().names) == whole


def test_json_on_stdout(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    capsys.readouterr()  # what saving the fixture printed
    code = evaluate.run(parse(["skin", str(tmp_path / "body.blend"), "--method", "reference", "--format", "json",
                               "--split-file", str(tmp_path / "none.json"), "--quiet"]))
    report = json.loads(capsys.readouterr().out)
    assert code == 0
    assert (report["task"], report["method"],
            [entry["l1"] for entry in report["characters"]]) == ("skin", "reference", [0.0])


def test_baseline_report_is_shown_beside(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "data" / "body.blend")
    run_eval(["skin", str(tmp_path / "data"), "--method", "reference"], tmp_path, capsys)
    (tmp_path / "report.json").rename(tmp_path / "reference.json")
    code, _, stdout = run_eval(["skin", str(tmp_path / "data" / "body.blend"), "--method", "nearest_bone",
                                "--baseline", str(tmp_path / "reference.json")], tmp_path, capsys)
    assert code == 0
    # Matched by file, although the names differ (folder vs file input):
    # l1 = 48 / 506, recall = 506 / 578 beside the reference's 0 and 1.
    assert "| body | 0.09486 / 0 | 1 / 1 | 0.8754 / 1 |" in stdout
    assert "### Summary (mean: nearest_bone / reference)" in stdout
    (tmp_path / "wrong.json").write_text(json.dumps({"task": "rig", "characters": []}))
    capsys.readouterr()
    assert main(["eval", "skin", str(tmp_path / "data"), "--method", "reference",
                 "--baseline", str(tmp_path / "wrong.json")]) == 2
    assert capsys.readouterr().err == (
        f"error: '{tmp_path / 'wrong.json'}' is not a report of an 'skin' evaluation (write one with --out).\n"
    )


def test_out_naming_a_folder_is_a_usage_error_before_anything_runs(tmp_path, capsys, monkeypatch):
    (tmp_path / "reports").mkdir()
    monkeypatch.setattr(evaluate, "evaluate", lambda *args: pytest.fail("the evaluation ran"))
    capsys.readouterr()
    # The data need not exist: --out is checked first.
    assert main(["eval", "skin", str(tmp_path / "missing"), "--method", "reference",
                 "--out", str(tmp_path / "reports")]) == 2
    assert capsys.readouterr().err == f"error: --out {str(tmp_path / 'reports')!r} is a folder; name a file in it.\n"


def test_a_predicted_rig_with_a_joint_on_its_parent_is_scored(clean_scene, tmp_path, capsys):
    """No armature is built from a predicted rig: a joint at its parent's
    position (a zero-length bone) is scored, not refused."""
    save_body(tmp_path / "body.blend")
    predicted = tmp_path / "predicted"
    predicted.mkdir()
    (predicted / "body.txt").write_text(
        f"joints {LOWER_BONE} 0 0 0\njoints {UPPER_BONE} 0 0 1\njoints Extra 0 0 1\n"
        f"root {LOWER_BONE}\nhier {LOWER_BONE} {UPPER_BONE}\nhier {UPPER_BONE} Extra\n")
    code, report, _ = run_eval(["rig", str(tmp_path / "body.blend"), "--method", f"file:{predicted}"], tmp_path, capsys)
    assert code == 0
    (entry,) = report["characters"]
    assert "error" not in entry
    # The two reference joints are matched exactly; the extra one lies on one of them.
    assert entry["cd_j2j"] == 0.0
