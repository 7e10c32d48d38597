"""The ``eval`` subcommand (autorig_addon.eval_command) on scenes built in code."""

import argparse
import json
import math

import bpy
import numpy as np
import pytest

from autorig_addon import eval_command
from autorig_addon.blender import scene_io
from autorig_addon.core.evaluation.deformation import unique_edges
from autorig_addon.core.errors import InputError
from autorig_addon.core.io.rignet_rig import write_rignet_rig
from autorig_addon.core.evaluation.skin_metrics import evaluate_transfer
from autorig_addon.core.types import Skeleton, Weights
from blender_fixtures import (
    BODY_HEIGHT,
    BODY_RADIUS,
    LOWER_BONE,
    UPPER_BONE,
    box_geometry,
    build_rig_scene,
    expected_body_weights,
    make_sleeve,
    mesh_object,
    reset_scene,
)

BODY_SIZE = math.sqrt((2 * BODY_RADIUS) ** 2 * 2 + BODY_HEIGHT ** 2)
SKIN_KEYS = {"name", "category", "path", "l1", "precision", "recall", "deform_mean", "deform_max", "seconds", "unweighted"}
RIG_KEYS = {"cd_j2j", "cd_j2b", "cd_b2b", "iou", "precision", "recall", "tree_edit"}


def parse(arguments):
    parser = argparse.ArgumentParser()
    eval_command.add_arguments(parser)
    return parser.parse_args(arguments)


def run_eval(arguments, tmp_path, capsys):
    """Run ``eval`` with a JSON report; returns (exit code, report, stdout)."""
    out = tmp_path / "report.json"
    capsys.readouterr()
    code = eval_command.run(parse(arguments + ["--out", str(out), "--split-file", str(tmp_path / "no_split.json")]))
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
    assert report["task"] == "skin" and report["method"] == "reference"
    (entry,) = report["characters"]
    assert SKIN_KEYS <= set(entry)
    assert entry["name"] == "body" and entry["category"] == "data"
    assert entry["l1"] == 0.0 and entry["precision"] == 1.0 and entry["recall"] == 1.0
    assert entry["deform_mean"] == 0.0 and entry["deform_max"] == 0.0 and entry["unweighted"] == 0
    overall = report["summary"]["overall"]
    assert overall["count"] == 1 and overall["failed"] == 0 and overall["mean"]["l1"] == 0.0
    assert report["summary"]["categories"]["data"]["median"]["recall"] == 1.0
    assert "| body | 0 | 1 | 1 | 0 | 0 | 0 |" in stdout and "**overall**" in stdout


def test_nearest_bone_has_the_hand_computed_error(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    code, report, _ = run_eval(["skin", str(tmp_path / "body.blend"), "--method", "nearest_bone"], tmp_path, capsys)
    assert code == 0
    (entry,) = report["characters"]
    # Rings every 0.1 in z, 24 vertices each, 506 vertices in all. Reference
    # Upper weights 0.25, 0.5, 0.75 at z = 0.9, 1.0, 1.1; nearest bone gives
    # Lower, Lower (tie, first bone), Upper: row errors 0.5, 1.0, 0.5.
    assert entry["l1"] == pytest.approx(24 * (0.5 + 1.0 + 0.5) / 506, abs=1e-6)
    # Every bone the vertex has is a reference bone; the blend rings lose one.
    assert entry["precision"] == pytest.approx(1.0)
    assert entry["recall"] == pytest.approx(506 / (506 + 3 * 24), abs=1e-9)
    assert entry["deform_mean"] > 0.0 and entry["deform_max"] > entry["deform_mean"]


def test_boneheat_runs_on_a_copy_and_counts_unweighted(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    code, report, _ = run_eval(["skin", str(tmp_path / "body.blend"), "--method", "boneheat"], tmp_path, capsys)
    assert code == 0
    (entry,) = report["characters"]
    assert entry["unweighted"] == 0
    # Heat spreads the joint more widely than the artist's 0.4 band but keeps
    # each end wholly on its bone: a small, non-zero error.
    assert 0.0 < entry["l1"] < 0.5 and entry["recall"] > 0.9


def test_unweighted_prediction_stays_at_rest_in_the_deformation_error():
    vertices = np.array([[0.0, 0.0, 0.5], [0.0, 0.0, 1.5], [0.2, 0.0, 1.5]])
    skeleton = Skeleton([[0, 0, 0], [0, 0, 1]], [-1, 0], ("a", "b"), [[0, 0, 1], [0, 0, 2]])
    reference = Weights(np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 1.0]]), ("a", "b"))
    predicted = Weights(np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]), ("a", "b"))
    # One pose: bone b turns 90 degrees about x at its head (0, 0, 1).
    poses = np.broadcast_to(np.eye(3), (1, 2, 3, 3)).copy()
    poses[0, 1] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
    scores = eval_command.skin_scores(vertices, predicted, reference, skeleton, poses)
    assert scores["unweighted"] == 1
    # The unweighted vertex stays at (0.2, 0, 1.5); the reference moves it to
    # (0.2, -0.5, 1.0): 0.5 * sqrt(2) apart. Mean over the three vertices.
    size = np.linalg.norm(vertices.max(0) - vertices.min(0))
    assert scores["deform_max"] == pytest.approx(0.5 * math.sqrt(2) / size)
    assert scores["deform_mean"] == pytest.approx(0.5 * math.sqrt(2) / size / 3)
    assert scores["l1"] == pytest.approx(1.0 / 3)
    assert scores["precision"] == 1.0 and scores["recall"] == pytest.approx(2.0 / 3)


def test_one_failure_does_not_stop_the_evaluation(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "data" / "a_body.blend")
    reset_scene()
    mesh_object("Rock", *box_geometry((0, 0, 0), 1.0))
    scene_io.save_scene(tmp_path / "data" / "b_rock.blend")
    code, report, stdout = run_eval(["skin", str(tmp_path / "data"), "--method", "nearest_bone"], tmp_path, capsys)
    assert code == 1
    body, rock = report["characters"]
    assert "error" not in body and body["l1"] > 0
    assert "No armature" in rock["error"] and "l1" not in rock
    assert report["summary"]["overall"]["count"] == 1 and report["summary"]["overall"]["failed"] == 1
    assert "| b_rock | failed: No armature" in stdout


def test_split_filters_the_data(clean_scene, tmp_path, capsys):
    for name in ("kept", "dropped"):
        save_body(tmp_path / "chars" / "pack" / f"{name}.blend")
    split = {"train": ["pack/dropped.blend"], "validation": ["pack/kept.blend"],
             "categories": {"biped": ["pack/kept.blend", "pack/dropped.blend"]}}
    (tmp_path / "split.json").write_text(json.dumps(split))
    arguments = ["skin", str(tmp_path / "chars"), "--method", "reference", "--split", "validation",
                 "--split-file", str(tmp_path / "split.json")]
    out = tmp_path / "r.json"
    assert eval_command.run(parse(arguments + ["--out", str(out)])) == 0
    report = json.loads(out.read_text())
    assert [(c["name"], c["category"]) for c in report["characters"]] == [("pack/kept", "biped")]
    with pytest.raises(InputError, match="validation"):
        eval_command.collect_data([str(tmp_path / "chars" / "pack" / "dropped.blend")], "validation",
                                  str(tmp_path / "split.json"))


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
    assert RIG_KEYS <= set(entry)
    assert entry["cd_j2j"] == 0.0 and entry["cd_j2b"] == 0.0 and entry["iou"] == 1.0 and entry["tree_edit"] == 0
    _, report, _ = run_eval(["rig", str(tmp_path / "body.blend"), "--method", f"file:{shifted}"], tmp_path, capsys)
    (entry,) = report["characters"]
    # Every joint is 0.05 from its counterpart: the Chamfer distance is 0.05 / size.
    assert entry["cd_j2j"] == pytest.approx(0.05 / BODY_SIZE, rel=1e-6)
    assert entry["iou"] == 1.0  # within the matching tolerance of 0.025 * size
    _, report, _ = run_eval(["rig", str(tmp_path / "body.blend"), "--method", f"file:{tmp_path}"], tmp_path, capsys)
    assert "No predicted rig" in report["characters"][0]["error"]


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
    assert garment["kind"] == "garment" and "deform_mean" not in garment
    # The sleeve's closest body points lie at its own heights, where the body's
    # weights are linear between rings: the transfer gives the exact blend.
    triangles = np.vstack([sleeve_quads[:, [0, 1, 2]], sleeve_quads[:, [0, 2, 3]]])
    skeleton = Skeleton([[0, 0, 0], [0, 0, 1]], [-1, 0], (LOWER_BONE, UPPER_BONE), [[0, 0, 1], [0, 0, 2]])
    expected = evaluate_transfer(sleeve_vertices, unique_edges(triangles), expected_body_weights(sleeve_vertices[:, 2]),
                                 skeleton)
    assert garment["stretch_p99"] == pytest.approx(expected["stretch_p99"], rel=1e-4)
    assert garment["stretch_max"] == pytest.approx(expected["stretch_max"], rel=1e-4)
    assert garment["stretch_max"] > 0.0
    # Self-transfer: the body pushed out along its normals gets its own weights back.
    assert self_check["kind"] == "self"
    assert self_check["deform_mean"] < 1e-6 and self_check["deform_max"] < 1e-5


def test_robust_transfer_self_check(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    code, report, stdout = run_eval(["transfer", str(tmp_path / "body.blend"), "--method", "robust"], tmp_path, capsys)
    assert code == 0
    (entry,) = report["characters"]
    assert entry["kind"] == "self" and entry["deform_mean"] < 1e-3
    assert "stretch_p99" in stdout


def test_garment_without_source_fails_alone(clean_scene, tmp_path, capsys):
    reset_scene()
    make_sleeve(with_button=False)
    scene_io.save_scene(tmp_path / "sleeve.blend")
    code, report, _ = run_eval(["transfer", str(tmp_path / "sleeve.blend"), "--method", "robust"], tmp_path, capsys)
    assert code == 1 and "--source" in report["characters"][0]["error"]


@pytest.mark.parametrize(
    ("task", "method", "message"),
    [("skin", "magic", "Unknown skin method"), ("rig", "file:/no/such/folder", "does not exist"),
     ("rig", "oracle", "Unknown rig method"), ("transfer", "copy", "Unknown transfer method")],
)
def test_unknown_methods_are_input_errors(task, method, message):
    with pytest.raises(InputError, match=message):
        eval_command.check_method(task, method)


def test_registered_rig_method_sees_only_the_mesh(clean_scene, tmp_path, capsys, monkeypatch):
    save_body(tmp_path / "body.blend")
    seen = []

    def predict(mesh):
        seen.append(mesh)
        top = mesh.vertices[:, 2].max()
        return Skeleton([[0, 0, 0], [0, 0, top / 2]], [-1, 0], ("root", "mid"))

    monkeypatch.setitem(eval_command.RIG_METHODS, "halves", eval_command.Method(predict, "test"))
    code, report, _ = run_eval(["rig", str(tmp_path / "body.blend"), "--method", "halves"], tmp_path, capsys)
    assert code == 0 and len(seen) == 1 and seen[0].vertex_count == 506
    assert report["characters"][0]["cd_j2j"] == 0.0


def test_json_on_stdout(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "body.blend")
    capsys.readouterr()  # what saving the fixture printed
    code = eval_command.run(parse(["skin", str(tmp_path / "body.blend"), "--method", "reference", "--format", "json",
                                   "--split-file", str(tmp_path / "none.json"), "--quiet"]))
    captured = capsys.readouterr().out
    report = json.loads(captured)
    assert code == 0 and report["characters"][0]["l1"] == 0.0


def test_baseline_report_is_shown_beside(clean_scene, tmp_path, capsys):
    save_body(tmp_path / "data" / "body.blend")
    _, _, _ = run_eval(["skin", str(tmp_path / "data"), "--method", "reference"], tmp_path, capsys)
    (tmp_path / "report.json").rename(tmp_path / "reference.json")
    code, _, stdout = run_eval(["skin", str(tmp_path / "data" / "body.blend"), "--method", "nearest_bone",
                                "--baseline", str(tmp_path / "reference.json")], tmp_path, capsys)
    assert code == 0
    # Matched by file, although the names differ (folder vs file input).
    assert "| body | 0.09486 / 0 | 1 / 1 | 0.8754 / 1 |" in stdout
    assert "### Summary (mean: nearest_bone / reference)" in stdout
    with pytest.raises(InputError, match="not a report"):
        (tmp_path / "wrong.json").write_text(json.dumps({"task": "rig", "characters": []}))
        eval_command.run(parse(["skin", str(tmp_path / "data"), "--method", "reference",
                                "--baseline", str(tmp_path / "wrong.json")]))
