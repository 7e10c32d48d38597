"""The command line (python -m autorig_addon), in process and as a subprocess."""

import io
import json
import math
import re
import subprocess
import sys

import bpy
import numpy as np
import pytest

from autorig_addon import packaging
from autorig_addon.blender import convert
from autorig_addon.blender.jobs.transfer import TransferSettings
from autorig_addon.cli import transfer as cli_transfer
from autorig_addon.cli.batch import TextProgress, output_paths
from autorig_addon.cli.main import SUBCOMMANDS, arguments_from_sys_argv, build_parser, main
from autorig_addon.core.distances.grid import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION
from autorig_addon.core.geometry.smoothing import MAX_SMOOTHING_ITERATIONS
from autorig_addon.core.rigging import predict
from autorig_addon.core.skinning import geometric as skinning
from autorig_addon.core.skinning.methods import DEFAULT_SKIN_METHOD
from autorig_addon.core.transfer import options as transfer_options
from autorig_addon.core.transfer.combine import MIX, REPLACE_ALL
from autorig_addon.core.transfer.options import TransferOptions
from autorig_addon.core.weights import MAX_INFLUENCES
from blender_fixtures import (
    COPY_TOLERANCE,
    LOWER_BONE,
    UPPER_BONE,
    build_rig_scene,
    expected_body_weights,
    local_positions,
    mesh_object,
    reset_scene,
)

BONES = [LOWER_BONE, UPPER_BONE]
#: What the transfer reports for the reference scene's sleeve: its 544 tube
#: vertices copied, the 8 of the button (a part with no match) inpainted.
SLEEVE_SUMMARY = "544 copied, 8 inpainted (1%), 8 on parts with no match"
TRANSFER_ARGUMENTS = ["--source", "Body", "--out", "o.blend"]
SKIN_ARGUMENTS = ["--out", "o.blend"]


def save_rig_blend(path, sleeve_offset=(0.0, 0.0, 0.0), sleeve_scale=1.0):
    reset_scene()
    rig = build_rig_scene()
    rig.sleeve.location = sleeve_offset
    rig.sleeve.scale = (sleeve_scale,) * 3
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return local_positions(rig.sleeve)


def open_blend(path):
    bpy.ops.wm.open_mainfile(filepath=str(path))
    return bpy.data.objects


def parse(arguments):
    return build_parser().parse_args(arguments)


def run_main(arguments, capsys):
    """``main(arguments)``: (exit code, stdout, stderr)."""
    capsys.readouterr()
    code = main(arguments)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def assert_tube_weights_follow_the_body(sleeve, positions):
    """The sleeve's tube copies the body's linear blend; the button goes wholly to Lower."""
    weights = convert.read_weights(sleeve, BONES).matrix
    tube = np.hypot(positions[:, 0], positions[:, 1]) < 0.4
    assert tube.sum() > 500 and (~tube).sum() >= 8
    np.testing.assert_allclose(weights[tube], expected_body_weights(positions[tube, 2]), atol=COPY_TOLERANCE)
    np.testing.assert_allclose(weights[~tube], [[1.0, 0.0]] * int((~tube).sum()), atol=1e-3)


# --------------------------------------------------------------------------- parser, exit codes


def test_help_lists_every_subcommand_without_loading_blender(repository_root):
    result = subprocess.run(
        [sys.executable, "-c", "import sys; from autorig_addon.cli import main; code = main(['--help']); "
         "sys.exit(3 if 'bpy' in sys.modules else code)"],
        cwd=repository_root, capture_output=True, text=True, timeout=60,
    )
    assert result.returncode == 0, result.stderr
    text = " ".join(result.stdout.split())
    assert list(SUBCOMMANDS) == ["transfer", "skin", "rig", "rename", "eval", "package", "train"]
    for name, subcommand in SUBCOMMANDS.items():
        assert f"{name} {subcommand.help}" in text


def test_python_dash_m_without_subcommand_prints_usage_and_exits_2(repository_root):
    result = subprocess.run([sys.executable, "-m", "autorig_addon"], cwd=repository_root, capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 2
    assert result.stderr.startswith("usage: python -m autorig_addon [-h] SUBCOMMAND ...")
    assert result.stdout == ""


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["/usr/bin/blender", "--background", "--python-expr", "x"], []),
        (["blender", "-b", "--python", "run.py", "--", "transfer", "a.blend"], ["transfer", "a.blend"]),
        (["/repo/autorig_addon/__main__.py", "package", "--out", "d"], ["package", "--out", "d"]),
    ],
)
def test_arguments_from_sys_argv(argv, expected):
    assert arguments_from_sys_argv(argv) == expected


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["transfer", "in.blend"], "error: the following arguments are required: --out, --source"),
        (["transfer", "in.blend", *TRANSFER_ARGUMENTS, "--mix", "1.5"],
         "error: argument --mix: 1.5 is not between 0 and 1"),
        (["transfer", "in.blend", *TRANSFER_ARGUMENTS, "--smoothing-iterations", str(MAX_SMOOTHING_ITERATIONS + 1)],
         f"error: argument --smoothing-iterations: {MAX_SMOOTHING_ITERATIONS + 1} is not between 0 and "
         f"{MAX_SMOOTHING_ITERATIONS}"),
        (["transfer", "in.blend", *TRANSFER_ARGUMENTS, "--smoothing-iterations", "1000000"],
         f"error: argument --smoothing-iterations: 1000000 is not between 0 and {MAX_SMOOTHING_ITERATIONS}"),
        (["skin", "in.blend", *SKIN_ARGUMENTS, "--smoothing-iterations", "1000000"],
         f"error: argument --smoothing-iterations: 1000000 is not between 0 and {MAX_SMOOTHING_ITERATIONS}"),
        (["transfer", "in.blend", *TRANSFER_ARGUMENTS, "--max-influences", "-1"],
         f"error: argument --max-influences: -1 is not between 0 and {MAX_INFLUENCES}"),
        (["transfer", "in.blend", *TRANSFER_ARGUMENTS, "--max-normal-angle", "181"],
         "error: argument --max-normal-angle: 181 is not between 0.1 and 180"),
        (["transfer", "in.blend", *TRANSFER_ARGUMENTS, "--max-distance", "0"],
         "error: argument --max-distance: 0 is not positive"),
        (["transfer", "in.blend", *TRANSFER_ARGUMENTS, "--replace", "some"],
         "error: argument --replace: invalid choice: 'some'"),
        (["skin", "in.blend", *SKIN_ARGUMENTS, "--resolution", str(MAX_RESOLUTION + 1)],
         f"error: argument --resolution: {MAX_RESOLUTION + 1} is not between {MIN_RESOLUTION} and {MAX_RESOLUTION}"),
        (["skin", "in.blend", *SKIN_ARGUMENTS, "--resolution", "fine"],
         "error: argument --resolution: fine is not an integer"),
        (["skin", "in.blend", *SKIN_ARGUMENTS, "--falloff", "0.05"],
         "error: argument --falloff: 0.05 is not between 0.1 and 64"),
        (["skin", "in.blend", *SKIN_ARGUMENTS, "--distance", "euclidean"],
         "error: argument --distance: invalid choice: 'euclidean'"),
        (["skin", "in.blend", *SKIN_ARGUMENTS, "--method", "magic"],
         "error: argument --method: invalid choice: 'magic'"),
    ],
)
def test_bad_arguments_exit_2_with_the_reason(arguments, message, capsys):
    code, out, err = run_main(arguments, capsys)
    assert code == 2 and out == ""
    assert message in err


def test_no_subcommand_and_empty_input_folder_exit_2(tmp_path, capsys):
    code, _, err = run_main([], capsys)
    assert code == 2 and err.startswith("usage: python -m autorig_addon")
    code, out, err = run_main(["transfer", str(tmp_path), "--source", "Body", "--out", str(tmp_path / "out")], capsys)
    assert code == 2 and out == ""
    assert err == f"error: No input files found in {tmp_path} (looked for .blend, .glb, .gltf, .fbx, .obj).\n"


def test_option_bounds_are_the_panels(clean_scene):
    """Each number the CLI checks has the same bounds as its panel property
    (both come from the core); the angle is in degrees here, radians there."""
    properties = clean_scene.autorig.bl_rna.properties
    bounds = [
        ("transfer", "--distance-fraction", "distance_fraction",
         transfer_options.MIN_DISTANCE_FRACTION, transfer_options.MAX_DISTANCE_FRACTION),
        ("transfer", "--smoothing-iterations", "smoothing_iterations", 0, MAX_SMOOTHING_ITERATIONS),
        ("transfer", "--max-influences", "max_influences", 0, MAX_INFLUENCES),
        ("transfer", "--smoothing-strength", "smoothing_strength", 0.0, 1.0),
        ("transfer", "--smoothing-length", "smoothing_length",
         transfer_options.MIN_SMOOTHING_LENGTH, transfer_options.MAX_SMOOTHING_LENGTH),
        ("skin", "--resolution", "skin_resolution", MIN_RESOLUTION, MAX_RESOLUTION),
        ("skin", "--falloff", "skin_falloff", skinning.MIN_FALLOFF, skinning.MAX_FALLOFF),
        ("skin", "--max-influences", "skin_max_influences", 0, MAX_INFLUENCES),
        ("skin", "--smoothing-iterations", "skin_smoothing_iterations", 0, MAX_SMOOTHING_ITERATIONS),
        ("rig", "--bandwidth", "rig_bandwidth", predict.MIN_BANDWIDTH, predict.MAX_BANDWIDTH),
        ("rig", "--density-threshold", "rig_density_threshold",
         predict.MIN_DENSITY_THRESHOLD, predict.MAX_DENSITY_THRESHOLD),
    ]
    for subcommand, option, name, low, high in bounds:
        assert (properties[name].hard_min, properties[name].hard_max) == (pytest.approx(low), pytest.approx(high)), name
        common = TRANSFER_ARGUMENTS if subcommand == "transfer" else SKIN_ARGUMENTS
        destination = option[2:].replace("-", "_")
        for value in (low, high):
            assert getattr(parse([subcommand, "in.blend", *common, option, str(value)]), destination) == value
    angle = properties["max_normal_angle"]
    assert math.degrees(angle.hard_min) == pytest.approx(transfer_options.MIN_MAX_NORMAL_ANGLE)
    assert math.degrees(angle.hard_max) == pytest.approx(transfer_options.MAX_MAX_NORMAL_ANGLE)


def test_defaults_are_the_panels_and_the_cores(clean_scene):
    settings = clean_scene.autorig
    transfer = parse(["transfer", "in.blend", *TRANSFER_ARGUMENTS])
    assert cli_transfer.transfer_settings(transfer) == TransferSettings(
        options=TransferOptions(), mask_group=transfer_options.DEFAULT_MASK_GROUP,
    )
    assert transfer.distance_fraction == pytest.approx(settings.distance_fraction)
    assert transfer.max_normal_angle == pytest.approx(math.degrees(settings.max_normal_angle))
    assert (transfer.accept_flipped_normals, transfer.smoothing_iterations, transfer.max_influences,
            transfer.mask_group) == (
        settings.accept_flipped_normals, settings.smoothing_iterations, settings.max_influences, settings.mask_group)
    assert transfer.smoothing_strength == pytest.approx(settings.smoothing_strength)
    assert transfer.smoothing_length == pytest.approx(settings.smoothing_length)
    assert transfer.allow_poor_match == settings.allow_poor_match == transfer_options.DEFAULT_ALLOW_POOR_MATCH
    assert cli_transfer.transfer_settings(parse(["transfer", "in.blend", *TRANSFER_ARGUMENTS, "--allow-poor-match"])
                                          ).options.allow_poor_match is True
    skin = parse(["skin", "in.blend", *SKIN_ARGUMENTS])
    assert (skin.distance.upper(), skin.resolution, skin.max_influences, skin.smoothing_iterations) == (
        settings.skin_distance, settings.skin_resolution, settings.skin_max_influences,
        settings.skin_smoothing_iterations)
    assert (skin.resolution, skin.distance) == (DEFAULT_RESOLUTION, skinning.DEFAULT_DISTANCE)
    assert skin.method.upper() == settings.skin_method and skin.method == DEFAULT_SKIN_METHOD
    assert skin.falloff == pytest.approx(settings.skin_falloff) and skin.falloff == skinning.DEFAULT_FALLOFF
    assert skin.smoothing_strength == pytest.approx(settings.skin_smoothing_strength)
    rig = parse(["rig", "in.blend", *SKIN_ARGUMENTS])
    assert rig.bandwidth == pytest.approx(settings.rig_bandwidth) and rig.bandwidth == predict.DEFAULT_BANDWIDTH
    assert rig.density_threshold == pytest.approx(settings.rig_density_threshold)
    assert rig.density_threshold == predict.DEFAULT_DENSITY_THRESHOLD
    assert rig.symmetry == settings.rig_symmetry == predict.DEFAULT_SYMMETRY
    assert rig.skin.upper() == settings.skin_method and parse(["rig", "in.blend", *SKIN_ARGUMENTS, "--no-symmetry"]
                                                              ).symmetry is False


@pytest.mark.parametrize(
    ("extra", "mode", "factor", "bones"),
    [([], "REPLACE", 1.0, None), (["--mix", "0.25"], MIX, 0.25, None), (["--replace", "all", "--bones", "Lower, Upper"],
                                                                          REPLACE_ALL, 1.0, ("Lower", "Upper"))],
)
def test_write_options_become_transfer_settings(extra, mode, factor, bones):
    settings = cli_transfer.transfer_settings(parse(["transfer", "in.blend", *TRANSFER_ARGUMENTS, *extra]))
    assert (settings.replace_mode, settings.mix_factor, settings.bones) == (mode, factor, bones)


# --------------------------------------------------------------------------- batch machinery


def test_output_paths_keep_sub_folders_and_number_clashes(tmp_path):
    items = [(tmp_path / "a.blend", tmp_path.joinpath("a.blend").relative_to(tmp_path)),
             (tmp_path / "a.glb", tmp_path.joinpath("a.glb").relative_to(tmp_path)),
             (tmp_path / "sub" / "b.fbx", tmp_path.joinpath("sub", "b.fbx").relative_to(tmp_path))]
    out = tmp_path / "out"
    assert output_paths(items, str(out), True, "glb") == [out / "a.glb", out / "a_2.glb", out / "sub" / "b.glb"]
    assert output_paths(items[:1], str(tmp_path / "x.fbx"), False, "glb") == [tmp_path / "x.fbx"]
    assert output_paths(items[:1], str(out), False, "blend") == [out / "a.blend"]  # no extension: a folder


def test_text_progress_draws_the_overall_fraction():
    stream = io.StringIO()
    bar = TextProgress(2, stream)
    bar.update(1, "b.blend", 0.6, "Matching")  # second of two files, 60 % done: 80 % overall
    bar.update(1, "b.blend", 0.601, "Matching")  # under the redraw step: nothing drawn
    bar.finish_item(1, "b.blend", "ok -> out/b.blend")
    assert stream.getvalue() == (
        "\r[" + "#" * 24 + "-" * 6 + "]  80% 2/2 b.blend: Matching\x1b[K"
        "\r2/2 b.blend: ok -> out/b.blend\x1b[K\n"
    )


# --------------------------------------------------------------------------- transfer runs


def test_transfer_one_blend_file(clean_scene, tmp_path, capsys):
    source_path, out_path = tmp_path / "scene.blend", tmp_path / "out" / "weighted.blend"
    summary_path = tmp_path / "summary.json"
    sleeve_positions = save_rig_blend(source_path)

    code, out, _ = run_main([
        "transfer", str(source_path), "--source", "Body", "--target", "Sleeve", "--out", str(out_path),
        "--summary", str(summary_path), "--quiet",
    ], capsys)

    assert code == 0
    summary = json.loads(summary_path.read_text())
    assert json.loads(out) == summary
    (item,) = summary["succeeded"]
    assert summary["failed"] == [] and item.pop("seconds") > 0
    assert item == {"input": str(source_path), "output": str(out_path), "targets": {"Sleeve": SLEEVE_SUMMARY}}
    objects = open_blend(out_path)
    sleeve = objects["Sleeve"]
    assert sorted(objects.keys()) == ["Armature", "Body", "Sleeve"]
    np.testing.assert_array_equal(local_positions(sleeve), sleeve_positions)  # vertex order kept
    assert_tube_weights_follow_the_body(sleeve, sleeve_positions)
    assert sleeve.parent == objects["Armature"]


def test_max_influences_and_default_targets(clean_scene, tmp_path, capsys):
    source_path = tmp_path / "scene.blend"
    save_rig_blend(source_path)
    code, out, _ = run_main(["transfer", str(source_path), "--source", "Body", "--out", str(tmp_path / "o.blend"),
                             "--max-influences", "1", "--quiet"], capsys)
    assert code == 0
    # The only mesh not bound to an armature is the sleeve.
    assert json.loads(out)["succeeded"][0]["targets"] == {"Sleeve": SLEEVE_SUMMARY}
    weights = convert.read_weights(open_blend(tmp_path / "o.blend")["Sleeve"], BONES).matrix
    np.testing.assert_array_equal(np.count_nonzero(weights, axis=1), 1)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)


def test_batch_with_bad_files_keeps_going_and_exits_1(clean_scene, tmp_path, capsys):
    inputs = tmp_path / "inputs"
    (inputs / "more").mkdir(parents=True)
    save_rig_blend(inputs / "good.blend")
    save_rig_blend(inputs / "more" / "far.blend", sleeve_offset=(40.0, 0.0, 0.0))
    reset_scene()
    mesh_object("Lonely", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    bpy.ops.wm.save_as_mainfile(filepath=str(inputs / "no_body.blend"), copy=True)
    (inputs / "broken.glb").write_bytes(b"not a gltf file")
    out_dir, summary_path = tmp_path / "out", tmp_path / "summary.json"

    code, out, err = run_main(["transfer", str(inputs), "--source", "Body", "--target", "Sleeve", "--out", str(out_dir),
                               "--summary", str(summary_path)], capsys)

    assert code == 1
    summary = json.loads(out)
    assert summary == json.loads(summary_path.read_text())
    assert [item["input"] for item in summary["succeeded"]] == [str(inputs / "good.blend")]
    failed = {item["input"]: item["error"] for item in summary["failed"]}
    assert list(failed) == [str(inputs / name) for name in ("broken.glb", "more/far.blend", "no_body.blend")]
    assert failed[str(inputs / "more" / "far.blend")] == (
        "'Sleeve' does not overlap the source 'Body': move the garment onto the body "
        "(or apply the object transforms) before transferring."
    )
    assert failed[str(inputs / "no_body.blend")] == "No mesh object named 'Body'. Available: Lonely."
    assert "Bad glTF" in failed[str(inputs / "broken.glb")]  # Blender's importer's own words
    assert sorted(path.relative_to(out_dir).as_posix() for path in out_dir.rglob("*.blend")) == ["good.blend"]
    # The progress ends each file with its own line, numbered out of four in path order.
    assert "\r1/4 broken.glb: FAILED: " in err
    assert f"\r2/4 good.blend: ok -> {out_dir / 'good.blend'}\x1b[K\n" in err
    assert f"\r3/4 far.blend: FAILED: {failed[str(inputs / 'more' / 'far.blend')]}\x1b[K\n" in err
    assert f"\r4/4 no_body.blend: FAILED: {failed[str(inputs / 'no_body.blend')]}\x1b[K\n" in err
    sleeve = open_blend(out_dir / "good.blend")["Sleeve"]
    assert_tube_weights_follow_the_body(sleeve, local_positions(sleeve))


def test_missing_input_file_fails_alone(clean_scene, tmp_path, capsys):
    save_rig_blend(tmp_path / "good.blend")
    code, out, _ = run_main([
        "transfer", str(tmp_path / "missing.blend"), str(tmp_path / "good.blend"),
        "--source", "Body", "--out", str(tmp_path / "out"), "--quiet",
    ], capsys)
    assert code == 1
    summary = json.loads(out)
    assert summary["failed"] == [{"input": str(tmp_path / "missing.blend"),
                                  "error": f"The file '{tmp_path / 'missing.blend'}' does not exist."}]
    assert [item["output"] for item in summary["succeeded"]] == [str(tmp_path / "out" / "good.blend")]
    assert (tmp_path / "out" / "good.blend").is_file()


def test_glb_output_round_trip(clean_scene, tmp_path, capsys):
    save_rig_blend(tmp_path / "scene.blend")
    out_path = tmp_path / "weighted.glb"
    code, _, _ = run_main(["transfer", str(tmp_path / "scene.blend"), "--source", "Body", "--target", "Sleeve",
                           "--out", str(out_path), "--quiet"], capsys)
    assert code == 0
    from autorig_addon.blender import scene_io

    scene_io.load_scene(out_path)
    sleeve = bpy.data.objects["Sleeve"]
    assert sorted(group.name for group in sleeve.vertex_groups) == BONES
    # glTF splits vertices at seams, so compare by position, not by index.
    assert_tube_weights_follow_the_body(sleeve, np.array([vertex.co[:] for vertex in sleeve.data.vertices]))


def test_subprocess_stdout_is_pure_json(tmp_path, repository_root):
    """Blender prints from C while loading and saving; none of it may reach stdout."""
    script = (
        "import sys, bpy; sys.path[:0] = [sys.argv[1], sys.argv[1] + '/tests']; "
        "import blender_fixtures as f; f.reset_scene(); f.build_rig_scene(); "
        "bpy.ops.wm.save_as_mainfile(filepath=sys.argv[2], copy=True)"
    )
    source_path = tmp_path / "scene.blend"
    subprocess.run([sys.executable, "-c", script, str(repository_root), str(source_path)], check=True,
                   capture_output=True, timeout=120)
    result = subprocess.run(
        [sys.executable, "-m", "autorig_addon", "transfer", str(source_path), "--source", "Body", "--target", "Sleeve",
         "--out", str(tmp_path / "out.blend")],
        cwd=repository_root, capture_output=True, text=True, timeout=120,
    )
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["failed"] == [] and summary["succeeded"][0]["output"] == str(tmp_path / "out.blend")
    assert summary["succeeded"][0]["targets"] == {"Sleeve": SLEEVE_SUMMARY}
    assert f"1/1 scene.blend: ok -> {tmp_path / 'out.blend'}" in result.stderr


# --------------------------------------------------------------------------- package


def test_package_prints_each_zip(monkeypatch, tmp_path, capsys):
    calls = []

    def build_packages(out_dir, platforms, wheel_cache):
        calls.append((out_dir, platforms, wheel_cache))
        return [f"{out_dir}/autorig-{platform}.zip" for platform in platforms]

    monkeypatch.setattr(packaging, "build_packages", build_packages)
    code, out, _ = run_main(["package", "--out", str(tmp_path), "--platform", "linux-x64", "--platform", "windows-x64",
                             "--wheel-cache", "cache"], capsys)
    assert code == 0
    assert calls == [(str(tmp_path), ["linux-x64", "windows-x64"], "cache")]
    assert out == f"{tmp_path}/autorig-linux-x64.zip\n{tmp_path}/autorig-windows-x64.zip\n"


def test_package_download_failure_exits_1(monkeypatch, tmp_path, capsys):
    """A failed build is not a usage error: the command line was right."""
    message = "pip could not download scipy==0.0.1 for platform tags win_amd64. Check the network."

    def build_packages(out_dir, platforms, wheel_cache):
        raise packaging.PackagingError(message)

    monkeypatch.setattr(packaging, "build_packages", build_packages)
    code, out, err = run_main(["package", "--out", str(tmp_path)], capsys)
    assert (code, out, err) == (1, "", f"error: {message}\n")


def test_package_unknown_platform_exits_2_before_building(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(packaging, "build_packages", lambda *arguments: pytest.fail("must not build"))
    code, out, err = run_main(["package", "--out", str(tmp_path), "--platform", "linux-arm64"], capsys)
    assert (code, out) == (2, "")
    assert err == ("error: Unknown platform(s) linux-arm64; choose from linux-x64, windows-x64, macos-x64, "
                   "macos-arm64.\n")


# --------------------------------------------------------------------------- scene files


def test_scene_io_rejects_unknown_and_missing_files(clean_scene, tmp_path):
    from autorig_addon.blender import scene_io
    from autorig_addon.core.errors import InputError

    with pytest.raises(InputError,
                       match=r"^Cannot read 'scene.usd': use one of \.blend, \.glb, \.gltf, \.fbx, \.obj\.$"):
        scene_io.load_scene(tmp_path / "scene.usd")
    with pytest.raises(InputError, match=r"^The file '.*missing\.fbx' does not exist\.$"):
        scene_io.load_scene(tmp_path / "missing.fbx")
    with pytest.raises(InputError, match=r"^Cannot write 'scene.obj': use one of \.blend, \.glb, \.gltf, \.fbx\.$"):
        scene_io.save_scene(tmp_path / "scene.obj")


def test_scene_io_fbx_round_trip_and_obj_import(clean_scene, tmp_path):
    from autorig_addon.blender import scene_io
    from autorig_addon.blender.armature_binding import find_armature
    from autorig_addon.blender.selection import find_object
    from autorig_addon.core.errors import InputError

    build_rig_scene()
    scene_io.save_scene(tmp_path / "rig.fbx")
    scene_io.load_scene(tmp_path / "rig.fbx")
    body = find_object("Body", "MESH")
    assert {LOWER_BONE, UPPER_BONE} <= set(body.vertex_groups.keys())
    assert find_armature(body).type == "ARMATURE"
    with pytest.raises(InputError,
                       match="'Body' has type Mesh, expected Armature. Available armature objects: Armature"):
        find_object("Body", "ARMATURE")

    (tmp_path / "triangle.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    scene_io.load_scene(tmp_path / "triangle.obj")
    meshes = [obj for obj in bpy.data.objects if obj.type == "MESH"]
    assert len(meshes) == 1 and len(meshes[0].data.vertices) == 3
    with pytest.raises(InputError, match=f"No object named 'Body'. Available: {meshes[0].name}"):
        find_object("Body")


# --------------------------------------------------------------------------- bad input reported early and plainly


@pytest.mark.parametrize("out, message", [
    ("weighted.xyz", "--out {out!r}: cannot write '.xyz' files; use one of .blend, .glb, .gltf, .fbx, or a folder."),
    ("weighted.obj", "--out {out!r}: cannot write '.obj' files; use one of .blend, .glb, .gltf, .fbx, or a folder."),
    ("scene.blend/weighted.blend", "--out: {scene!r} is a file, not a folder; nothing can be written inside it."),
])
def test_a_bad_out_is_a_usage_error_before_anything_is_loaded(clean_scene, tmp_path, capsys, monkeypatch, out, message):
    from autorig_addon.blender import scene_io

    scene = str(tmp_path / "scene.blend")
    save_rig_blend(scene)

    def never(path):
        raise AssertionError(f"{path} was loaded")

    monkeypatch.setattr(scene_io, "load_scene", never)
    expected = message.format(out=str(tmp_path / out), scene=scene)
    for subcommand, arguments in (("transfer", ["--source", "Body"]), ("skin", [])):
        code, stdout, err = run_main([subcommand, scene, *arguments, "--out", str(tmp_path / out), "--quiet"], capsys)
        assert (code, stdout, err) == (2, "", f"error: {expected}\n")


def test_a_garment_in_other_units_fails_with_the_factor_unless_allowed(clean_scene, tmp_path, capsys):
    save_rig_blend(tmp_path / "inches.blend", sleeve_scale=2.54)
    arguments = ["transfer", str(tmp_path / "inches.blend"), "--source", "Body", "--target", "Sleeve", "--quiet"]
    code, out, _ = run_main([*arguments, "--out", str(tmp_path / "refused.blend")], capsys)
    assert code == 1
    (failed,) = json.loads(out)["failed"]
    assert "'Sleeve' looks 2.54 times too large for 'Body' (inches and centimetres mixed up?)" in failed["error"]
    assert failed["error"].endswith(
        "To transfer anyway, turn on Allow Poor Match (--allow-poor-match on the command line).")
    assert not (tmp_path / "refused.blend").exists()
    code, out, _ = run_main([*arguments, "--out", str(tmp_path / "allowed.blend"), "--allow-poor-match"], capsys)
    assert code == 0
    weights = convert.read_weights(open_blend(tmp_path / "allowed.blend")["Sleeve"], BONES).matrix
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-6)


def test_skin_at_a_resolution_beyond_the_free_memory_fails_naming_one_that_fits(clean_scene, tmp_path, capsys,
                                                                              monkeypatch):
    from autorig_addon.core import memory

    save_rig_blend(tmp_path / "scene.blend")
    monkeypatch.setattr(memory, "available_memory_bytes", lambda: 2**30)  # a machine with 1 GiB free
    code, out, _ = run_main(["skin", str(tmp_path / "scene.blend"), "--mesh", "Body", "--resolution", "1024",
                             "--out", str(tmp_path / "o.blend"), "--quiet"], capsys)
    assert code == 1
    (failed,) = json.loads(out)["failed"]
    assert re.match(r"^The voxel grid at resolution 1024 \(\d+ x \d+ x \d+ cells\) would need about [\d.]+ GiB of "
                    r"memory, but only 1 GiB is free\. Resolution \d+ fits: lower it to that or less \(Resolution in "
                    r"the Skin panel, --resolution on the command line\)\.$", failed["error"]), failed["error"]
    assert not (tmp_path / "o.blend").exists()


def test_eval_with_an_out_inside_a_file_is_a_usage_error_before_any_scoring(tmp_path, capsys):
    blocker = tmp_path / "report.json"
    blocker.write_text("{}")
    code, out, err = run_main(["eval", "skin", str(tmp_path), "--method", "nearest_bone",
                               "--out", str(blocker / "again.json")], capsys)
    assert (code, out) == (2, "")
    assert err == f"error: --out: {str(blocker)!r} is a file, not a folder; nothing can be written inside it.\n"
