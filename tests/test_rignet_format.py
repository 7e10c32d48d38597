"""RigNet rig_info text format: known files, round trips, malformed input."""

import re

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.io.rignet_rig import read_rignet_rig, rignet_rig_text, write_rignet_rig
from autorig_addon.core.types import Skeleton, Weights

# Hierarchy lines deliberately children-before-parents and joints out of
# order, as RigNet's exporter does not sort them.
SMALL_RIG = """\
joints hand_L 0.6 0.0 1.4
joints hips 0.0 0.0 1.0
joints spine 0.0 0.0 1.3
joints arm_L 0.2 0.0 1.4

joints head 0.0 0.0 1.6
root hips
hier arm_L hand_L
hier spine arm_L
hier hips spine
hier spine head
skin 0 hips 1.0
skin 1 hips 0.25 spine 0.75
skin 3 arm_L 0.5 hand_L 0.5
"""


def test_small_file_parents_and_weights():
    skeleton, weights = read_rignet_rig(SMALL_RIG)
    # Parents first; among ready joints file order decides (spine before its
    # children, arm_L (file index 3) before head (file index 4)).
    assert skeleton.names == ("hips", "spine", "arm_L", "hand_L", "head")
    parent_names = [skeleton.names[p] if p >= 0 else None for p in skeleton.parents]
    assert parent_names == [None, "hips", "spine", "arm_L", "spine"]
    np.testing.assert_allclose(skeleton.joints[skeleton.names.index("hand_L")], [0.6, 0.0, 1.4])
    np.testing.assert_allclose(skeleton.joints[0], [0.0, 0.0, 1.0])
    # spine's tail is the mean of its children's heads (arm_L and head).
    np.testing.assert_allclose(skeleton.tails[1], [0.1, 0.0, 1.5])
    # The leaf hand_L continues its parent direction at half its length.
    np.testing.assert_allclose(skeleton.tails[3], [0.8, 0.0, 1.4])

    assert weights.bone_names == skeleton.names
    assert weights.matrix.shape == (4, 5)
    expected = np.zeros((4, 5))
    expected[0, 0] = 1.0
    expected[1, [0, 1]] = [0.25, 0.75]
    expected[3, [2, 3]] = [0.5, 0.5]  # vertex 2 has no skin line: zero row
    np.testing.assert_array_equal(weights.matrix, expected)


def test_vertex_count_pads_rows_and_rejects_out_of_range():
    _, weights = read_rignet_rig(SMALL_RIG, vertex_count=6)
    assert weights.matrix.shape == (6, 5)
    assert weights.matrix[4:].sum() == 0.0
    with pytest.raises(InputError, match=r"Line 14: vertex index 3 is out of range for a mesh of 3"):
        read_rignet_rig(SMALL_RIG, vertex_count=3)


def test_file_without_skin_gives_no_weights(tmp_path):
    path = tmp_path / "rig.txt"
    path.write_text("joints a 0 0 0\njoints b 0 0 1\nroot a\nhier a b\n")
    skeleton, weights = read_rignet_rig(path)
    assert weights is None
    assert skeleton.names == ("a", "b")
    np.testing.assert_array_equal(skeleton.parents, [-1, 0])
    # Same content through the str path
    skeleton_again, _ = read_rignet_rig(str(path))
    np.testing.assert_array_equal(skeleton_again.joints, skeleton.joints)


def _random_tree_skeleton(rng, joint_count):
    parents = np.array([-1] + [int(rng.integers(0, j)) for j in range(1, joint_count)])
    joints = rng.normal(size=(joint_count, 3))
    names = tuple(f"bone_{j:02d}.{'L' if j % 2 else 'R'}" for j in range(joint_count))
    return Skeleton(joints, parents, names)


def test_round_trip_write_read_is_exact(tmp_path):
    rng = np.random.default_rng(7)
    skeleton = _random_tree_skeleton(rng, 12)
    matrix = rng.random((30, 12)) * (rng.random((30, 12)) < 0.3)
    matrix[:, 0] += 0.01  # every vertex keeps one weight, so the row count survives
    matrix /= matrix.sum(axis=1, keepdims=True)
    weights = Weights(matrix, skeleton.names)

    path = tmp_path / "rig_info.txt"
    write_rignet_rig(path, skeleton, weights)
    skeleton_read, weights_read = read_rignet_rig(path)

    assert skeleton_read.names == skeleton.names
    np.testing.assert_array_equal(skeleton_read.parents, skeleton.parents)
    np.testing.assert_array_equal(skeleton_read.joints, skeleton.joints)  # repr floats: bit exact
    np.testing.assert_array_equal(weights_read.matrix, weights.matrix)
    assert weights_read.bone_names == skeleton.names


def test_round_trip_of_weight_subset_and_empty_rows():
    rng = np.random.default_rng(3)
    skeleton = _random_tree_skeleton(rng, 6)
    subset = (skeleton.names[4], skeleton.names[1])
    matrix = np.array([[0.3, 0.7], [0.0, 0.0], [1.0, 0.0], [0.0, 0.0]])
    text = rignet_rig_text(skeleton, Weights(matrix, subset))
    assert text.count("\nskin ") == 2  # zero rows are not written
    _, weights_read = read_rignet_rig(text, vertex_count=4)
    np.testing.assert_array_equal(weights_read.select_bones(subset).matrix, matrix)
    others = [name for name in skeleton.names if name not in subset]
    assert weights_read.select_bones(others).matrix.sum() == 0.0


def test_reading_unsorted_file_then_writing_gives_sorted_file():
    skeleton, weights = read_rignet_rig(SMALL_RIG)
    skeleton_again, weights_again = read_rignet_rig(rignet_rig_text(skeleton, weights), vertex_count=4)
    assert skeleton_again.names == skeleton.names
    np.testing.assert_array_equal(skeleton_again.parents, skeleton.parents)
    np.testing.assert_array_equal(weights_again.matrix, weights.matrix)


@pytest.mark.parametrize(
    "text, message",
    [
        ("joints a 0 0\nroot a\n", r"Line 1: expected 'joints NAME X Y Z', got 4 fields"),
        ("joints a 0 0 zero\nroot a\n", r"Line 1: joint coordinate 'zero' is not a number"),
        ("joints a 0 0 nan\nroot a\n", r"Line 1: joint coordinate 'nan' is not finite"),
        ("joints a 0 0 0\njoints a 1 0 0\nroot a\n", r"Line 2: joint 'a' is defined twice \(first on line 1\)"),
        ("joints a 0 0 0\n\nbones a\n", r"Line 3: unknown record 'bones'"),
        ("joints a 0 0 0\nroot b\n", r"Line 2: root 'b' is not a joint"),
        ("joints a 0 0 0\nroot a\nhier a c\n", r"Line 3: unknown joint 'c' in 'hier' line"),
        ("joints a 0 0 0\nroot a\nhier a\n", r"Line 3: expected 'hier PARENT CHILD', got 2 fields"),
        ("joints a 0 0 0\nroot a\nskin 0 a\n", r"Line 3: expected 'skin VERTEX NAME WEIGHT"),
        ("joints a 0 0 0\nroot a\nskin 0 a 0.5 a\n", r"Line 3: expected 'skin VERTEX NAME WEIGHT"),
        ("joints a 0 0 0\nroot a\nskin x a 1\n", r"Line 3: vertex index 'x' is not an integer"),
        ("joints a 0 0 0\nroot a\nskin -1 a 1\n", r"Line 3: vertex index -1 is negative"),
        ("joints a 0 0 0\nroot a\nskin 0 a -0.5\n", r"Line 3: negative skin weight -0.5"),
        ("joints a 0 0 0\nroot a\nskin 0 q 1\n", r"Line 3: unknown joint 'q' in 'skin' line"),
        ("joints a 0 0 0\nroot a\nskin 0 a 1\nskin 0 a 1\n", r"Vertex 0 has several 'skin' lines \(lines \[3, 4\]\)"),
        ("root a\n", r"has no 'joints' line; it defines no skeleton"),
    ],
)
def test_malformed_lines_name_the_line(text, message):
    with pytest.raises(InputError, match=message):
        read_rignet_rig(text)


def test_hierarchy_errors():
    joints = "joints a 0 0 0\njoints b 0 0 1\njoints c 0 0 2\njoints d 0 0 3\n"
    with pytest.raises(InputError, match=re.escape(
            "Line 6: several roots ('a' on line 5 and 'b'); a RigNet rig has exactly one root.")):
        read_rignet_rig(joints + "root a\nroot b\nhier a b\nhier b c\nhier c d\n")
    with pytest.raises(InputError, match="exactly one root; joints without a parent: a, c"):
        read_rignet_rig(joints + "root a\nhier a b\nhier c d\n")
    with pytest.raises(InputError, match=re.escape(
            "The joint hierarchy has a cycle through 'c', 'd'; these joints cannot be reached from the root.")):
        read_rignet_rig(joints + "root a\nhier a b\nhier c d\nhier d c\n")
    with pytest.raises(InputError, match=re.escape(
            "The joint hierarchy is a cycle: every joint has a parent, so none can be the root.")):
        read_rignet_rig(joints + "hier a b\nhier b c\nhier c d\nhier d a\n")
    with pytest.raises(InputError, match="Line 5: joint 'a' is its own parent"):
        read_rignet_rig(joints + "hier a a\n")
    with pytest.raises(InputError, match=r"Line 7: joint 'c' already has parent 'b' \(line 6\)"):
        read_rignet_rig(joints + "root a\nhier b c\nhier a c\n")
    with pytest.raises(InputError, match=re.escape("Line 5: root 'b' has a parent ('a'); the root must have none.")):
        read_rignet_rig(joints + "root b\nhier a b\nhier b c\nhier c d\n")


def test_siblings_keep_file_order_and_a_child_listed_first_moves_after_its_parent():
    text = ("joints tip 0 0 2\njoints hips 0 0 0\njoints leg_R -1 0 0\njoints leg_L 1 0 0\njoints spine 0 0 1\n"
            "root hips\nhier spine tip\nhier hips leg_R\nhier hips leg_L\nhier hips spine\n")
    # Ready after hips: leg_R (2), leg_L (3), spine (4) in file order; tip (0) only after spine.
    skeleton, _ = read_rignet_rig(text)
    assert skeleton.names == ("hips", "leg_R", "leg_L", "spine", "tip")
    np.testing.assert_array_equal(skeleton.parents, [-1, 0, 0, 0, 3])
    np.testing.assert_array_equal(skeleton.joints[:, 2], [0, 0, 0, 1, 2])


def test_root_is_inferred_without_root_line():
    skeleton, _ = read_rignet_rig("joints b 0 0 1\njoints a 0 0 0\nhier a b\n")
    assert skeleton.names == ("a", "b")
    np.testing.assert_array_equal(skeleton.parents, [-1, 0])


def test_missing_file_is_input_error(tmp_path):
    missing = str(tmp_path / "missing.txt")
    with pytest.raises(InputError, match=re.escape(f"RigNet rig file not found: {missing!r}.")):
        read_rignet_rig(tmp_path / "missing.txt")


def test_write_rejects_what_the_format_cannot_hold():
    two_roots = Skeleton(np.eye(3), [-1, -1, 1], ("a", "b", "c"))
    with pytest.raises(InputError, match="exactly one root bone, this skeleton has 2 \\(a, b\\)"):
        rignet_rig_text(two_roots)
    spaced = Skeleton(np.eye(3)[:2], [-1, 0], ("upper arm", "b"))
    with pytest.raises(InputError, match=re.escape(
            "Bone name 'upper arm' is empty or contains whitespace, which the RigNet text format cannot store.")):
        rignet_rig_text(spaced)
    chain = Skeleton(np.eye(3)[:2], [-1, 0], ("a", "b"))
    with pytest.raises(InputError, match="missing from the skeleton: z"):
        rignet_rig_text(chain, Weights(np.ones((1, 1)), ("z",)))
    with pytest.raises(InputError,
                       match=re.escape("Weights contain NaN or infinite values; clean them before writing.")):
        rignet_rig_text(chain, Weights(np.array([[np.nan, 1.0]]), ("a", "b")))


# --------------------------------------------------------------------------- files that are not rigs, or damaged ones


def test_a_glb_picked_by_mistake_is_named_as_such(tmp_path):
    path = tmp_path / "character.glb"
    path.write_bytes(b"glTF\x02\x00\x00\x00\x9c\x12\x00\x00JSON{}")  # the header every .glb starts with
    with pytest.raises(InputError, match=re.escape(
            "'character.glb' is a binary glTF file, not a RigNet rig: import it with File > Import > glTF 2.0.")):
        read_rignet_rig(path)


def test_a_file_that_is_not_utf8_text_is_refused_not_a_decode_error(tmp_path):
    path = tmp_path / "rig.txt"
    path.write_bytes("joints épaule 0 0 0\nroot épaule\n".encode("latin-1"))  # saved in a Windows code page
    with pytest.raises(InputError, match=re.escape(
            "'rig.txt' is not a RigNet rig: it is not text (byte 0xe9 at position 7 is not UTF-8).")):
        read_rignet_rig(path)


def test_a_huge_vertex_index_is_refused_before_any_allocation():
    text = "joints a 0 0 0\njoints b 0 0 1\nroot a\nhier a b\nskin 0 a 1.0\nskin 1000000000000 b 1.0\n"
    with pytest.raises(InputError, match=re.escape(
            "Line 6: vertex index 1000000000000 is larger than any mesh can have "
            "(Blender meshes hold at most 2147483647 vertices); the file is damaged.")):
        read_rignet_rig(text)


def test_a_weight_table_larger_than_the_free_memory_is_refused(monkeypatch):
    from autorig_addon.core import memory

    monkeypatch.setattr(memory, "available_memory_bytes", lambda: 2 ** 30)  # a machine with 1 GiB free
    text = "joints a 0 0 0\njoints b 0 0 1\nroot a\nhier a b\nskin 0 a 1.0\nskin 2000000000 b 1.0\n"
    with pytest.raises(InputError, match=re.escape(
            "Line 6: vertex index 2000000000 means a mesh of 2000000001 vertices; its weight table would need "
            "about 29.8 GiB of memory, but only 1 GiB is free. The file is damaged, or import it with its mesh "
            "selected so the indices are checked against it.")):
        read_rignet_rig(text)
    # Checked against a mesh, the same line is out of range.
    with pytest.raises(InputError, match="Line 6: vertex index 2000000000 is out of range for a mesh of 10 vertices"):
        read_rignet_rig(text, vertex_count=10)


@pytest.mark.parametrize("coordinates", ["0 0 1e30", "-2e6 0 0"])
def test_joints_far_beyond_any_character_are_refused(coordinates):
    text = f"joints a 0 0 0\njoints b {coordinates}\nroot a\nhier a b\n"
    with pytest.raises(InputError, match=r"^Line 2: joint 'b' lies at .*, beyond 1e\+06 units from the origin: "
                                         r"Blender cannot keep bone lengths there\."):
        read_rignet_rig(text)


@pytest.mark.parametrize("text, message", [
    ("joints a 0 0 0\njoints b 0 0 0\njoints c 0 0 1\nroot a\nhier a b\nhier b c\n",
     "Line 2: joint 'b' is at the same position as its parent 'a' (line 1)"),
    ("joints a 0 0 0\njoints b 0 0 1\njoints c 0 0 1\nroot a\nhier a b\nhier b c\n",
     "Line 3: joint 'c' is at the same position as its parent 'b' (line 2)"),
    ("joints a 1 1 1\njoints b 1 1 1\nroot a\nhier a b\n",
     "Line 2: joint 'b' is at the same position as its parent 'a' (line 1)"),
])
def test_a_joint_at_its_parents_position_is_refused(text, message):
    with pytest.raises(InputError, match="^" + re.escape(
            f"{message}, so the bone between them has no length or direction (1 such joint(s)). Move one of them, "
            "or remove the duplicate and give its children to the other.") + "$"):
        read_rignet_rig(text)
    # Read for its joints alone (a predicted rig scored by eval), the file is accepted as it is.
    skeleton, _ = read_rignet_rig(text, for_armature=False)
    assert skeleton.bone_count == text.count("joints ")
