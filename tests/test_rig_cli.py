"""``python -m autorig_addon rig`` on a procedural biped written by the test (.glb and .blend)."""

import json

import bpy
import numpy as np
import pytest

from autorig_addon.blender import scene_io
from autorig_addon.blender.convert import read_weights
from autorig_addon.cli.main import main
from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging import predict, rig_library
from autorig_addon.core.skeleton.key_joints import key_joints
from autorig_addon.core.types import Mesh, Skeleton
from blender_fixtures import make_armature, mesh_object, reset_scene

#: A symmetric procedural biped (1,866 vertices).
BIPED_SEED = 0
RIG_ARGUMENTS = ["--out", "o.blend"]


def run_main(arguments, capsys):
    """``main(arguments)``: (exit code, stdout, stderr)."""
    capsys.readouterr()
    code = main(arguments)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def save_biped(path, bound_to_armature=False):
    """The biped (object 'Biped') alone, or bound to a two-bone armature 'Old' with its groups."""
    reset_scene()
    character = generate_character(BIPED_SEED, "biped")
    obj = mesh_object("Biped", character.mesh.vertices, character.mesh.triangles)
    if bound_to_armature:
        old = make_armature("Old")
        modifier = obj.modifiers.new("Armature", "ARMATURE")
        modifier.object = old
        obj.parent = old
        group = obj.vertex_groups.new(name="Lower")
        group.add(list(range(len(obj.data.vertices))), 1.0, "REPLACE")
    bpy.context.view_layer.update()
    scene_io.save_scene(path)


def objects_of(path):
    bpy.ops.wm.open_mainfile(filepath=str(path))
    return {obj.name: obj for obj in bpy.data.objects}


def the_armature_and_mesh(path):
    objects = objects_of(path)
    armatures = [obj for obj in objects.values() if obj.type == "ARMATURE"]
    meshes = [obj for obj in objects.values() if obj.type == "MESH"]
    assert len(armatures) == 1 and len(meshes) == 1
    return armatures[0], meshes[0]


def test_rig_a_glb_binds_the_mesh(clean_scene, tmp_path, capsys):
    source, out = tmp_path / "hero.glb", tmp_path / "out" / "hero.blend"
    save_biped(source)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--quiet"], capsys)

    assert code == 0
    summary = json.loads(stdout)
    (item,) = summary["succeeded"]
    assert summary["failed"] == []
    armature, mesh = the_armature_and_mesh(out)
    bones = [bone.name for bone in armature.data.bones]
    assert (item["armature"], item["bones"], item["skin"]) == ("hero_rig", len(bones), "heterskinnet")
    assert armature.name == "hero_rig" and len(bones) >= 5 and all(b.use_deform for b in armature.data.bones)
    assert {group.name for group in mesh.vertex_groups} <= set(bones) and len(mesh.vertex_groups) >= 2
    np.testing.assert_allclose(read_weights(mesh, bones).matrix.sum(axis=1), 1.0, atol=1e-5)
    assert [(m.type, m.object) for m in mesh.modifiers] == [("ARMATURE", armature)]


def test_skin_none_leaves_the_mesh_unbound(clean_scene, tmp_path, capsys):
    source, out = tmp_path / "hero.blend", tmp_path / "rigged.blend"
    save_biped(source)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--skin", "none", "--no-symmetry",
                                "--bandwidth", str(2 * predict.DEFAULT_BANDWIDTH), "--quiet"], capsys)

    assert code == 0 and json.loads(stdout)["succeeded"][0]["skin"] == "none"
    armature, mesh = the_armature_and_mesh(out)
    assert len(armature.data.bones) >= 2
    assert len(mesh.vertex_groups) == 0 and len(mesh.modifiers) == 0 and mesh.parent is None


def test_existing_armature_is_refused_unless_replace(clean_scene, tmp_path, capsys):
    source, out = tmp_path / "bound.blend", tmp_path / "out"
    save_biped(source, bound_to_armature=True)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--quiet"], capsys)

    assert code == 1
    summary = json.loads(stdout)
    assert summary["succeeded"] == [] and summary["failed"] == [{
        "input": str(source),
        "error": "The file already holds an armature ('Old'): pass --replace to remove it and rig the meshes anew.",
    }]
    assert not out.exists()

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--replace", "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert item["replaced"] == ["Old"]
    armature, mesh = the_armature_and_mesh(out / "bound.blend")
    assert armature.name == "bound_rig" and mesh.parent == armature
    assert "Lower" not in mesh.vertex_groups.keys()
    assert [(m.type, m.object) for m in mesh.modifiers] == [("ARMATURE", armature)]


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["rig", "in.blend"], "error: the following arguments are required: --out"),
        (["rig", "in.blend", *RIG_ARGUMENTS, "--bandwidth", str(2 * predict.MAX_BANDWIDTH)],
         f"error: argument --bandwidth: {2 * predict.MAX_BANDWIDTH} is not between "
         f"{predict.MIN_BANDWIDTH:g} and {predict.MAX_BANDWIDTH:g}"),
        (["rig", "in.blend", *RIG_ARGUMENTS, "--density-threshold", "-0.5"],
         f"error: argument --density-threshold: -0.5 is not between {predict.MIN_DENSITY_THRESHOLD:g} and "
         f"{predict.MAX_DENSITY_THRESHOLD:g}"),
        (["rig", "in.blend", *RIG_ARGUMENTS, "--skin", "magic"], "error: argument --skin: invalid choice: 'magic'"),
    ],
)
def test_bad_arguments_exit_2_with_the_reason(arguments, message, capsys):
    code, out, err = run_main(arguments, capsys)
    assert code == 2 and out == ""
    assert message in err


def test_a_standard_biped_with_mixamo_names_then_renamed_to_unreal(clean_scene, tmp_path, capsys):
    source, out, renamed = tmp_path / "hero.glb", tmp_path / "hero.blend", tmp_path / "hero_unreal.blend"
    save_biped(source)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--template", "biped", "--names", "mixamo",
                                "--skin", "geometric", "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert (item["template"], item["rigify"], item["bones"]) == ("biped", False, 22)
    assert item["body"] in ("biped", "quadruped", "other") and 0.0 <= item["confidence"] <= 1.0
    assert item["key_joints_from"] is None  # no training character lies within 0.025 of this procedural biped
    armature, mesh = the_armature_and_mesh(out)
    assert {"mixamorig:Hips", "mixamorig:LeftArm", "mixamorig:RightToeBase"} <= set(armature.data.bones.keys())
    assert "mixamorig:LeftUpLeg" in mesh.vertex_groups

    code, stdout, _ = run_main(["rename", str(out), "--out", str(renamed), "--names", "unreal", "--quiet"], capsys)

    assert code == 0 and json.loads(stdout)["succeeded"][0]["renamed"] == 22
    armature, mesh = the_armature_and_mesh(renamed)
    assert {"pelvis", "upperarm_l", "ball_r"} <= set(armature.data.bones.keys())
    assert "thigh_l" in mesh.vertex_groups and "mixamorig:LeftUpLeg" not in mesh.vertex_groups


def test_rigify_builds_the_control_rig_and_binds_to_its_def_bones(clean_scene, tmp_path, capsys):
    source, out = tmp_path / "hero.glb", tmp_path / "hero.blend"
    save_biped(source)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--template", "biped", "--rigify",
                                "--skin", "geometric", "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert item["rigify"] is True and item["armature"] == "hero_rig"
    objects = objects_of(out)
    rig, mesh = objects["hero_rig"], objects["Biped"]
    assert objects["hero_rig_metarig"].type == "ARMATURE"
    assert [(m.type, m.object) for m in mesh.modifiers] == [("ARMATURE", rig)]
    assert {group.name for group in mesh.vertex_groups} <= {b.name for b in rig.data.bones if b.use_deform}
    assert "DEF-forearm.L" in mesh.vertex_groups


def test_rigify_with_the_free_form_template_is_refused(clean_scene, tmp_path, capsys):
    source = tmp_path / "hero.glb"
    save_biped(source)
    code, stdout, _ = run_main(["rig", str(source), "--out", str(tmp_path / "o.blend"), "--template", "free-form",
                                "--rigify", "--quiet"], capsys)
    assert code == 1
    assert json.loads(stdout)["failed"][0]["error"] == ("Rigify needs a standard skeleton: choose the Auto, Biped or "
                                                       "Quadruped template.")


def save_two_far_parts(path):
    """A post and a small block three heights away from it, saved as one
    character (the block is too small to be refused as a second character:
    9 % of the area, 0.15 of the post's height)."""
    from geometry_fixtures import box_mesh

    reset_scene()
    post, block = box_mesh([-0.1, -0.1, 0.0], [0.1, 0.1, 1.0], 0.05), box_mesh([3.0, -0.05, 0.0], [3.1, 0.05, 0.15],
                                                                              0.05)
    vertices = np.vstack([post.vertices, block.vertices])
    mesh_object("Parts", vertices, np.vstack([post.triangles, block.triangles + len(post.vertices)]))
    bpy.context.view_layer.update()
    scene_io.save_scene(path)


def test_a_poor_skeleton_fails_with_the_reason_unless_kept(clean_scene, tmp_path, capsys):
    source, out = tmp_path / "parts.blend", tmp_path / "rigged.blend"
    save_two_far_parts(source)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--template", "free-form", "--quiet"], capsys)

    assert code == 1 and not out.exists()
    error = json.loads(stdout)["failed"][0]["error"]
    assert error.startswith("The predicted skeleton looks poor: ") and "lies mostly outside the body" in error
    assert error.endswith("keep it anyway with Keep Poor Result (--keep-poor).")

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--template", "free-form", "--keep-poor",
                                "--quiet"], capsys)

    assert code == 0 and out.exists()
    (item,) = json.loads(stdout)["succeeded"]
    assert item["problems"] and all("outside the body" in problem for problem in item["problems"])
    assert any(note.startswith("poor result kept: ") for note in item["notes"])


def test_no_fingers_gives_the_22_bones_on_a_biped_with_fingers_and_fingers_the_52(clean_scene, tmp_path, capsys):
    from test_fingers import procedural_biped_with_box_fingers

    source = tmp_path / "hero.blend"
    reset_scene()
    mesh = procedural_biped_with_box_fingers()
    mesh_object("Biped", mesh.vertices, mesh.triangles)
    bpy.context.view_layer.update()
    scene_io.save_scene(source)
    counts = {}
    for switch in ("--no-fingers", "--fingers"):
        out = tmp_path / f"out{switch}.blend"
        code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--template", "biped", switch,
                                    "--skin", "none", "--quiet"], capsys)
        assert code == 0
        (item,) = json.loads(stdout)["succeeded"]
        armature = next(obj for obj in objects_of(out).values() if obj.type == "ARMATURE")
        counts[switch] = (item["bones"], len(armature.data.bones),
                          sum(bone.name.startswith(("thumb", "f_")) for bone in armature.data.bones))
    assert counts == {"--no-fingers": (22, 22, 0), "--fingers": (52, 52, 30)}


def test_rigid_parts_bind_each_piece_mostly_on_one_bone_wholly_to_it_unless_switched_off(clean_scene, tmp_path,
                                                                                          capsys):
    """The procedural biped is 13 loose pieces (limb boxes, head, torso):
    by default the pieces weighted mostly to one bone are bound wholly to it,
    exactly ``rigid_weights`` of what ``--no-rigid-parts`` gives."""
    from autorig_addon.core.skinning.rigid_parts import rigid_weights
    from autorig_addon.core.types import Mesh

    source = tmp_path / "hero.glb"
    save_biped(source)
    results = {}
    for flag in ("--rigid-parts", "--no-rigid-parts"):
        out = tmp_path / f"hero{flag}.blend"
        code, _, _ = run_main(["rig", str(source), "--out", str(out), "--template", "biped", flag, "--quiet"],
                              capsys)
        assert code == 0
        armature, mesh = the_armature_and_mesh(out)
        bones = [bone.name for bone in armature.data.bones if bone.use_deform]
        vertices = np.array([vertex.co[:] for vertex in mesh.data.vertices])
        triangles = np.array([polygon.vertices[:] for polygon in mesh.data.polygons])
        results[flag] = (Mesh(vertices, triangles), read_weights(mesh, bones).matrix)
    shape, smooth = results["--no-rigid-parts"]
    expected, count = rigid_weights(shape, smooth)
    assert count >= 1
    np.testing.assert_allclose(results["--rigid-parts"][1], expected, atol=1e-6)
    assert not np.allclose(smooth, expected, atol=1e-3)


def known_twin(monkeypatch, widened: float = 1.0):
    """The procedural biped saved by :func:`save_biped`, made the only known
    rig (``procedural/biped_twin``) of the rig library; returns it. ``widened``:
    the known body is that many times as wide (1.8: 0.033 from the biped, a
    relative beyond the known-rig limit but within the kind's)."""
    character = generate_character(BIPED_SEED, "biped")
    known = Mesh(character.mesh.vertices * np.array([widened, 1.0, 1.0]), character.mesh.triangles)
    sample = CharacterSample.from_character("procedural/biped_twin", "biped", known, character.skeleton,
                                            character.weights)
    monkeypatch.setattr(rig_library, "shipped_library", lambda: rig_library.build_rig_library([sample]))
    return character


def test_the_summary_names_the_known_rig_whose_key_joints_were_copied(clean_scene, tmp_path, capsys, monkeypatch):
    source, out = tmp_path / "hero.glb", tmp_path / "hero.blend"
    save_biped(source)
    character = known_twin(monkeypatch)

    # Auto would give the twin's whole rig (test below); the standard biped takes its key joints.
    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--skin", "geometric", "--template", "biped",
                                "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert (item["template"], item["key_joints_from"]) == ("biped", "procedural/biped_twin")
    assert ("Key joints copied from the closest known rig, procedural/biped_twin (surfaces 0.002 of the largest side "
            "apart).") in item["notes"]
    armature, _ = the_armature_and_mesh(out)
    thigh = armature.data.bones["thigh.L"].head_local
    hip = key_joints(character.skeleton.names, character.skeleton.joints, left_direction=[1.0, 0.0, 0.0],
                     parents=character.skeleton.parents).positions["hip.L"]
    np.testing.assert_allclose(np.array(armature.matrix_world @ thigh), hip, atol=1e-5)


def test_a_body_near_a_known_one_gets_its_rig_fitted_and_bound(clean_scene, tmp_path, capsys, monkeypatch):
    source, out = tmp_path / "hero.glb", tmp_path / "hero.blend"
    save_biped(source)
    character = known_twin(monkeypatch)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--skin", "geometric", "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert (item["template"], item["rig_from"], item["bones"]) == ("known rig", "procedural/biped_twin", 26)
    assert item["notes"][0].startswith("Template: the rig of the closest known character, procedural/biped_twin")
    armature, mesh = the_armature_and_mesh(out)
    artist = character.skeleton.deform_subset()
    assert sorted(bone.name for bone in armature.data.bones) == sorted(artist.names)
    for name in ("thigh.L", "hand.R", "spine.006"):
        np.testing.assert_allclose(np.array(armature.matrix_world @ armature.data.bones[name].head_local),
                                   artist.joints[artist.names.index(name)], atol=2e-3)
    # Bound: every vertex weighted, to the twin's bones.
    groups = {group.name for group in mesh.vertex_groups}
    assert groups <= set(artist.names) and all(len(vertex.groups) for vertex in mesh.data.vertices)
    # Engine names need the standard skeleton: asked for, it is built instead.
    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--names", "mixamo", "--quiet"], capsys)
    (item,) = json.loads(stdout)["succeeded"]
    assert (item["template"], item["rig_from"]) == ("biped", None)


def known_rig_edited(monkeypatch, edit) -> object:
    """The procedural biped's twin made the only known rig, its artist's
    skeleton changed by ``edit(joints, deform, names)`` (the arrays edited in
    place); returns the character."""
    character = generate_character(BIPED_SEED, "biped")
    skeleton = character.skeleton
    joints, deform = skeleton.joints.copy(), skeleton.deform.copy()
    edit(joints, deform, skeleton.names)
    edited = Skeleton(joints, skeleton.parents, skeleton.names, None, deform)
    sample = CharacterSample.from_character("procedural/biped_twin", "biped", character.mesh, edited,
                                            character.weights)
    monkeypatch.setattr(rig_library, "shipped_library", lambda: rig_library.build_rig_library([sample]))
    return character


def test_a_known_rig_whose_legs_hang_from_a_bone_that_deforms_nothing_keeps_it_unweighted(clean_scene, tmp_path,
                                                                                        capsys, monkeypatch):
    source, out = tmp_path / "hero.glb", tmp_path / "hero.blend"
    save_biped(source)

    def hips_deform_nothing(joints, deform, names):
        deform[names.index("spine")] = False  # the legs and the spine hang from it

    known_rig_edited(monkeypatch, hips_deform_nothing)
    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--skin", "geometric", "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert (item["template"], item["bones"], item["problems"]) == ("known rig", 26, [])
    armature, mesh = the_armature_and_mesh(out)
    bones = armature.data.bones
    assert not bones["spine"].use_deform and bones["thigh.L"].parent.name == "spine"
    assert sum(bone.use_deform for bone in bones) == 25
    # Bound to the 25 deforming bones only: no vertex on the hips bone, every vertex weighted.
    assert "spine" not in {group.name for group in mesh.vertex_groups}
    assert all(len(vertex.groups) for vertex in mesh.data.vertices)


def test_a_known_rig_that_sits_poorly_on_the_body_gives_way_to_the_standard_skeleton(clean_scene, tmp_path, capsys,
                                                                                    monkeypatch):
    source, out = tmp_path / "hero.glb", tmp_path / "hero.blend"
    save_biped(source)

    def hair_in_the_air(joints, deform, names):
        joints[names.index("hair.002")] += [0.0, 0.0, 1.0]  # a metre above the head

    known_rig_edited(monkeypatch, hair_in_the_air)
    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--skin", "geometric", "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert (item["template"], item["rig_from"], item["problems"]) == ("biped", None, [])
    assert any(note.startswith("The rig of the closest known character, procedural/biped_twin, looks poor on this "
                               "body (") and note.endswith("): it was not used.")
               for note in item["notes"])
    armature, _ = the_armature_and_mesh(out)
    assert "hair.002" not in armature.data.bones and "neck" in armature.data.bones  # the standard biped's


def test_the_summary_names_the_known_body_whose_kind_a_body_read_as_other_took(clean_scene, tmp_path, capsys,
                                                                               monkeypatch, read_as_other):
    source, out = tmp_path / "hero.glb", tmp_path / "hero.blend"
    save_biped(source)
    known_twin(monkeypatch, widened=1.8)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--skin", "geometric", "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    assert (item["template"], item["body"], item["kind_from"]) == ("biped", "other", "procedural/biped_twin")
    assert item["rig_from"] is None
    assert item["confidence"] == pytest.approx(0.9)
    # Without the known body, the free-form skeleton, and no kind taken.
    monkeypatch.setattr(rig_library, "shipped_library", lambda: None)
    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--skin", "geometric", "--quiet"], capsys)
    (item,) = json.loads(stdout)["succeeded"]
    assert (item["template"], item["kind_from"]) == ("free-form", None)


def test_rigify_on_a_body_with_a_known_rig_builds_it_on_the_standard_biped(clean_scene, tmp_path, capsys, monkeypatch):
    source, out = tmp_path / "hero.glb", tmp_path / "hero.blend"
    save_biped(source)
    known_twin(monkeypatch)

    code, stdout, _ = run_main(["rig", str(source), "--out", str(out), "--rigify", "--quiet"], capsys)

    assert code == 0
    (item,) = json.loads(stdout)["succeeded"]
    # Rigify's metarig is the standard biped's layout: the twin's key joints, not its rig.
    assert (item["template"], item["rigify"], item["rig_from"], item["key_joints_from"]) == (
        "biped", True, None, "procedural/biped_twin")
