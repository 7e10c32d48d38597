"""The command line (python -m autorig_addon), in process and as a subprocess."""

import json
import subprocess
import sys
import types

import bpy
import numpy as np
import pytest

from autorig_addon import cli
from autorig_addon.blender import convert
from blender_fixtures import LOWER_BONE, UPPER_BONE, build_rig_scene, local_positions, mesh_object, reset_scene
from conftest import REPOSITORY_ROOT


def save_rig_blend(path, sleeve_offset=(0.0, 0.0, 0.0)):
    reset_scene()
    rig = build_rig_scene()
    rig.sleeve.location = sleeve_offset
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return local_positions(rig.sleeve)


def open_blend(path):
    bpy.ops.wm.open_mainfile(filepath=str(path))
    return bpy.data.objects


def test_help_lists_subcommands_without_loading_blender():
    result = subprocess.run(
        [sys.executable, "-c", "import sys; from autorig_addon.cli import main; code = main(['--help']); "
         "sys.exit(3 if 'bpy' in sys.modules else code)"],
        cwd=REPOSITORY_ROOT, capture_output=True, text=True, timeout=60,
    )
    assert result.returncode == 0, result.stderr
    assert "transfer" in result.stdout and "package" in result.stdout


def test_python_dash_m_entry_point_exits_with_usage_code():
    result = subprocess.run([sys.executable, "-m", "autorig_addon"], cwd=REPOSITORY_ROOT, capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert "transfer" in result.stderr


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["/usr/bin/blender", "--background", "--python-expr", "x"], []),
        (["blender", "-b", "--python", "run.py", "--", "transfer", "a.blend"], ["transfer", "a.blend"]),
        (["/repo/autorig_addon/__main__.py", "package", "--out", "d"], ["package", "--out", "d"]),
    ],
)
def test_arguments_from_sys_argv(argv, expected):
    assert cli.arguments_from_sys_argv(argv) == expected


def test_usage_errors_return_2(clean_scene, tmp_path):
    assert cli.main([]) == 2
    assert cli.main(["transfer", "in.blend"]) == 2  # no --source / --out
    assert cli.main(["transfer", str(tmp_path), "--source", "Body", "--out", str(tmp_path / "out")]) == 2  # empty folder
    assert cli.main(["transfer", "in.blend", "--source", "B", "--out", "o.blend", "--mix", "1.5"]) == 2


def test_transfer_one_blend_file(clean_scene, tmp_path, capsys):
    source_path, out_path, summary_path = tmp_path / "scene.blend", tmp_path / "out" / "weighted.blend", tmp_path / "summary.json"
    sleeve_positions = save_rig_blend(source_path)
    capsys.readouterr()

    code = cli.main([
        "transfer", str(source_path), "--source", "Body", "--target", "Sleeve", "--out", str(out_path),
        "--summary", str(summary_path), "--max-influences", "1", "--quiet",
    ])

    assert code == 0
    summary = json.loads(summary_path.read_text())
    assert json.loads(capsys.readouterr().out) == summary
    assert [item["input"] for item in summary["succeeded"]] == [str(source_path)] and summary["failed"] == []
    assert "Sleeve" in summary["succeeded"][0]["targets"]
    objects = open_blend(out_path)
    sleeve = objects["Sleeve"]
    assert sorted(objects.keys()) == ["Armature", "Body", "Sleeve"]
    np.testing.assert_array_equal(local_positions(sleeve), sleeve_positions)  # vertex order kept
    weights = convert.read_weights(sleeve, [LOWER_BONE, UPPER_BONE]).matrix
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)
    assert np.count_nonzero(weights, axis=1).max() == 1
    low = np.flatnonzero(sleeve_positions[:, 2] < 0.7)
    assert weights[low, 0].min() > 0.999
    assert sleeve.parent == objects["Armature"]


def test_default_targets_are_unrigged_meshes(clean_scene, tmp_path, capsys):
    source_path = tmp_path / "scene.blend"
    save_rig_blend(source_path)
    capsys.readouterr()
    assert cli.main(["transfer", str(source_path), "--source", "Body", "--out", str(tmp_path / "o.blend"), "--quiet"]) == 0
    assert list(json.loads(capsys.readouterr().out)["succeeded"][0]["targets"]) == ["Sleeve"]


def test_batch_with_bad_files_keeps_going_and_exits_1(clean_scene, tmp_path, capsys):
    inputs = tmp_path / "inputs"
    (inputs / "more").mkdir(parents=True)
    save_rig_blend(inputs / "good.blend")
    save_rig_blend(inputs / "more" / "far.blend", sleeve_offset=(40.0, 0.0, 0.0))
    reset_scene()
    mesh_object("Lonely", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    bpy.ops.wm.save_as_mainfile(filepath=str(inputs / "no_body.blend"), copy=True)
    (inputs / "broken.glb").write_bytes(b"not a gltf file")
    capsys.readouterr()
    out_dir, summary_path = tmp_path / "out", tmp_path / "summary.json"

    code = cli.main(["transfer", str(inputs), "--source", "Body", "--target", "Sleeve", "--out", str(out_dir), "--summary", str(summary_path)])

    assert code == 1
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert summary == json.loads(summary_path.read_text())
    assert [item["input"] for item in summary["succeeded"]] == [str(inputs / "good.blend")]
    failed = {item["input"]: item["error"] for item in summary["failed"]}
    assert set(failed) == {str(inputs / name) for name in ("broken.glb", "more/far.blend", "no_body.blend")}
    assert "does not overlap" in failed[str(inputs / "more" / "far.blend")]
    assert "No mesh object named 'Body'" in failed[str(inputs / "no_body.blend")]
    assert (out_dir / "good.blend").is_file()
    assert not (out_dir / "no_body.blend").exists()
    assert "4/4" in captured.err  # the progress bar went through every file
    objects = open_blend(out_dir / "good.blend")
    assert convert.read_weights(objects["Sleeve"], [LOWER_BONE]).matrix.max() == pytest.approx(1.0)


def test_missing_input_file_fails_alone(clean_scene, tmp_path, capsys):
    save_rig_blend(tmp_path / "good.blend")
    capsys.readouterr()
    code = cli.main([
        "transfer", str(tmp_path / "missing.blend"), str(tmp_path / "good.blend"),
        "--source", "Body", "--out", str(tmp_path / "out"), "--quiet",
    ])
    assert code == 1
    summary = json.loads(capsys.readouterr().out)
    assert summary["failed"][0]["input"] == str(tmp_path / "missing.blend")
    assert "does not exist" in summary["failed"][0]["error"]
    assert (tmp_path / "out" / "good.blend").is_file()


def test_glb_output_round_trip(clean_scene, tmp_path, capsys):
    save_rig_blend(tmp_path / "scene.blend")
    out_path = tmp_path / "weighted.glb"
    assert cli.main(["transfer", str(tmp_path / "scene.blend"), "--source", "Body", "--target", "Sleeve",
                     "--out", str(out_path), "--quiet"]) == 0
    from autorig_addon.blender import scene_io

    scene_io.load_scene(out_path)
    skinned = [obj for obj in bpy.data.objects if obj.type == "MESH" and {LOWER_BONE, UPPER_BONE} <= set(obj.vertex_groups.keys())]
    assert len(skinned) == 2  # body and sleeve both come back with their bone groups


def test_package_subcommand_calls_build_packages(monkeypatch, tmp_path, capsys):
    calls = []

    def build_packages(out_dir, platforms):
        calls.append((out_dir, platforms))
        return [f"{out_dir}/autorig-{platform}.zip" for platform in platforms]

    monkeypatch.setitem(sys.modules, "autorig_addon.packaging", types.SimpleNamespace(build_packages=build_packages))
    code = cli.main(["package", "--out", str(tmp_path), "--platform", "linux-x64", "--platform", "windows-x64"])
    assert code == 0
    assert calls == [(str(tmp_path), ["linux-x64", "windows-x64"])]
    assert capsys.readouterr().out.split() == [f"{tmp_path}/autorig-linux-x64.zip", f"{tmp_path}/autorig-windows-x64.zip"]


def test_subprocess_stdout_is_pure_json(tmp_path):
    """Blender prints from C while loading and saving; none of it may reach stdout."""
    script = (
        "import sys, bpy; sys.path[:0] = [sys.argv[1], sys.argv[1] + '/tests']; "
        "import blender_fixtures as f; f.reset_scene(); f.build_rig_scene(); "
        "bpy.ops.wm.save_as_mainfile(filepath=sys.argv[2], copy=True)"
    )
    source_path = tmp_path / "scene.blend"
    subprocess.run([sys.executable, "-c", script, str(REPOSITORY_ROOT), str(source_path)], check=True, capture_output=True, timeout=120)
    result = subprocess.run(
        [sys.executable, "-m", "autorig_addon", "transfer", str(source_path), "--source", "Body", "--target", "Sleeve",
         "--out", str(tmp_path / "out.blend")],
        cwd=REPOSITORY_ROOT, capture_output=True, text=True, timeout=120,
    )
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["succeeded"][0]["output"] == str(tmp_path / "out.blend")
    assert "1/1 scene.blend: ok" in result.stderr


def test_scene_io_rejects_unknown_and_missing_files(clean_scene, tmp_path):
    from autorig_addon.blender import scene_io
    from autorig_addon.core.errors import InputError

    with pytest.raises(InputError, match=r"Cannot read 'scene.usd': use one of \.blend"):
        scene_io.load_scene(tmp_path / "scene.usd")
    with pytest.raises(InputError, match="does not exist"):
        scene_io.load_scene(tmp_path / "missing.fbx")
    with pytest.raises(InputError, match="Cannot write 'scene.obj'"):
        scene_io.save_scene(tmp_path / "scene.obj")


def test_scene_io_fbx_round_trip_and_obj_import(clean_scene, tmp_path):
    from autorig_addon.blender import scene_io
    from autorig_addon.core.errors import InputError

    build_rig_scene()
    scene_io.save_scene(tmp_path / "rig.fbx")
    scene_io.load_scene(tmp_path / "rig.fbx")
    body = scene_io.find_object("Body", "MESH")
    assert {LOWER_BONE, UPPER_BONE} <= set(body.vertex_groups.keys())
    assert convert.find_armature(body).type == "ARMATURE"
    with pytest.raises(InputError, match="'Body' has type Mesh, expected Armature. Available armature objects: Armature"):
        scene_io.find_object("Body", "ARMATURE")

    (tmp_path / "triangle.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    scene_io.load_scene(tmp_path / "triangle.obj")
    meshes = [obj for obj in bpy.data.objects if obj.type == "MESH"]
    assert len(meshes) == 1 and len(meshes[0].data.vertices) == 3
    with pytest.raises(InputError, match=f"No object named 'Body'. Available: {meshes[0].name}"):
        scene_io.find_object("Body")
