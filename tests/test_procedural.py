"""Tests of the procedural character generator."""

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.geometry.closest_point import closest_points_on_triangles
from autorig_addon.core.procedural import (
    KINDS,
    PART_CLOTH,
    PART_DRIVEN,
    PART_RIGID,
    PART_TYPES,
    ProceduralCharacter,
    generate_character,
    generate_characters,
)
from autorig_addon.core.procedural.character_builder import CharacterBuilder
from autorig_addon.core.procedural.frames import axis_frame
from autorig_addon.core.procedural.kinds import BUILDERS
from autorig_addon.core.procedural.part_weights import (
    closest_point_weights,
    joint_blend_weights,
    stack_weight_blocks,
    sum_weight_blocks,
)
from autorig_addon.core.procedural.polylines import cumulative_lengths, points_at_fractions, resample_polyline
from autorig_addon.core.procedural.rig_builder import TAIL_SHRINK, RigBuilder, curling_directions, shrinking_lengths
from autorig_addon.core.procedural.shapes import box_geometry, ellipsoid_geometry, signed_volume
from autorig_addon.core.procedural.tubes import round_radii, tapered_radii

SEEDS_PER_KIND = (0, 1, 2, 3, 4, 5)
MIRROR = np.array([-1.0, 1.0, 1.0])


def characters():
    return [generate_character(seed, kind) for kind in KINDS for seed in SEEDS_PER_KIND]


@pytest.fixture(scope="module")
def samples():
    return characters()


def triangle_areas(vertices, triangles):
    corners = vertices[triangles]
    return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)


def part_triangles(character, part):
    triangles = character.mesh.triangles
    return triangles[character.parts[triangles[:, 0]] == part]


# --- determinism -------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS + (None,))
def test_same_seed_gives_identical_arrays(kind):
    first, second = generate_character(11, kind), generate_character(11, kind)
    np.testing.assert_array_equal(first.mesh.vertices, second.mesh.vertices)
    np.testing.assert_array_equal(first.mesh.triangles, second.mesh.triangles)
    np.testing.assert_array_equal(first.weights.matrix, second.weights.matrix)
    np.testing.assert_array_equal(first.skeleton.joints, second.skeleton.joints)
    np.testing.assert_array_equal(first.skeleton.tails, second.skeleton.tails)
    np.testing.assert_array_equal(first.parts, second.parts)
    assert first.skeleton.names == second.skeleton.names
    assert first.part_names == second.part_names
    assert (first.kind, first.variant) == (second.kind, second.variant)


@pytest.mark.parametrize("kind", KINDS)
def test_different_seeds_give_different_characters(kind):
    a, b = generate_character(0, kind), generate_character(1, kind)
    same_shape = a.mesh.vertices.shape == b.mesh.vertices.shape
    assert not (same_shape and np.allclose(a.mesh.vertices, b.mesh.vertices))
    same_bones = a.skeleton.joints.shape == b.skeleton.joints.shape
    assert not (same_bones and np.allclose(a.skeleton.joints, b.skeleton.joints))


def test_seed_alone_draws_every_kind():
    drawn = {generate_character(seed).kind for seed in range(48)}
    assert drawn == set(KINDS)


def test_variants_of_each_kind_appear():
    expected = {
        "multileg": {"insect", "spider", "centipede"},
        "winged": {"bird", "dragon"},
        "tailed": {"theropod", "lizard", "tailed_humanoid"},
        "long_chain": {"snake", "tentacles", "rope"},
        "fish": {"shark", "reef_fish", "dolphin"},
        "prop": {"door", "lamp", "chest"},
    }
    for kind, variants in expected.items():
        seen = {generate_character(seed, kind).variant for seed in range(16)}
        assert seen == variants, kind


def test_generate_characters_is_the_lazy_sequence_of_seeds():
    lazy = list(generate_characters([4, 9], "fish"))
    for character, seed in zip(lazy, (4, 9)):
        np.testing.assert_array_equal(character.mesh.vertices, generate_character(seed, "fish").mesh.vertices)
        assert character.seed == seed


def test_bad_input_raises_input_error():
    with pytest.raises(InputError, match="kind"):
        generate_character(0, "dragonfly")
    with pytest.raises(InputError, match="seed"):
        generate_character(-1)
    with pytest.raises(InputError, match="seed"):
        generate_character(1.5)


# --- validity of every sample --------------------------------------------------


def test_every_kind_generates_a_character_of_that_kind(samples):
    assert {c.kind for c in samples} == set(KINDS)
    for character in samples:
        assert isinstance(character, ProceduralCharacter)
        assert character.mesh.vertex_count == len(character.parts) == character.weights.vertex_count
        assert character.skeleton.bone_count >= 1
        assert set(character.part_types) <= set(PART_TYPES)
        assert len(set(character.part_names)) == len(character.part_names)
        assert set(np.unique(character.parts)) == set(range(len(character.part_names)))


def test_weights_are_a_partition_of_unity(samples):
    for character in samples:
        weights = character.weights.matrix
        assert weights.min() >= 0.0
        np.testing.assert_allclose(weights.sum(axis=1), 1.0, atol=1e-9, rtol=0)


def test_weight_columns_are_the_skeleton_bones(samples):
    for character in samples:
        assert character.weights.bone_names == character.skeleton.names
        weights = character.weights.matrix
        control = ~character.skeleton.deform
        assert np.all(weights[:, control] == 0.0)
        # Every deforming bone moves some vertex: the weights follow the build.
        assert np.all(weights[:, character.skeleton.deform].max(axis=0) > 0.0), character.kind


def test_skeleton_lists_parents_first(samples):
    for character in samples:
        parents = character.skeleton.parents
        assert np.all(parents < np.arange(len(parents)))
        assert np.all(character.skeleton.bone_lengths > 0.0)


def test_no_degenerate_triangles(samples):
    for character in samples:
        areas = triangle_areas(character.mesh.vertices, character.mesh.triangles)
        assert areas.min() > 1e-12 * character.mesh.bounding_box_diagonal ** 2, (character.kind, character.seed)


def test_triangles_stay_within_one_part(samples):
    for character in samples:
        labels = character.parts[character.mesh.triangles]
        assert np.all(labels == labels[:, :1])


def test_closed_parts_are_watertight_and_face_outwards(samples):
    for character in samples:
        vertices = character.mesh.vertices
        for part in np.flatnonzero(character.part_closed):
            triangles = part_triangles(character, part)
            directed = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
            # Each edge in exactly two triangles, used once in each direction.
            assert len(np.unique(directed, axis=0)) == len(directed), character.part_names[part]
            _, counts = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
            assert np.all(counts == 2), character.part_names[part]
            corners = vertices[triangles]
            volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0
            assert volume > 0.0, character.part_names[part]


def test_open_parts_are_cloth_driven_or_membranes(samples):
    for character in samples:
        for part in np.flatnonzero(~character.part_closed):
            assert character.part_types[part] in (PART_CLOTH, PART_DRIVEN) or "membrane" in character.part_names[part]


def test_left_and_right_bones_mirror_across_x(samples):
    for character in samples:
        skeleton = character.skeleton
        index = {name: k for k, name in enumerate(skeleton.names)}
        left = [name for name in skeleton.names if name.endswith(".L")]
        right = [name for name in skeleton.names if name.endswith(".R")]
        assert len(left) == len(right)
        for name in left:
            twin = index[name[:-2] + ".R"]
            np.testing.assert_allclose(skeleton.joints[twin], skeleton.joints[index[name]] * MIRROR, atol=1e-9, rtol=0)
            np.testing.assert_allclose(skeleton.tails[twin], skeleton.tails[index[name]] * MIRROR, atol=1e-9, rtol=0)


def test_symmetric_kinds_have_sided_limbs():
    for kind in ("biped", "quadruped", "multileg", "winged", "tailed", "fish"):
        names = generate_character(3, kind).skeleton.names
        assert sum(name.endswith(".L") for name in names) >= 2, kind


def test_left_and_right_parts_mirror_with_mirrored_weights(samples):
    for character in samples:
        names = character.part_names
        bones = character.skeleton.names
        swap = [bones.index(b[:-2] + ".R") if b.endswith(".L") else bones.index(b[:-2] + ".L") if b.endswith(".R")
                else k for k, b in enumerate(bones)]
        for part, name in enumerate(names):
            if not name.endswith(".L"):
                continue
            twin = names.index(name[:-2] + ".R")
            left, right = character.parts == part, character.parts == twin
            np.testing.assert_allclose(character.mesh.vertices[right], character.mesh.vertices[left] * MIRROR,
                                       atol=1e-9, rtol=0)
            np.testing.assert_allclose(character.weights.matrix[right], character.weights.matrix[left][:, swap],
                                       atol=1e-12)


def test_rigid_accessory_vertices_follow_exactly_one_bone(samples):
    rigid_seen = 0
    for character in samples:
        for part in np.flatnonzero(np.array(character.part_types) == PART_RIGID):
            rows = character.weights.matrix[character.parts == part]
            assert np.all((rows > 0).sum(axis=1) == 1)
            assert np.all(rows.max(axis=1) == 1.0)
            # One bone for the whole piece.
            assert len(np.unique(rows.argmax(axis=1))) == 1
            rigid_seen += 1
    assert rigid_seen > 20


def deforming_parents(skeleton):
    """Parent of each bone after skipping control bones (-1 for none)."""
    parents = skeleton.parents.copy()
    for k in range(len(parents)):
        while parents[k] >= 0 and not skeleton.deform[parents[k]]:
            parents[k] = parents[parents[k]]
    return parents


def test_body_vertices_blend_only_a_bone_and_its_parent(samples):
    """Where a body vertex has two bones, one is the other's (deforming)
    parent; membranes blend across fingers and are left out."""
    for character in samples:
        parents = deforming_parents(character.skeleton)
        for part in np.flatnonzero(np.array(character.part_types) == "body"):
            if "membrane" in character.part_names[part]:
                continue
            rows = character.weights.matrix[character.parts == part]
            assert np.all((rows > 0).sum(axis=1) <= 2)
            pairs = np.unique(rows[(rows > 0).sum(axis=1) == 2] > 0, axis=0)
            for row in pairs:
                a, b = np.flatnonzero(row)
                assert parents[b] == a or parents[a] == b, (character.part_names[part], character.skeleton.names[a],
                                                            character.skeleton.names[b])


# --- construction rules with known answers -------------------------------------


def test_joint_blend_weights_are_linear_within_the_joint_region():
    joint_arc = np.array([0.0, 1.0, 3.0])
    arc = np.array([0.5, 0.875, 1.0, 1.125, 1.25, 2.0, 3.0])
    weights = joint_blend_weights(arc, joint_arc, 0.25, False, False)
    # Half-width at the joint: 0.25 x the shorter bone (1.0) = 0.25.
    expected_first = np.array([1.0, 0.75, 0.5, 0.25, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(weights[:, 0], expected_first, atol=1e-15)
    np.testing.assert_allclose(weights[:, 1], 1.0 - expected_first, atol=1e-15)


def test_joint_blend_weights_with_parent_and_child():
    joint_arc = np.array([0.0, 2.0])
    weights = joint_blend_weights(np.array([0.0, 0.25, 1.0, 2.0]), joint_arc, 0.25, True, True)
    # Columns: parent, bone, child; half-width 0.25 x 2.0 = 0.5 at each end.
    np.testing.assert_allclose(weights, [[0.5, 0.5, 0.0], [0.25, 0.75, 0.0], [0.0, 1.0, 0.0], [0.0, 0.5, 0.5]],
                               atol=1e-15)


def test_closest_point_weights_interpolate_the_body():
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    triangles = np.array([[0, 1, 2], [0, 2, 3]])
    weights = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 1.0]])  # first bone at y = 0, second at y = 1
    points = np.array([[0.3, 0.25, 0.4], [0.8, 0.75, -0.2], [0.5, 2.0, 0.1]])
    result = closest_point_weights(points, vertices, triangles, weights)
    # Weights here vary linearly with y; the last point is closest to the edge y = 1.
    np.testing.assert_allclose(result, [[0.75, 0.25], [0.25, 0.75], [0.0, 1.0]], atol=1e-12)


def test_box_has_the_exact_volume_and_corners():
    vertices, triangles = box_geometry(np.array([1.0, 2.0, 3.0]), np.array([0.5, 0.25, 2.0]), np.eye(3))
    assert signed_volume(vertices, triangles) == pytest.approx(8 * 0.5 * 0.25 * 2.0, rel=1e-12)
    corners = vertices[np.abs(vertices[:, 0] - 1.0) > 1e-9]
    np.testing.assert_allclose(np.abs(corners - [1.0, 2.0, 3.0]), np.tile([0.5, 0.25, 2.0], (len(corners), 1)),
                               atol=1e-12)


def test_ellipsoid_vertices_lie_on_the_ellipsoid():
    radii = np.array([0.3, 0.5, 0.9])
    frame = axis_frame(np.array([0.0, 1.0, 1.0]), np.array([1.0, 0.0, 0.0]))
    centre = np.array([0.1, -0.2, 0.3])
    vertices, triangles = ellipsoid_geometry(centre, radii, frame, 0.05)
    local = (vertices - centre) @ frame
    np.testing.assert_allclose(((local / radii) ** 2).sum(axis=1), 1.0, atol=1e-12)
    volume = signed_volume(vertices, triangles)
    assert 0.9 * (4 / 3) * np.pi * radii.prod() < volume < (4 / 3) * np.pi * radii.prod()


def test_straight_tube_rings_have_the_requested_radius():
    builder = CharacterBuilder(np.random.default_rng(0))
    builder.rig.add("a", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    builder.rig.add("b", [0.0, 0.0, 1.0], [0.0, 0.0, 2.0], "a")
    builder.spacing = 0.1
    part = builder.tube("limb", ["a", "b"], [(0.2, 0.2), (0.2, 0.2), (0.2, 0.2)], up=np.array([0.0, 1.0, 0.0]))
    vertices = part.vertices
    on_sides = (vertices[:, 2] >= 0.0) & (vertices[:, 2] <= 2.0)
    np.testing.assert_allclose(np.linalg.norm(vertices[on_sides, :2], axis=1), 0.2, atol=1e-12)
    columns = {name: k for k, name in enumerate(part.bone_names)}
    middle_of_a = np.abs(vertices[:, 2] - 0.5) < 1e-9
    middle_of_b = np.abs(vertices[:, 2] - 1.5) < 1e-9
    assert np.all(part.weights[middle_of_a, columns["a"]] == 1.0)
    assert np.all(part.weights[middle_of_b, columns["b"]] == 1.0)
    at_joint = np.abs(vertices[:, 2] - 1.0) < 1e-9
    np.testing.assert_allclose(part.weights[at_joint][:, [columns["a"], columns["b"]]], 0.5, atol=1e-12)


def test_bent_chain_splits_into_two_shells():
    builder = CharacterBuilder(np.random.default_rng(0))
    builder.rig.add("thigh", [0.0, 0.0, 1.0], [0.0, 0.0, 0.5])
    builder.rig.add("foot", [0.0, 0.0, 0.5], [0.0, -0.5, 0.5], "thigh")
    builder.spacing = 0.05
    part = builder.tube("leg", ["thigh", "foot"], [(0.05, 0.05)] * 3, up=np.array([1.0, 0.0, 0.0]))
    directed = np.concatenate([part.triangles[:, [0, 1]], part.triangles[:, [1, 2]], part.triangles[:, [2, 0]]])
    adjacency = {}
    for a, b in directed:
        adjacency.setdefault(a, set()).add(b)
    # Count connected shells by flood fill.
    unseen, shells = set(range(len(part.vertices))), 0
    while unseen:
        stack = [unseen.pop()]
        shells += 1
        while stack:
            for neighbour in adjacency.get(stack.pop(), ()):
                if neighbour in unseen:
                    unseen.remove(neighbour)
                    stack.append(neighbour)
    assert shells == 2


def test_stacked_weight_blocks_take_the_union_of_bone_names():
    names, weights = stack_weight_blocks([(("a", "b"), np.array([[0.25, 0.75]])),
                                          (("c", "a", "a"), np.array([[0.5, 0.25, 0.25], [1.0, 0.0, 0.0]]))])
    # Names in first-seen order; a name repeated within a block adds up.
    assert names == ("a", "b", "c")
    np.testing.assert_array_equal(weights, [[0.25, 0.75, 0.0], [0.5, 0.0, 0.5], [0.0, 0.0, 1.0]])


def test_summed_weight_blocks_add_up_by_bone_name():
    names, weights = sum_weight_blocks([(("a", "b"), np.array([[0.5, 0.25], [0.0, 0.5]])),
                                        (("c", "a"), np.array([[0.125, 0.125], [0.5, 0.0]]))])
    assert names == ("a", "b", "c")
    np.testing.assert_array_equal(weights, [[0.625, 0.25, 0.125], [0.0, 0.5, 0.5]])


def test_polyline_points_by_arc_length():
    polyline = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 2.0, 0.0]])  # 3 long, a corner at 1
    np.testing.assert_array_equal(cumulative_lengths(polyline), [0.0, 1.0, 3.0])
    np.testing.assert_allclose(resample_polyline(polyline, 4), [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 2, 0]], atol=1e-15)
    np.testing.assert_allclose(points_at_fractions(polyline, np.array([0.5, 1.0])), [[1.0, 0.5, 0.0], [1.0, 2.0, 0.0]],
                               atol=1e-15)


def test_tapered_and_round_radii():
    np.testing.assert_allclose(tapered_radii(2, (1.0, 0.5), 0.2), [[0.2, 0.2], [0.15, 0.15], [0.1, 0.1]], atol=1e-15)
    np.testing.assert_array_equal(round_radii([1.0, 0.5], 2.0), [[2.0, 2.0], [1.0, 1.0]])


def test_grown_tail_shrinks_and_curls():
    assert list(shrinking_lengths(3, 7.0, 0.5)) == [4.0, 2.0, 1.0]
    turned = curling_directions(np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 2.0]), np.pi / 2, 3)
    np.testing.assert_allclose(turned, [[1, 0, 0], [0, 1, 0], [-1, 0, 0]], atol=1e-15)
    rig = RigBuilder()
    rig.add("spine", [0.0, 0.0, 1.0], [0.0, -1.0, 1.0])
    tail = rig.grow_tail("tail", "spine", [0.0, 0.0, 1.0], np.array([0.0, 1.0, 0.0]), 2.0, 4, 0.0)
    # Straight (no bend): connected bones along +y, each 0.88 x the one before, 2.0 in all.
    assert tail == ["tail", "tail.001", "tail.002", "tail.003"]
    lengths = [rig.length(b) for b in tail]
    assert sum(lengths) == pytest.approx(2.0, rel=1e-12)
    np.testing.assert_allclose(np.array(lengths[1:]) / lengths[:-1], TAIL_SHRINK, rtol=1e-12)
    np.testing.assert_allclose(rig.tail("tail.003"), [0.0, 2.0, 1.0], atol=1e-12)


def test_symmetrize_mirrors_left_bones_with_mirrored_parents():
    rig = RigBuilder()
    rig.add("spine", [0.0, 0.0, 1.0], [0.0, 0.0, 1.5])
    rig.add_path(["arm.L", "hand.L"], np.array([[0.2, 0.0, 1.4], [0.5, 0.1, 1.3], [0.7, 0.1, 1.2]]), "spine")
    rig.symmetrize()
    assert rig.names == ["spine", "arm.L", "hand.L", "arm.R", "hand.R"]
    assert rig.parents == [None, "spine", "arm.L", "spine", "arm.R"]
    np.testing.assert_array_equal(rig.head("hand.R"), [-0.5, 0.1, 1.3])
    np.testing.assert_array_equal(rig.tail("hand.R"), [-0.7, 0.1, 1.2])


def test_every_kind_has_a_builder():
    assert tuple(BUILDERS) == KINDS


# --- clothing and driven parts --------------------------------------------------


def find_character(predicate, kind="biped", seeds=range(200)):
    for seed in seeds:
        character = generate_character(seed, kind)
        if predicate(character):
            return character
    raise AssertionError("no seed produced the wanted character")


def test_cloth_takes_body_weights_at_the_closest_body_point():
    character = find_character(lambda c: "skirt" in c.part_names
                               and c.part_types[c.part_names.index("skirt")] == PART_CLOTH)
    skirt = character.parts == character.part_names.index("skirt")
    trunk = np.isin(character.parts, [character.part_names.index(n) for n in ("torso", "leg.L", "leg.R")])
    triangles = character.mesh.triangles[trunk[character.mesh.triangles[:, 0]]]
    vertices, weights = character.mesh.vertices, character.weights.matrix
    points = vertices[skirt][::7]
    # Brute force over every trunk triangle.
    count = len(triangles)
    best = []
    for point in points:
        closest, bary = closest_points_on_triangles(np.tile(point, (count, 1)), vertices[triangles[:, 0]],
                                                    vertices[triangles[:, 1]], vertices[triangles[:, 2]])
        distance = np.linalg.norm(closest - point, axis=1)
        # Ties (the midline between the legs) average the distinct closest points.
        tied = np.flatnonzero(distance <= distance.min() + 1e-9)
        _, distinct = np.unique(np.round(closest[tied], 9), axis=0, return_index=True)
        best.append(np.mean([bary[k] @ weights[triangles[k]] for k in tied[distinct]], axis=0))
    np.testing.assert_allclose(weights[skirt][::7], np.array(best), atol=1e-9)


def test_driven_skirt_follows_its_own_bones_outside_the_body():
    character = find_character(lambda c: "skirt" in c.part_names
                               and c.part_types[c.part_names.index("skirt")] == PART_DRIVEN)
    skirt = character.parts == character.part_names.index("skirt")
    names = character.skeleton.names
    skirt_bones = [k for k, n in enumerate(names) if n.startswith("skirt_")]
    hips = names.index("spine")
    used = np.flatnonzero(character.weights.matrix[skirt].max(axis=0) > 0)
    assert set(used) <= set(skirt_bones) | {hips}
    assert len(skirt_bones) in (8, 12, 16)
    # The skirt bones lie on the skirt (within an edge of its vertices) and
    # outside the trunk: farther from the body axis than the trunk surface
    # in the same direction at the same height.
    trunk = np.isin(character.parts, [character.part_names.index(n) for n in ("torso", "leg.L", "leg.R")])
    axis_y = character.skeleton.joints[hips, 1]
    corners = character.mesh.vertices[part_triangles(character, character.part_names.index("skirt"))]
    longest_edge = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max()
    trunk_vertices = character.mesh.vertices[trunk]
    trunk_angle = np.arctan2(trunk_vertices[:, 0], trunk_vertices[:, 1] - axis_y)
    trunk_radius = np.hypot(trunk_vertices[:, 0], trunk_vertices[:, 1] - axis_y)
    compared = 0
    for bone in skirt_bones:
        head = character.skeleton.joints[bone]
        angle = np.arctan2(head[0], head[1] - axis_y)
        same_direction = np.abs(np.angle(np.exp(1j * (trunk_angle - angle)))) < np.radians(20)
        same_height = np.abs(trunk_vertices[:, 2] - head[2]) < longest_edge
        if (same_direction & same_height).any():  # between the legs there is no trunk to compare with
            assert np.hypot(head[0], head[1] - axis_y) > trunk_radius[same_direction & same_height].max()
            compared += 1
        assert np.linalg.norm(character.mesh.vertices[skirt] - head, axis=1).min() <= longest_edge
    assert compared >= len(skirt_bones) // 2


def test_sword_rides_a_floating_weapon_bone():
    character = find_character(lambda c: "weapon" in c.skeleton.names)
    names = character.skeleton.names
    weapon = names.index("weapon")
    assert names[character.skeleton.parents[weapon]] == "hand.R"
    sword = np.isin(character.parts, [k for k, n in enumerate(character.part_names) if n.startswith("sword")])
    assert np.all(character.weights.matrix[sword, weapon] == 1.0)
    assert np.all(character.weights.matrix[~sword, weapon] == 0.0)


def test_eye_bones_sit_inside_their_eyes():
    character = generate_character(2, "fish")
    names = character.skeleton.names
    for side in ("L", "R"):
        eye = character.parts == character.part_names.index(f"eye.{side}")
        centre = character.mesh.vertices[eye].mean(axis=0)
        np.testing.assert_allclose(character.skeleton.joints[names.index(f"eye.{side}")], centre, atol=1e-9)


def test_characters_stand_on_the_floor():
    for kind in ("biped", "quadruped", "tailed", "multileg"):
        character = generate_character(5, kind)
        assert character.skeleton.joints[:, 2].min() >= -1e-9
        assert abs(min(character.skeleton.joints[:, 2].min(), character.skeleton.tails[:, 2].min())) < 1e-9
