"""Normalisation, samples, cache and data split (autorig_addon.core.dataset), no Blender."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

from autorig_addon.core import dataset
from autorig_addon.core.dataset.cache import (
    CACHE_ENVIRONMENT_VARIABLE,
    DEFAULT_CACHE_ROOT,
    build_samples,
    default_cache_dir,
    file_content_hash,
)
from autorig_addon.core.dataset.normalise import (
    FACING_AS_NAMED,
    FACING_TURNED,
    FACING_UNKNOWN,
    apply_transform,
    bone_side,
    facing_decision,
    facing_quarter_turns,
    head_tail_quarter_turns,
    normalise,
)
from autorig_addon.core.dataset.sample import SAMPLE_FORMAT_VERSION, CharacterSample
from autorig_addon.core.dataset.split import (
    DataItem,
    category_of,
    collect_data,
    read_data_split,
    relative_name,
    select_split,
)
from autorig_addon.core.errors import InputError
from autorig_addon.core.types import Mesh, Skeleton, Weights
from geometry_fixtures import cylinder


def biped(facing_plus_y: bool) -> tuple:
    """A box-ish "character" 1.8 tall standing at (3, -2, 0.5) with arms named
    .L/.R; facing -Y puts the left arm at +X (Blender convention)."""
    body = cylinder(radius=0.25, height=1.8, segments=12, rings=10, z0=0.5)
    vertices = body.vertices + [3.0, -2.0, 0.0]
    side = -1.0 if facing_plus_y else 1.0
    skeleton = Skeleton(
        joints=[[3.0, -2.0, 1.4], [3.0, -2.0, 2.0], [3.0 + side * 0.2, -2.0, 2.0], [3.0 - side * 0.2, -2.0, 2.0]],
        parents=[-1, 0, 1, 1],
        names=("Hips", "Chest", "UpperArm.L", "UpperArm.R"),
        tails=[[3.0, -2.0, 2.0], [3.0, -2.0, 2.2], [3.0 + side * 0.5, -2.0, 2.0], [3.0 - side * 0.5, -2.0, 2.0]],
    )
    return Mesh(vertices, body.triangles), skeleton


@pytest.mark.parametrize(
    ("name", "side"),
    [
        ("UpperArm.L", 1), ("hand.r", -1), ("Foot_L", 1), ("toe_r", -1), ("L_Hand", 1), ("r.leg", -1),
        ("mixamorig:LeftArm", 1), ("B_Knee_Right", -1), ("Spine", 0), ("Tail", 0), ("Lower", 0), ("Root", 0),
        ("LeftRight", 0),
        # A lone letter between separators (Character Studio's Biped, Red Eclipse's twist bones).
        ("bip01 l hand", 1), ("bip01 r calf", -1), ("thigh.L.01", 1), ("finger_index.01.R.02", -1),
        # A word outranks a letter: 0 A.D.'s giraffe names its rear legs left_r_ and right_r_.
        ("left_r_leg_top", 1), ("right_f_foot", -1), ("Bovidae_FrontCalf_left", 1),
    ],
)
def test_bone_side_from_names(name, side):
    assert bone_side(name) == side


def test_normalise_puts_feet_at_zero_centres_and_scales_to_unit_height():
    mesh, skeleton = biped(facing_plus_y=False)
    result = normalise(mesh, skeleton)
    low, high = result.mesh.vertices.min(axis=0), result.mesh.vertices.max(axis=0)
    assert low[2] == pytest.approx(0.0, abs=1e-12)
    # The tallest side (1.8 high, 0.5 wide) becomes 1.
    assert high[2] - low[2] == pytest.approx(1.0)
    np.testing.assert_allclose((low[:2] + high[:2]) / 2.0, [0.0, 0.0], atol=1e-12)
    assert result.facing == FACING_AS_NAMED
    # The transform maps the original joints onto the moved ones.
    np.testing.assert_allclose(apply_transform(skeleton.joints, result.transform), result.skeleton.joints, atol=1e-12)
    # Hips at height 1.4 - 0.5 above the feet, divided by the 1.8 height.
    assert result.skeleton.joints[0, 2] == pytest.approx(0.9 / 1.8)
    np.testing.assert_array_equal(result.mesh.triangles, mesh.triangles)


def test_normalise_turns_a_character_facing_plus_y():
    mesh, skeleton = biped(facing_plus_y=True)
    assert skeleton.joints[2, 0] < skeleton.joints[3, 0]  # UpperArm.L at -X: faces +Y
    result = normalise(mesh, skeleton)
    assert result.facing == FACING_TURNED
    left, right = result.skeleton.joints[2], result.skeleton.joints[3]
    assert left[0] == pytest.approx(0.2 / 1.8) and right[0] == pytest.approx(-0.2 / 1.8)
    # A half turn about z: x and y change sign, heights stay.
    np.testing.assert_allclose(result.transform[:3, :3], np.diag([-1.0, -1.0, 1.0]) / 1.8, atol=1e-12)
    assert np.linalg.det(result.transform[:3, :3]) > 0  # triangles keep their orientation


def test_normalise_turns_a_character_facing_sideways_by_a_quarter():
    mesh, skeleton = biped(facing_plus_y=False)
    # Turn the whole character 90 degrees counter-clockwise: it faces +X, its left is at +Y.
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    turned_mesh = Mesh(mesh.vertices @ turn.T, mesh.triangles)
    turned = Skeleton(skeleton.joints @ turn.T, skeleton.parents, skeleton.names, skeleton.tails @ turn.T)
    assert facing_quarter_turns(turned) == 3
    result = normalise(turned_mesh, turned)
    assert result.facing == FACING_TURNED
    expected = normalise(mesh, skeleton)
    np.testing.assert_allclose(result.skeleton.joints, expected.skeleton.joints, atol=1e-12)
    np.testing.assert_allclose(result.mesh.vertices, expected.mesh.vertices, atol=1e-12)


def test_normalise_keeps_orientation_when_names_say_nothing():
    mesh, skeleton = biped(facing_plus_y=True)
    anonymous = Skeleton(skeleton.joints, skeleton.parents, ("a", "b", "c", "d"), skeleton.tails)
    result = normalise(mesh, anonymous)
    assert result.facing == FACING_UNKNOWN
    assert result.transform[0, 0] > 0


def quadruped(left_x: float, deform_sides: bool = True) -> Skeleton:
    """A four-legged animal 2 long along y with its head at -Y (facing -Y) and
    its tail at +Y; its legs named .L lie at x = ``left_x`` (+0.3 is Blender's
    convention, -0.3 a mirrored naming)."""
    joints = [[0, 0, 1], [0, -0.9, 1.3], [0, 1.0, 1.0],
              [left_x, -0.7, 0.9], [left_x, -0.7, 0.0], [-left_x, -0.7, 0.9], [-left_x, -0.7, 0.0],
              [left_x, 0.7, 0.9], [left_x, 0.7, 0.0], [-left_x, 0.7, 0.9], [-left_x, 0.7, 0.0]]
    names = ("spine", "head", "tail", "front_leg.L", "front_foot.L", "front_leg.R", "front_foot.R",
             "hind_leg.L", "hind_foot.L", "hind_leg.R", "hind_foot.R")
    return Skeleton(joints, [-1, 0, 0, 0, 3, 0, 5, 0, 7, 0, 9], names, deform=[True] * 11 if deform_sides else None)


def turned_about_z(skeleton: Skeleton, degrees: float) -> Skeleton:
    angle = np.radians(degrees)
    turn = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    return Skeleton(skeleton.joints @ turn.T, skeleton.parents, skeleton.names, skeleton.tails @ turn.T,
                    skeleton.deform)


def test_the_head_ahead_of_the_tail_outranks_mirrored_side_names():
    # 0 A.D.'s cattle face -Y with their .L legs at -X: the names alone would turn them half around.
    mirrored = quadruped(left_x=-0.3)
    assert facing_quarter_turns(mirrored) == 2 and head_tail_quarter_turns(mirrored) == 0
    decision = facing_decision(mirrored)
    assert decision.quarter_turns == 0 and decision.facing == FACING_AS_NAMED
    assert decision.note == ("faces -Y as loaded (head ahead of tail; its side names would have turned it half a "
                             "turn, so they are mirrored or not lateral)")
    # Names and head agree: the names say it.
    assert facing_decision(quadruped(left_x=0.3)).note == "faces -Y as loaded (side names: left joints at +X)"


def test_sides_named_from_the_viewer_turn_the_character_the_other_way():
    # Godot's platformer robot faces -Y with its l- bones at -X: told so, it is kept facing -Y.
    from_the_viewer = quadruped(left_x=-0.3)
    plain = Skeleton(from_the_viewer.joints, from_the_viewer.parents,
                     ("spine", "neck", "back") + from_the_viewer.names[3:], deform=from_the_viewer.deform)
    assert facing_decision(plain).quarter_turns == 2
    decision = facing_decision(plain, sides_named_from_the_viewer=True)
    assert (decision.quarter_turns, decision.facing) == (0, FACING_AS_NAMED)
    assert decision.note == "faces -Y as loaded (side names, given from the viewer: right joints at +X)"
    # Facing +X so named, it turns a quarter the other way: clockwise, its face to -Y.
    assert facing_decision(turned_about_z(plain, 90.0), sides_named_from_the_viewer=True).quarter_turns == 3
    mesh = Mesh(np.array([[-0.4, -1.0, 0.0], [0.4, -1.0, 0.0], [0.0, 1.0, 1.3]]), np.array([[0, 1, 2]]))
    normalised = normalise(mesh, plain, sides_named_from_the_viewer=True)
    np.testing.assert_allclose(normalised.transform[:3, 0], [1.0 / 2.0, 0.0, 0.0])  # kept: only scaled by 1/2


def test_the_head_ahead_of_the_tail_turns_an_animal_without_side_names():
    plain = quadruped(left_x=0.3)
    anonymous = Skeleton(plain.joints, plain.parents, ("spine", "head", "tail") + tuple(f"leg{k}" for k in range(8)))
    facing_plus_x = turned_about_z(anonymous, 90.0)  # head at +X
    assert facing_quarter_turns(facing_plus_x) is None and head_tail_quarter_turns(facing_plus_x) == 3
    decision = facing_decision(facing_plus_x)
    assert (decision.quarter_turns, decision.facing) == (3, FACING_TURNED)
    assert decision.note == "turned a quarter turn clockwise to face -Y (head ahead of tail; no side names)"
    # A head above its tail, not ahead of it (a biped with a hanging tail), says nothing.
    upright = Skeleton([[0, 0, 1.0], [0, 0.05, 1.8], [0, 0.1, 0.9]], [-1, 0, 0], ("hips", "head", "tail"))
    assert head_tail_quarter_turns(upright) is None
    assert facing_decision(upright).note == "facing kept as loaded: no side names, no head ahead of a tail"


def test_facing_reads_deform_bones_near_the_body():
    # Facing -Y (left at +X) with a stance: the left hand and its fingers reach across to -X,
    # and weightless IK targets named for each side sit on the wrong side.
    joints = [[0, 0, 1.0], [0, 0, 1.5], [0.1, 0, 1.5], [0.25, 0, 1.5], [0.1, -0.3, 1.3], [-0.5, -0.4, 1.3],
              [-0.6, -0.4, 1.3], [-0.7, -0.4, 1.3], [-0.8, -0.4, 1.3], [-0.1, 0, 1.5], [-0.25, 0, 1.5],
              [-0.3, -0.1, 1.2], [-0.35, -0.1, 1.0], [-2.0, 0, 0], [2.0, 0, 0]]
    names = ("hips", "chest", "clavicle.L", "upper_arm.L", "forearm.L", "hand.L", "finger.L", "finger.001.L",
             "finger.002.L", "clavicle.R", "upper_arm.R", "forearm.R", "hand.R", "ik_hand.L", "ik_hand.R")
    parents = [-1, 0, 1, 2, 3, 4, 5, 6, 7, 1, 9, 10, 11, 0, 0]
    stance = Skeleton(joints, parents, names, deform=[True] * 13 + [False, False])
    assert facing_quarter_turns(stance) == 0
    # Every side-named joint counted alike, the hand and the IK targets would turn it half around.
    everything = np.array([bone_side(name) for name in names])
    points = np.asarray(joints)
    assert points[everything == 1, 0].mean() < points[everything == -1, 0].mean()


def test_facing_notes_a_body_turned_off_the_axes():
    decision = facing_decision(turned_about_z(quadruped(left_x=0.3), 30.0))
    assert decision.quarter_turns == 0
    assert decision.note == ("faces -Y as loaded (side names: left joints at +X; the left-right line is 30 degrees "
                             "off that axis)")


def test_normalise_notes_its_scale_and_facing():
    mesh, skeleton = biped(facing_plus_y=False)
    assert normalise(mesh, skeleton).notes == ("scaled by 1/1.8: the largest side is z, 1.8 file units (height 1.8)",
                                               "faces -Y as loaded (side names: left joints at +X)")


def test_normalise_rejects_meshes_without_extent():
    skeleton = Skeleton([[0.0, 0.0, 0.0]], [-1], ("Root",))
    with pytest.raises(InputError, match="The mesh has no vertices, so it cannot be normalised"):
        normalise(Mesh(np.zeros((0, 3)), np.zeros((0, 3), int)), skeleton)
    with pytest.raises(InputError, match="All vertices lie at one point, so the mesh cannot be normalised"):
        normalise(Mesh(np.ones((3, 3)), [[0, 1, 2]]), skeleton)


def test_sample_needs_one_weight_row_per_vertex():
    mesh, skeleton = biped(facing_plus_y=False)
    weights = Weights(np.ones((3, 1)), ("Hips",))
    with pytest.raises(InputError,
                       match=f"'Guy': the weights have 3 rows but the mesh has {mesh.vertex_count} vertices"):
        CharacterSample.from_character("Guy", "biped", mesh, skeleton, weights)


def test_long_animals_are_scaled_by_their_longest_side():
    body = cylinder(radius=0.1, height=4.0, segments=8, rings=5)
    lying = Mesh(body.vertices[:, [2, 0, 1]], body.triangles)  # 4 long along x, 0.2 high
    skeleton = Skeleton([[0.0, 0.0, 0.0]], [-1], ("Spine",), [[4.0, 0.0, 0.0]])
    result = normalise(lying, skeleton)
    extent = result.mesh.vertices.max(axis=0) - result.mesh.vertices.min(axis=0)
    np.testing.assert_allclose(extent, [1.0, 0.05, 0.05], atol=1e-12)


#: Loader notes as ``blender.characters`` writes them (one on the bone tails).
NOTES = ("bone tails derived from the joints: the stored ones are point-like", "12 of 120 vertices have no weight")
#: What the normalisation notes about the biped of :func:`make_sample` (1.8 tall, facing +Y).
NORMALISATION_NOTES = ("scaled by 1/1.8: the largest side is z, 1.8 file units (height 1.8)",
                       "turned half a turn to face -Y (side names: left joints at +X)")


def make_sample(name="Guy", category="biped", notes=NOTES):
    mesh, skeleton = biped(facing_plus_y=True)
    z = mesh.vertices[:, 2]
    upper = np.clip((z - 1.6) / 0.4, 0.0, 1.0)
    weights = Weights(np.column_stack([1 - upper, upper, np.zeros_like(z), np.zeros_like(z)]),
                      ("Hips", "Chest", "UpperArm.L", "UpperArm.R"))
    return CharacterSample.from_character(name, category, mesh, skeleton, weights, notes=notes), mesh, weights


def test_sample_round_trip(tmp_path):
    sample, mesh, weights = make_sample()
    assert sample.facing == FACING_TURNED
    assert sample.weights.shape == (mesh.vertex_count, 4)
    np.testing.assert_allclose(sample.weights, weights.matrix)
    path = tmp_path / "guy.npz"
    sample.save(path)
    loaded = CharacterSample.load(path)
    for key in ("vertices", "triangles", "joints", "parents", "tails", "deform", "weights", "transform"):
        np.testing.assert_array_equal(getattr(loaded, key), getattr(sample, key))
    assert loaded.names == sample.names and loaded.name == "Guy" and loaded.category == "biped"
    assert loaded.facing == FACING_TURNED and loaded.source_vertex_count == mesh.vertex_count
    assert loaded.notes == NOTES + NORMALISATION_NOTES
    # The stored transform takes the original mesh onto the stored vertices.
    np.testing.assert_allclose(apply_transform(mesh.vertices, loaded.transform), loaded.vertices, atol=1e-12)
    assert loaded.skin.bone_names == ("Hips", "Chest", "UpperArm.L", "UpperArm.R")


def test_sample_without_notes_round_trips(tmp_path):
    sample, _, _ = make_sample(notes=())
    sample.save(tmp_path / "quiet.npz")
    assert CharacterSample.load(tmp_path / "quiet.npz").notes == NORMALISATION_NOTES


def test_loading_another_format_version_is_an_input_error(tmp_path):
    # Format 4: samples of format 3 (whose bones, when the importer pointed
    # them all one way, kept those tails) must be rebuilt.
    assert SAMPLE_FORMAT_VERSION == 4
    sample, _, _ = make_sample()
    path = tmp_path / "old.npz"
    sample.save(path)
    with np.load(path) as data:
        arrays = dict(data)
    arrays["format_version"] = np.int64(3)
    np.savez(path, **arrays)
    with pytest.raises(InputError, match="'old.npz' is a sample of format 3, this version reads 4: delete it"):
        CharacterSample.load(path)
    with pytest.raises(InputError, match="The sample file '.*missing.npz' does not exist"):
        CharacterSample.load(tmp_path / "missing.npz")


class CountingLoader:
    """Stands in for the Blender loader: returns the biped, counts calls."""

    def __init__(self, sides_named_from_the_viewer: bool = False):
        self.calls = []
        self.sides_named_from_the_viewer = sides_named_from_the_viewer

    def __call__(self, path, target_vertices):
        self.calls.append((path.name, target_vertices))
        sample, mesh, weights = make_sample(name=path.stem)
        _, skeleton = biped(facing_plus_y=True)
        return SimpleNamespace(name=path.stem, category="biped", mesh=mesh, skeleton=skeleton, weights=weights,
                               notes=NOTES, sides_named_from_the_viewer=self.sides_named_from_the_viewer)


def character_files(tmp_path, count=2):
    paths = []
    for index in range(count):
        path = tmp_path / "data" / f"char{index}.glb"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(f"fake character {index}".encode())
        paths.append(path)
    return paths


def test_build_samples_caches_and_reuses(tmp_path):
    paths = character_files(tmp_path)
    loader = CountingLoader()
    first = build_samples(paths, loader, tmp_path / "cache", target_vertices=2000)
    assert [call[0] for call in loader.calls] == ["char0.glb", "char1.glb"]
    assert all(call[1] == 2000 for call in loader.calls)
    assert len(list((tmp_path / "cache").glob("*.npz"))) == 2
    second = build_samples(paths, loader, tmp_path / "cache", target_vertices=2000)
    assert len(loader.calls) == 2  # nothing loaded again
    for built, cached in zip(first, second):
        np.testing.assert_array_equal(built.vertices, cached.vertices)
        np.testing.assert_array_equal(built.weights, cached.weights)
        assert built.name == cached.name
        assert built.notes == cached.notes == NOTES + NORMALISATION_NOTES
    # Other parameters or changed content make new samples.
    build_samples(paths, loader, tmp_path / "cache", target_vertices=1000)
    assert len(loader.calls) == 4
    paths[0].write_bytes(b"edited")
    build_samples(paths, loader, tmp_path / "cache", target_vertices=2000)
    assert [call[0] for call in loader.calls[4:]] == ["char0.glb"]


def test_a_character_named_from_the_viewer_gets_a_sample_of_its_own_turned_the_other_way(tmp_path):
    # The loader's biped faces +Y by its side names; told they were named from the viewer, it faces -Y as given.
    paths = character_files(tmp_path)
    plain = build_samples(paths, CountingLoader(), tmp_path / "cache")
    told_loader = CountingLoader(sides_named_from_the_viewer=True)
    told = build_samples(paths, told_loader, tmp_path / "cache", key_extras=lambda path: (
        {"sides_named_from_the_viewer": True} if path.name == "char1.glb" else {}))
    assert [call[0] for call in told_loader.calls] == ["char1.glb"]  # char0's cached sample still serves
    assert plain[1].facing == FACING_TURNED and told[1].facing == FACING_AS_NAMED
    np.testing.assert_allclose(told[1].vertices[:, :2], -plain[1].vertices[:, :2], atol=1e-12)
    assert len(list((tmp_path / "cache").glob("char1-*.npz"))) == 2


def test_builds_are_reproducible(tmp_path):
    paths = character_files(tmp_path, count=1)
    one = build_samples(paths, CountingLoader(), tmp_path / "a")[0]
    two = build_samples(paths, CountingLoader(), tmp_path / "b")[0]
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == sorted(p.name for p in (tmp_path / "b").iterdir())
    for key in ("vertices", "triangles", "joints", "weights", "transform"):
        np.testing.assert_array_equal(getattr(one, key), getattr(two, key))


def test_cache_folder_follows_the_environment(tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENVIRONMENT_VARIABLE, str(tmp_path / "root"))
    assert default_cache_dir() == tmp_path / "root" / "samples"
    paths = character_files(tmp_path, count=1)
    build_samples(paths, CountingLoader())
    assert len(list((tmp_path / "root" / "samples").glob("char0-*.npz"))) == 1
    monkeypatch.delenv(CACHE_ENVIRONMENT_VARIABLE)
    assert default_cache_dir() == DEFAULT_CACHE_ROOT.expanduser() / "samples"


def test_gltf_hash_covers_its_buffer(tmp_path):
    document = {"asset": {"version": "2.0"}, "buffers": [{"uri": "mesh.bin", "byteLength": 4}]}
    gltf = tmp_path / "c.gltf"
    gltf.write_text(json.dumps(document))
    (tmp_path / "mesh.bin").write_bytes(b"\x00\x01\x02\x03")
    before = file_content_hash(gltf)
    (tmp_path / "mesh.bin").write_bytes(b"\x00\x01\x02\x04")
    assert file_content_hash(gltf) != before


def test_too_coarse_target_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match=r"A target of 10 vertices is too coarse for a character; use at least 100 "
                                         r"\(1000 to 5000 suits networks\)"):
        build_samples(character_files(tmp_path, 1), CountingLoader(), tmp_path / "cache", target_vertices=10)


def test_data_split_in_both_category_layouts(tmp_path):
    by_category = {"train": ["a/x.glb", "b/y.glb"], "validation": ["a/z.glb"],
                   "categories": {"animal": ["a/x.glb", "a/z.glb"], "human": ["b/y.glb"]}}
    by_path = {"train": ["a/x.glb"], "validation": ["a/z.glb"], "categories": {"a/x.glb": "animal"}}
    (tmp_path / "one.json").write_text(json.dumps(by_category))
    (tmp_path / "two.json").write_text(json.dumps(by_path))
    split = read_data_split(tmp_path / "one.json")
    assert split.validation == ("a/z.glb",) and split.subset("all") == ("a/x.glb", "b/y.glb", "a/z.glb")
    assert category_of("b/y.glb", split) == "human"
    assert category_of("c/w.glb", split) == "c"
    assert category_of("a/x.glb", read_data_split(tmp_path / "two.json")) == "animal"
    assert select_split(["a/z.glb", "b/y.glb"], split, "validation") == [0]
    (tmp_path / "bad.json").write_text("[]")
    with pytest.raises(InputError, match="'bad.json' must be a JSON object with 'train' and 'validation' lists"):
        read_data_split(tmp_path / "bad.json")
    (tmp_path / "broken.json").write_text("{")
    with pytest.raises(InputError, match="'broken.json' is not valid JSON"):
        read_data_split(tmp_path / "broken.json")
    with pytest.raises(InputError, match="The data split '.*none.json' does not exist"):
        read_data_split(tmp_path / "none.json")
    with pytest.raises(InputError, match="Unknown split 'test': use train, validation or all"):
        split.subset("test")


def test_relative_names(tmp_path):
    path = tmp_path / "pack" / "Fox.glb"
    assert relative_name(path, tmp_path) == "pack/Fox"
    assert relative_name(path) == "Fox"
    assert relative_name(path, tmp_path / "elsewhere") == "Fox"


def test_collect_data_names_categorises_and_filters(tmp_path):
    chars = tmp_path / "chars"
    for relative in ("pack/a.glb", "pack/b.GLB", "top.obj", "notes/readme.txt"):
        (chars / relative).parent.mkdir(parents=True, exist_ok=True)
        (chars / relative).write_text("")
    split_file = tmp_path / "split.json"
    split_file.write_text(json.dumps({"train": ["pack/a.glb", "top.obj"], "validation": ["pack/b.GLB"],
                                      "categories": {"biped": ["pack/a.glb"]}}))
    a, b, top = chars / "pack" / "a.glb", chars / "pack" / "b.GLB", chars / "top.obj"
    # A folder gives its loadable files (any case of extension), sorted and
    # named by their path below it; the category is the split's, else the
    # folder's, and "uncategorised" for a split entry at the top.
    assert collect_data([str(chars)], "all", str(split_file)) == [
        DataItem(a, "pack/a", "biped"), DataItem(b, "pack/b", "pack"), DataItem(top, "top", "uncategorised"),
    ]
    assert collect_data([str(chars)], "train", str(split_file)) == [
        DataItem(a, "pack/a", "biped"), DataItem(top, "top", "uncategorised"),
    ]
    # A file is named by its stem; the split finds it by the end of its path.
    assert collect_data([str(b)], "validation", str(split_file)) == [DataItem(b, "b", "pack")]
    # The longest split entry that ends the path is the file's.
    split_file.write_text(json.dumps({"train": ["a.glb", "pack/a.glb"], "validation": [],
                                      "categories": {"loose": ["a.glb"], "biped": ["pack/a.glb"]}}))
    assert collect_data([str(a)], "train", str(split_file)) == [DataItem(a, "a", "biped")]
    # With "all", a broken split only loses its categories; a subset needs it.
    split_file.write_text("{")
    assert collect_data([str(a), str(top)], "all", str(split_file)) == [
        DataItem(a, "a", "pack"), DataItem(top, "top", "chars"),
    ]
    with pytest.raises(InputError, match="'split.json' is not valid JSON"):
        collect_data([str(a)], "train", str(split_file))
    with pytest.raises(InputError, match=r"^No loadable file found in .*notes\.$"):
        collect_data([str(chars / "notes")], "all", str(tmp_path / "none.json"))


def test_package_exports_the_public_names():
    # blender.characters and the eval command use ``core.dataset`` as one namespace.
    assert dataset.CharacterSample is CharacterSample and dataset.build_samples is build_samples
    assert dataset.read_data_split is read_data_split and dataset.MIN_TARGET_VERTICES == 100
    assert dataset.collect_data is collect_data and dataset.DataItem is DataItem


def test_training_samples_are_the_cached_training_side_only(tmp_path, monkeypatch):
    # Cached: two training characters, one validation character; read by name, sorted.
    (tmp_path / "split.json").write_text(json.dumps({"train": ["b/y.glb", "a/x.glb"], "validation": ["a/z.glb"]}))
    for index, name in enumerate(("a/z", "b/y", "a/x")):
        make_sample(name=name)[0].save(tmp_path / "samples" / f"{index}.npz")
    found = dataset.training_samples(tmp_path / "samples", str(tmp_path / "split.json"))
    assert [sample.name for sample in found] == ["a/x", "b/y"]
    monkeypatch.setenv("AUTORIG_CACHE", str(tmp_path))  # the default folder is <cache root>/samples
    found = dataset.training_samples(split_file=str(tmp_path / "split.json"))
    assert [sample.name for sample in found] == ["a/x", "b/y"]
    (tmp_path / "samples" / "2.npz").unlink()
    with pytest.raises(InputError, match=(
        rf"^1 training character\(s\) have no cached sample in '{tmp_path / 'samples'}' \(e\.g\. a/x\); build the "
        r"samples first: python -m autorig_addon train samples \(needs the bpy module\)\.$"
    )):
        dataset.training_samples(tmp_path / "samples", str(tmp_path / "split.json"))
