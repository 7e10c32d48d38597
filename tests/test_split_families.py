"""The data split's parts on generated data: glTF skins read without Blender, rig families,
the drawing rule and the skeleton-only flag (no ../shared)."""

import json
import struct

import numpy as np
import pytest

from autorig_addon.core import dataset
from autorig_addon.core.dataset.families import body_of, rig_families, rig_keys
from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.dataset.split import PURPOSE_SKELETON, PURPOSE_SKIN, collect_data, read_data_split
from autorig_addon.core.dataset.split_drawing import TRAIN, VALIDATION, draw_split, interleave_by_folder
from autorig_addon.core.errors import InputError
from autorig_addon.core.io.glb import GLB_CHUNK_HEADER, GLB_HEADER, GLB_JSON_CHUNK, GLB_MAGIC
from autorig_addon.core.io.gltf_skins import SkinRig, declared_skeleton, read_gltf, skin_rigs
from autorig_addon.core.types import Mesh, Skeleton, Weights

BINARY_CHUNK = 0x004E4942  # "BIN"
# A skin of four joints: hips -> spine -> head, and hips -> weapon (a prop point no vertex weights).
JOINT_NAMES = ["hips", "spine", "head", "weapon"]
# Three vertices: all on hips; half spine, half head (unsigned bytes 128/127 of 255); all on spine.
JOINTS = np.array([[0, 0, 0, 0], [1, 2, 0, 0], [1, 0, 0, 0]], dtype=np.uint8)
WEIGHTS = np.array([[255, 0, 0, 0], [128, 127, 0, 0], [255, 0, 0, 0]], dtype=np.uint8)


def skinned_document(buffer_uri=None) -> tuple[dict, bytes]:
    """A glTF document with one skinned triangle and the bytes of its one buffer."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32).tobytes()
    binary = positions + JOINTS.tobytes() + WEIGHTS.tobytes()
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
             {"buffer": 0, "byteOffset": 36, "byteLength": 12},
             {"buffer": 0, "byteOffset": 48, "byteLength": 12}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                 {"bufferView": 1, "componentType": 5121, "count": 3, "type": "VEC4"},
                 {"bufferView": 2, "componentType": 5121, "count": 3, "type": "VEC4", "normalized": True}]
    nodes = [{"name": "hips", "children": [1, 3]}, {"name": "spine", "children": [2]}, {"name": "head"},
             {"name": "weapon"}, {"name": "body", "mesh": 0, "skin": 0}]
    buffer = {"byteLength": len(binary)}
    if buffer_uri:
        buffer["uri"] = buffer_uri
    document = {
        "asset": {"version": "2.0", "extras": {"skeleton": "biped:Biped"}},
        "nodes": nodes, "skins": [{"joints": [0, 1, 2, 3]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}}]}],
        "buffers": [buffer], "bufferViews": views, "accessors": accessors,
    }
    return document, binary


def write_glb(path, document: dict, binary: bytes) -> None:
    text = json.dumps(document).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    chunks = (GLB_CHUNK_HEADER.pack(len(text), GLB_JSON_CHUNK) + text
              + GLB_CHUNK_HEADER.pack(len(binary), BINARY_CHUNK) + binary)
    path.write_bytes(GLB_HEADER.pack(GLB_MAGIC, 2, GLB_HEADER.size + len(chunks)) + chunks)


EXPECTED_RIG = SkinRig(names=("hips", "spine", "head", "weapon"), parents=(-1, 0, 1, 0),
                       weighted=(True, True, True, False))


def test_skins_of_a_glb_give_names_parents_and_the_joints_that_carry_weight(tmp_path):
    document, binary = skinned_document()
    write_glb(tmp_path / "guy.glb", document, binary)
    read_document, buffers = read_gltf(tmp_path / "guy.glb")
    assert buffers[0][:len(binary)] == binary
    assert skin_rigs(read_document, buffers) == (EXPECTED_RIG,)
    assert declared_skeleton(read_document) == "biped:Biped"


def test_skins_of_a_gltf_read_its_buffer_beside_it(tmp_path):
    document, binary = skinned_document("guy%20body.bin")
    (tmp_path / "guy body.bin").write_bytes(binary)
    (tmp_path / "guy.gltf").write_text(json.dumps(document))
    assert skin_rigs(*read_gltf(tmp_path / "guy.gltf")) == (EXPECTED_RIG,)
    (tmp_path / "guy body.bin").unlink()
    with pytest.raises(InputError, match="'guy.gltf' needs the buffer 'guy%20body.bin', which is not beside it"):
        read_gltf(tmp_path / "guy.gltf")


def test_reading_a_file_that_is_not_glb_is_an_input_error(tmp_path):
    (tmp_path / "fake.glb").write_bytes(b"PK\x03\x04" + struct.pack("<III", 0, 0, 0))
    with pytest.raises(InputError, match="'fake.glb' is not a binary glTF file"):
        read_gltf(tmp_path / "fake.glb")


def test_rig_keys_tie_copies_of_a_rig_that_differ_by_a_weightless_joint():
    plain = SkinRig(("hips", "spine", "head"), (-1, 0, 1), (True, True, True))
    with_prop = EXPECTED_RIG
    plain_keys, prop_keys = rig_keys([plain]), rig_keys([with_prop], "biped:Biped")
    assert plain_keys[0] != prop_keys[0]  # every joint: the prop point makes them differ
    assert plain_keys[1] == prop_keys[1] == "weighted:[('head', 'spine'), ('hips', ''), ('spine', 'hips')]"
    assert prop_keys[2] == "declared:biped:Biped"
    # A weightless joint between two weighted ones: the child hangs under the nearest weighted ancestor.
    gap = SkinRig(("root", "hips", "ctrl", "head"), (-1, 0, 1, 2), (True, True, False, True))
    assert rig_keys([gap])[1] == "weighted:[('head', 'hips'), ('hips', 'root'), ('root', '')]"
    # Two joints say nothing: a test cylinder shares no rig with another by its bone names.
    assert rig_keys([SkinRig(("Bone", "Bone.001"), (-1, 0), (True, True))]) == ()


def test_body_of_reads_the_converters_body_and_variant_names():
    assert body_of("zeroad_humans/m_tunic_long__head_beard.glb") == "zeroad_humans/m_tunic_long"
    assert body_of("pack/Fox.glb") == ""
    assert body_of("pack/__odd.glb") == ""


def test_families_join_shared_rigs_bodies_and_listed_groups():
    keys = {
        "humans/m_a__head_1.glb": ["joints:human"],
        "humans/m_a__head_2.glb": ["joints:human"],
        "humans/m_b__head_1.glb": ["joints:other-export"],  # its body joins it to m_b__head_2
        "humans/m_b__head_2.glb": ["joints:human"],
        "fish/one.glb": ["weighted:fish"],
        "fish/two.glb": ["weighted:fish", "declared:fish"],
        "pack/Horse.glb": ["joints:horse"],
        "pack/Horse_White.glb": ["joints:white-horse"],  # listed with Horse as one body
        "pack/Lone.glb": [],
    }
    families = rig_families(keys, bodies=[("pack/Horse.glb", "pack/Horse_White.glb", "elsewhere/Missing.glb")])
    assert families == [
        ("fish/one.glb", "fish/two.glb"),
        ("humans/m_a__head_1.glb", "humans/m_a__head_2.glb", "humans/m_b__head_1.glb", "humans/m_b__head_2.glb"),
        ("pack/Horse.glb", "pack/Horse_White.glb"),
        ("pack/Lone.glb",),
    ]


def test_interleave_takes_one_family_per_folder_in_turn():
    families = [("a/1.glb",), ("a/2.glb",), ("a/3.glb",), ("b/1.glb",), ("c/1.glb", "c/2.glb")]
    assert interleave_by_folder(families) == [("a/1.glb",), ("b/1.glb",), ("c/1.glb", "c/2.glb"),
                                              ("a/2.glb",), ("a/3.glb",)]


def synthetic_families():
    """Earlier-split families, a kind of one big family and nine small ones, and a kind of one family."""
    families = [
        ("old/a.glb", "new/a2.glb"),  # earlier training character: its new rig-mate trains
        ("old/b.glb", "new/b2.glb"),  # earlier validation character: its rig-mate validates
        ("old/c.glb", "old/d.glb", "new/e.glb"),  # earlier sides mixed: the newcomer trains
        tuple(f"school/fish_{k:02d}.glb" for k in range(30)),  # 30 files on one rig
        *[(f"sea{k % 3}/single_{k}.glb",) for k in range(9)],
        ("birds/only.glb",),
    ]
    kinds = {path: "humanoid" for family in families[:3] for path in family}
    kinds.update({path: "fish" for family in families[3:13] for path in family})
    kinds["birds/only.glb"] = "bird"
    earlier = {"old/a.glb": TRAIN, "old/b.glb": VALIDATION, "old/c.glb": TRAIN, "old/d.glb": VALIDATION}
    return families, kinds, earlier


def test_draw_split_moves_whole_families_and_keeps_earlier_sides():
    families, kinds, earlier = synthetic_families()
    sides = draw_split(families, kinds, earlier, fraction=0.28, seed=7)
    assert set(sides) == {path for family in families for path in family}
    assert [sides[p] for p in ("old/a.glb", "new/a2.glb", "old/b.glb", "new/b2.glb")] == [TRAIN, TRAIN, VALIDATION,
                                                                                           VALIDATION]
    assert [sides[p] for p in ("old/c.glb", "old/d.glb", "new/e.glb")] == [TRAIN, VALIDATION, TRAIN]
    for family in families:
        if not any(path in earlier for path in family):
            assert len({sides[path] for path in family}) == 1, family
    # Fish: 10 new families of 39 files: round(0.28 x 10) = 3 families in validation, within
    # round(0.28 x 39) = 11 files, so the 30-file family trains; one from each sea folder.
    validation = sorted(family for family in families[3:13] if sides[family[0]] == VALIDATION)
    assert len(validation) == 3 and all(len(family) == 1 for family in validation)
    assert sorted(family[0].split("/")[0] for family in validation) == ["sea0", "sea1", "sea2"]
    assert sides["school/fish_00.glb"] == TRAIN
    # A kind with a single new family trains it.
    assert sides["birds/only.glb"] == TRAIN


def test_draw_split_is_the_same_whatever_the_order_and_changes_with_the_seed():
    families, kinds, earlier = synthetic_families()
    first = draw_split(families, kinds, earlier, 0.28, seed=7)
    assert draw_split(list(reversed(families)), kinds, earlier, 0.28, seed=7) == first
    drawn = {seed: tuple(sorted(p for p, side in draw_split(families, kinds, earlier, 0.28, seed).items()
                                if side == VALIDATION and p.startswith("sea"))) for seed in range(6)}
    assert len(set(drawn.values())) > 1


def test_draw_split_takes_the_smallest_family_when_none_fits_and_refuses_mixed_kinds():
    families = [tuple(f"a/x{k}.glb" for k in range(5)), tuple(f"b/y{k}.glb" for k in range(4))]
    kinds = {path: "other" for family in families for path in family}
    sides = draw_split(families, kinds, {}, 0.28, seed=1)
    assert {sides[path] for path in families[1]} == {VALIDATION} and {sides[path] for path in families[0]} == {TRAIN}
    kinds["a/x0.glb"] = "fish"
    with pytest.raises(ValueError, match=r"mixes kinds \['fish', 'other'\]"):
        draw_split(families, kinds, {}, 0.28, seed=1)


# --------------------------------------------------------------------------- the skeleton-only flag

SPLIT = {
    "train": ["bots/rigid.glb", "people/painted.glb"],
    "validation": ["bots/rigid_val.glb", "people/val.glb"],
    "categories": {"humanoid": ["bots/rigid.glb", "people/painted.glb", "bots/rigid_val.glb", "people/val.glb"]},
    "skeleton_only": {"bots/rigid.glb": "rigid weights", "bots/rigid_val.glb": "rigid weights"},
    "excluded": {"people/broken.glb": "a mesh part far off the body"},
}


def test_skeleton_only_characters_serve_skeletons_and_never_skin_weights(tmp_path):
    (tmp_path / "split.json").write_text(json.dumps(SPLIT))
    split = read_data_split(tmp_path / "split.json")
    assert split.skeleton_only == {"bots/rigid.glb": "rigid weights", "bots/rigid_val.glb": "rigid weights"}
    assert split.excluded == {"people/broken.glb": "a mesh part far off the body"}
    assert "people/broken.glb" not in split.subset("all")
    assert split.usable_for("bots/rigid.glb", PURPOSE_SKELETON) and not split.usable_for("bots/rigid.glb", PURPOSE_SKIN)
    assert split.subset("train", PURPOSE_SKIN) == ("people/painted.glb",)
    assert split.subset("train") == split.subset("train", PURPOSE_SKELETON) == ("bots/rigid.glb", "people/painted.glb")
    assert split.subset("all", PURPOSE_SKIN) == ("people/painted.glb", "people/val.glb")
    with pytest.raises(InputError, match="Unknown purpose 'colour': use skeleton or skin"):
        split.usable_for("people/val.glb", "colour")
    (tmp_path / "bad.json").write_text(json.dumps({**SPLIT, "skeleton_only": ["bots/rigid.glb"]}))
    with pytest.raises(InputError, match="'skeleton_only' must map paths to the reason their weights are not used"):
        read_data_split(tmp_path / "bad.json")


def save_sample(folder, name: str) -> None:
    mesh = Mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 0, 2]], float), np.array([[0, 1, 2]]))
    skeleton = Skeleton(np.array([[0, 0, 0], [0, 0, 1]], float), [-1, 0], ("hips", "head"))
    weights = Weights(np.array([[1, 0], [1, 0], [0, 1]], float), ("hips", "head"))
    sample = CharacterSample.from_character(name, "humanoid", mesh, skeleton, weights)
    sample.save(folder / f"{name.replace('/', '_')}.npz")


def test_training_samples_leave_skeleton_only_characters_out_of_skin_training(tmp_path):
    (tmp_path / "split.json").write_text(json.dumps(SPLIT))
    for name in ("bots/rigid", "people/painted", "bots/rigid_val", "people/val"):
        save_sample(tmp_path, name)
    split_file = str(tmp_path / "split.json")
    skin = dataset.training_samples(tmp_path, split_file, PURPOSE_SKIN)
    skeleton = dataset.training_samples(tmp_path, split_file, PURPOSE_SKELETON)
    assert [sample.name for sample in skin] == ["people/painted"]
    assert [sample.name for sample in skeleton] == ["bots/rigid", "people/painted"]


def test_skin_evaluation_leaves_skeleton_only_characters_out_and_says_why(tmp_path):
    from autorig_addon.cli.evaluate import TASK_PURPOSES

    root = tmp_path / "chars"
    for path in SPLIT["train"] + SPLIT["validation"]:
        (root / path).parent.mkdir(parents=True, exist_ok=True)
        (root / path).write_text("")
    (tmp_path / "split.json").write_text(json.dumps(SPLIT))
    skipped = []
    items = collect_data([str(root)], "validation", str(tmp_path / "split.json"), TASK_PURPOSES["skin"],
                         lambda name, reason: skipped.append((name, reason)))
    assert [item.name for item in items] == ["people/val"]
    assert skipped == [("bots/rigid_val", "rigid weights")]
    rig_items = collect_data([str(root)], "validation", str(tmp_path / "split.json"), TASK_PURPOSES["rig"])
    assert [item.name for item in rig_items] == ["bots/rigid_val", "people/val"]
    assert TASK_PURPOSES == {"skin": PURPOSE_SKIN, "rig": PURPOSE_SKELETON, "transfer": PURPOSE_SKIN}
    # With the whole folder ("all"), skin evaluation still leaves them out.
    everything = collect_data([str(root)], "all", str(tmp_path / "split.json"), PURPOSE_SKIN)
    assert [item.name for item in everything] == ["people/painted", "people/val"]
