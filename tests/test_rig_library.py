"""The rig library (core/rigging/rig_library.py): a character read as a biped
or a quadruped takes the key joints of the nearest known rig of its kind
when that rig's surface lies near enough, mapped onto it (tests/test_surface_fit.py); a
body the landmark network reads as neither is a biped when its nearest known
body is one, near enough."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.rigging import predict, rig_library
from autorig_addon.core.rigging.nearest_character import SURFACE_POINTS, surface_points
from autorig_addon.core.rigging.networks.landmarks import sample_landmarks
from autorig_addon.core.rigging.rig_library import (
    LIBRARY_POINTS,
    SCREEN_POINTS,
    STORED_STEPS,
    RigLibrary,
    as_stored,
    build_rig_library,
    closest_rig,
    library_points,
    nearest_known_body,
    twin_mirror_error,
)
from autorig_addon.core.skeleton.key_joints import KEY_JOINTS, key_joints
from autorig_addon.core.types import Mesh, Skeleton
from geometry_fixtures import procedural_of_kind


@pytest.fixture(scope="module")
def biped():
    return procedural_of_kind("biped")


@pytest.fixture(scope="module")
def library(biped):
    """A biped, a quadruped and a fish: the fish only tells a kind (other), with no key joints."""
    return build_rig_library([biped[0], procedural_of_kind("quadruped")[0], procedural_of_kind("fish")[0]])


def normalised_copy(sample: CharacterSample, factors) -> Mesh:
    return Mesh(sample.vertices * np.asarray(factors, dtype=np.float64), sample.triangles)


def test_the_library_holds_every_character_and_the_key_joints_of_bipeds_and_quadrupeds(library, biped):
    assert library.names.tolist() == ["procedural/biped_0", "procedural/fish_0", "procedural/quadruped_0"]
    assert library.kinds.tolist() == ["biped", "other", "quadruped"]
    assert library.points.shape == (3, LIBRARY_POINTS, 3)
    # Every key joint of the biped; the quadruped's generator names no neck and no head joint it plays; the fish none.
    assert library.known.sum(axis=1).tolist() == [15, 0, 13]
    targets, _, _ = sample_landmarks(biped[0])
    np.testing.assert_allclose(library.key_joints[0], targets, atol=1e-6)


def test_the_library_keeps_points_spread_over_the_surface_and_stores_them_to_a_step():
    # A unit square (two triangles): 1,000 points on a grid would be 0.032 apart and leave no spot farther than 0.022
    # from one of them. The kept ones come close to that; a random half of the 2,000 drawn leaves gaps three times as
    # wide.
    square = (np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64),
              np.array([[0, 1, 2], [0, 2, 3]]))
    kept = library_points(*square)
    assert kept.shape == (LIBRARY_POINTS, 3) and np.all(kept[:, 2] == 0.0)
    drawn = surface_points(*square, SURFACE_POINTS)
    gap = cKDTree(kept).query(drawn)[0].max()
    random_gap = cKDTree(drawn[:LIBRARY_POINTS]).query(drawn)[0].max()
    assert gap < 0.025 and random_gap > 0.045  # measured: 0.018 and 0.053
    # Kept in random order: the first quarter covers the square as a uniform sample does, not one corner.
    first_quarter_centre = kept[: LIBRARY_POINTS // 4, :2].mean(axis=0)
    assert np.all(np.abs(first_quarter_centre - 0.5) < 0.1)
    # Stored in steps of 1/255 of each side of the box: a point moves half a step at most.
    box = np.array([[0.0, 0.0, -0.5], [2.0, 1.0, 0.5]])
    points = np.random.default_rng(3).uniform(box[0], box[1], size=(500, 3))
    error = np.abs(as_stored(points, box) - points)
    assert np.all(error <= 0.5 * (box[1] - box[0]) / STORED_STEPS + 1e-6)
    assert error[:, 0].max() > 0.4 * 2.0 / STORED_STEPS  # really rounded, not kept exact


def test_a_rig_whose_twin_joints_are_no_mirror_images_is_left_out(biped):
    sample = biped[0]
    wrist = key_joints(sample.names, sample.joints).bones["wrist.L"]
    joints = sample.joints.copy()
    joints[wrist, 2] += 0.08  # the left hand raised: a pose, or a rig off its body
    posed = replace(sample, joints=joints)
    targets, known, _ = sample_landmarks(posed)
    assert twin_mirror_error(targets, known > 0) == pytest.approx(0.08, abs=1e-6)
    # Its surface still tells a biped; its key joints are not copied.
    posed_library = build_rig_library([posed])
    assert posed_library.kinds.tolist() == ["biped"] and not posed_library.known.any()
    assert closest_rig(normalised_copy(sample, [1.0, 1.0, 1.0]), "biped", posed_library, limit=np.inf) is None


def test_twin_mirror_error_by_hand():
    joints = np.zeros((len(KEY_JOINTS), 3))
    known = np.zeros(len(KEY_JOINTS), dtype=bool)
    left, right = KEY_JOINTS.index("knee.L"), KEY_JOINTS.index("knee.R")
    joints[left], joints[right] = [0.1, 0.0, 0.3], [-0.1, 0.03, 0.34]
    assert twin_mirror_error(joints, known) == 0.0  # no pair known
    known[[left, right]] = True
    assert twin_mirror_error(joints, known) == pytest.approx(0.05)


def test_a_stretched_relative_takes_the_key_joints_stretched_by_the_same_factors(library, biped, tmp_path):
    factors = np.array([1.0, 1.1, 0.95])
    match = closest_rig(normalised_copy(biped[0], factors), "biped", library)
    assert match.name == "procedural/biped_0"
    assert 0.005 < match.distance < 0.02  # measured 0.0148: near, but not the same surface
    targets, _, _ = sample_landmarks(biped[0])
    assert set(match.points) == set(KEY_JOINTS)
    for index, name in enumerate(KEY_JOINTS):
        np.testing.assert_allclose(match.points[name], targets[index] * factors, atol=1e-5)
    # Saved (points in steps of 1/255 of the box's sides) and read back, the same entry and key joints.
    library.save(tmp_path / "library.npz")
    again = closest_rig(normalised_copy(biped[0], factors), "biped", RigLibrary.load(tmp_path / "library.npz"))
    assert again.name == match.name and abs(again.distance - match.distance) < 1e-3
    np.testing.assert_allclose(again.points["knee.L"], match.points["knee.L"], atol=1e-6)


def test_only_a_rig_of_the_kind_read_and_near_enough_is_copied(library, biped):
    copy = normalised_copy(biped[0], [1.0, 1.1, 0.95])
    distance = closest_rig(copy, "biped", library).distance
    assert closest_rig(copy, "biped", library, limit=0.5 * distance) is None
    assert closest_rig(copy, "biped", library, limit=2.0 * distance).name == "procedural/biped_0"
    # Whatever the distance, only an entry of the kind asked for.
    only_quadruped = library.subset(library.kinds == "quadruped")
    assert closest_rig(copy, "biped", only_quadruped, limit=np.inf) is None
    assert closest_rig(copy, "quadruped", library, limit=np.inf).name == "procedural/quadruped_0"
    # A generic body of another shape is no relative at the shipped limit.
    other_biped = procedural_of_kind("biped", seed=3)[0]
    assert closest_rig(Mesh(other_biped.vertices, other_biped.triangles), "biped", library) is None


def test_a_rig_without_a_neck_gives_the_key_joints_it_has_and_says_so(library, biped):
    known = library.known.copy()
    known[0, KEY_JOINTS.index("neck")] = False  # as KayKit's rigs: no neck bone
    neckless = replace(library, known=known)
    match = closest_rig(normalised_copy(biped[0], [1.0, 1.0, 1.0]), "biped", neckless)
    assert "neck" not in match.points and len(match.points) == 14
    assert match.note.endswith("the landmark network's kept for the 1 it lacks.")


def key_joint_errors(skeleton, reference, size):
    found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
    truth = key_joints(reference.names, reference.joints, left_direction=[1.0, 0.0, 0.0],
                       parents=reference.parents).positions
    return {role: float(np.linalg.norm(found[role] - truth[role])) / size for role in truth}


def test_a_character_whose_relative_is_known_gets_its_artist_key_joints(library, biped, monkeypatch):
    character = biped[1]
    size = float(np.ptp(character.mesh.vertices, axis=0).max())
    monkeypatch.setattr(rig_library, "shipped_library", lambda: None)
    alone = predict.predict_votes(character.mesh)
    assert alone.landmarks.closest_rig is None
    network_errors = key_joint_errors(predict.skeleton_from_votes(alone, template="biped"), character.skeleton, size)
    assert max(network_errors.values()) > 0.05  # measured: the head 0.062, the neck 0.059 off
    monkeypatch.setattr(rig_library, "shipped_library", lambda: library)
    votes = predict.predict_votes(character.mesh)
    assert votes.landmarks.closest_rig.name == "procedural/biped_0"
    # Its own surface, 0.002 away: the library keeps 1,000 of the 2,000 points the body is sampled at. (Auto gives
    # the known rig itself: the standard skeleton, asked for, takes its key joints.)
    assert ("Key joints copied from the closest known rig, procedural/biped_0 (surfaces 0.002 of the largest side "
            "apart).") in predict.template_notes(votes, "biped")
    copied_errors = key_joint_errors(predict.skeleton_from_votes(votes, template="biped"), character.skeleton, size)
    assert max(copied_errors.values()) < 1e-6
    # A quadruped forced on this biped is built on the network's key joints, not on the biped's rig.
    forced, network_only = (predict.skeleton_from_votes(read, template="quadruped") for read in (votes, alone))
    np.testing.assert_allclose(forced.joints, network_only.joints, atol=1e-9)
    assert not any(note.startswith("Key joints copied") for note in predict.template_notes(votes, "quadruped"))


def test_the_nearest_known_body_of_any_kind_tells_its_kind(library, biped):
    relative = nearest_known_body(normalised_copy(biped[0], [1.0, 1.0, 1.0]), library)
    assert (relative.name, relative.kind, relative.distance) == ("procedural/biped_0", "biped",
                                                                      pytest.approx(0.0022, abs=3e-4))
    fish = procedural_of_kind("fish")[0]
    assert nearest_known_body(normalised_copy(fish, [1.0, 1.0, 1.0]), library).kind == "other"
    # Stretched 30 % across: 0.016 away, a relative within the limit but not within half that distance.
    stretched = normalised_copy(biped[0], [1.3, 1.0, 1.0])
    distance = nearest_known_body(stretched, library).distance
    assert 0.01 < distance < rig_library.RELATIVE_KIND_DISTANCE
    assert nearest_known_body(stretched, library, limit=0.5 * distance) is None


def test_a_body_read_as_other_is_a_biped_when_its_nearest_known_body_is(library, biped, read_as_other, monkeypatch):
    character = biped[1]
    size = float(np.ptp(character.mesh.vertices, axis=0).max())
    monkeypatch.setattr(rig_library, "shipped_library", lambda: library)
    votes = predict.predict_votes(character.mesh)
    assert votes.landmarks.kind == "other" and votes.landmarks.relative.name == "procedural/biped_0"
    # Without its known rig (which Auto would give it, test below), a standard biped.
    kind, note = predict.chosen_template(votes, known_rig=False)
    assert kind == "biped"
    assert note == ("Template: standard biped skeleton; the landmark network reads the body as other (90% sure), not "
                    "surely a biped or quadruped; the closest known body, procedural/biped_0 (0.002 of the largest "
                    "side away), is a biped.")
    # Its key joints are its relative's, as for a body the network reads as a biped.
    assert any(note.startswith("Key joints copied from the closest known rig, procedural/biped_0")
               for note in predict.template_notes(votes, known_rig=False))
    skeleton = predict.skeleton_from_votes(votes, fingers=False, known_rig=False)
    assert len(skeleton.names) == 22
    assert max(key_joint_errors(skeleton, character.skeleton, size).values()) < 1e-6
    # With only a quadruped and a fish known, nothing tells its kind: the free-form skeleton.
    monkeypatch.setattr(rig_library, "shipped_library", lambda: library.subset(library.kinds != "biped"))
    votes = predict.predict_votes(character.mesh)
    assert votes.landmarks.relative is None
    assert predict.chosen_template(votes)[0] == "free-form"


def test_a_quadruped_nearest_gives_no_kind(library, read_as_other, monkeypatch):
    # The quadruped itself is known, 0 away: bipeds alone are given by their nearest known body.
    monkeypatch.setattr(rig_library, "shipped_library", lambda: library)
    sample, quadruped = procedural_of_kind("quadruped")
    assert nearest_known_body(normalised_copy(sample, [1.0, 1.0, 1.0]), library).kind == "quadruped"
    votes = predict.predict_votes(quadruped.mesh)
    assert votes.landmarks.relative is None
    assert predict.chosen_template(votes, known_rig=False)[0] == "free-form"
    # Its known rig, though, lies near: Auto gives that rig, whatever the kind.
    assert predict.chosen_template(votes)[0] == "known rig" and votes.known_rig.name == "procedural/quadruped_0"


def test_a_biped_by_its_nearest_known_body_facing_plus_y_is_turned_by_its_toes(library, biped, read_as_other,
                                                                             monkeypatch):
    monkeypatch.setattr(rig_library, "shipped_library", lambda: library)
    character = biped[1]
    # Given facing +Y: its own left lies at -X.
    turned = Mesh(character.mesh.vertices * np.array([-1.0, -1.0, 1.0]), character.mesh.triangles)
    votes = predict.predict_votes(turned)
    assert "The character faces away from -Y (its toes point toward +Y); it was turned half a turn for the " \
           "prediction, so its .L bones lie on its own left." in votes.notes
    assert not any(note.startswith("Which way the character faces could not be told") for note in votes.notes)
    # The standard biped and the known rig alike have their .L bones on its own left.
    for allowed in (False, True):
        skeleton = predict.skeleton_from_votes(votes, fingers=False, known_rig=allowed)
        found = key_joints(skeleton.names, skeleton.joints, parents=skeleton.parents).positions
        assert found["shoulder.L"][0] < 0.0 < found["shoulder.R"][0]


def test_a_body_near_a_known_body_gets_that_rig_fitted_by_default(library, biped, monkeypatch):
    character = biped[1]
    artist = character.skeleton
    size = float(np.ptp(character.mesh.vertices, axis=0).max())
    monkeypatch.setattr(rig_library, "shipped_library", lambda: library)
    votes = predict.predict_votes(character.mesh)
    kind, note = predict.chosen_template(votes)
    assert kind == "known rig"
    assert note.startswith("Template: the rig of the closest known character, procedural/biped_0 (surfaces 0.002 of "
                           "the largest side apart), fitted to this body: its artist's 26 bones and names; the "
                           "landmark network reads the body as biped")
    skeleton = predict.skeleton_from_votes(votes)
    # Its own rig: its artist's 26 deform bones (not the root and heels, which deform nothing and join nothing), with
    # their names and parents, each joint where the artist put it (the library keeps half precision: 0.0005 of the
    # largest side).
    artist = artist.deform_subset()
    assert sorted(skeleton.names) == sorted(artist.names) and len(skeleton.names) == 26 and skeleton.deform.all()
    order = [artist.names.index(name) for name in skeleton.names]
    np.testing.assert_allclose(skeleton.joints, artist.joints[order], atol=1e-3 * size)
    assert [skeleton.names[parent] if parent >= 0 else None for parent in skeleton.parents] == [
        artist.names[artist.parents[index]] if artist.parents[index] >= 0 else None for index in order]
    # A standard skeleton when asked for, when the known rig is not allowed (Rigify), or with engine names.
    for keywords in ({"template": "biped"}, {"known_rig": False}, {"names": "mixamo"}):
        standard = predict.skeleton_from_votes(votes, fingers=False, **keywords)
        assert len(standard.names) == 22 and standard.deform.all(), keywords
    assert "mixamorig:Hips" in predict.skeleton_from_votes(votes, names="mixamo").names
    # A body farther from every known one than the limit gets no known rig.
    stretched = Mesh(character.mesh.vertices * np.array([1.8, 1.0, 1.0]), character.mesh.triangles)
    far = predict.predict_votes(stretched)
    assert far.known_rig is None and predict.chosen_template(far)[0] == "biped"


def test_a_rig_that_is_several_trees_is_joined_into_one():
    # Two deform chains hanging from a root that deforms nothing: the root joins them and stays non-deforming.
    joints = np.array([[0, 0, 0], [0, 0, 1], [0, 0, 2], [1, 0, 1], [1, 0, 2], [0, 0, 3]], dtype=np.float64)
    rooted = Skeleton(joints[:5], np.array([-1, 0, 1, 0, 3]), ("root", "a", "a.001", "b", "b.001"),
                      deform=np.array([False, True, True, True, True]))
    joined = rig_library._one_tree_rig(rooted)
    assert joined.names == ("root", "a", "a.001", "b", "b.001") and joined.deform.tolist() == [False] + [True] * 4
    assert joined.parents.tolist() == [-1, 0, 1, 0, 3]
    # The same, with a weighted head that nothing joins (a tree of its own in the artist's rig): the root still joins
    # the chains, and the head hangs from the nearest joint of that tree, the top of chain a.
    apart = Skeleton(joints, np.array([-1, 0, 1, 0, 3, -1]), ("root", "a", "a.001", "b", "b.001", "head"),
                     deform=np.array([False, True, True, True, True, True]))
    joined = rig_library._one_tree_rig(apart)
    parent_of = dict(zip(joined.names, (joined.names[p] if p >= 0 else None for p in joined.parents)))
    assert parent_of == {"root": None, "a": "root", "a.001": "a", "b": "root", "b.001": "b", "head": "a.001"}
    assert dict(zip(joined.names, joined.deform.tolist()))["root"] is False
    # Nothing deforms: no rig.
    assert rig_library._one_tree_rig(Skeleton(joints[:2], np.array([-1, 0]), ("x", "y"),
                                              deform=np.array([False, False]))) is None


def test_every_entry_keeps_its_own_rig_through_saving_and_subsets(library, tmp_path):
    library.save(tmp_path / "library.npz")
    loaded = RigLibrary.load(tmp_path / "library.npz")
    for built_from in (loaded, loaded.subset(library.kinds != "biped")):
        for entry, name in enumerate(built_from.names):
            original = int(np.flatnonzero(library.names == name)[0])
            rows, kept = built_from.rig_rows(entry), library.rig_rows(original)
            assert built_from.rig_names[rows].tolist() == library.rig_names[kept].tolist()
            assert built_from.rig_parents[rows].tolist() == library.rig_parents[kept].tolist()
            assert built_from.rig_deform[rows].tolist() == library.rig_deform[kept].tolist()
            np.testing.assert_allclose(built_from.rig_joints[rows], library.rig_joints[kept], atol=1e-3)
    # The biped's, the fish's and the quadruped's rigs, one after the other: 26, 30 and 33 bones.
    assert library.rig_counts.tolist() == [26, 30, 33] and len(library.rig_names) == 89


def test_saved_points_keep_the_screening_sample_in_order_and_the_rest_as_a_sorted_set(library, tmp_path):
    """Each entry's first SCREEN_POINTS (the screening's uniform sample) come back in their order; the rest come
    back as the same set, sorted by x, which is what lets the shipped file compress (0.96 to 0.81 MB of points)."""
    library.save(tmp_path / "library.npz")
    loaded = RigLibrary.load(tmp_path / "library.npz")
    for stored, kept, box in zip(loaded.points, library.points, library.boxes):
        expected = as_stored(kept, box)
        np.testing.assert_array_equal(stored[:SCREEN_POINTS], expected[:SCREEN_POINTS])
        rest = stored[SCREEN_POINTS:]
        assert np.all(np.diff(rest[:, 0]) >= 0) and not np.all(np.diff(expected[SCREEN_POINTS:, 0]) >= 0)
        by_position = lambda points: points[np.lexsort(points.T[::-1])]  # noqa: E731
        np.testing.assert_array_equal(by_position(rest), by_position(expected[SCREEN_POINTS:]))


def test_a_known_rig_the_checks_find_poor_gives_way_to_the_skeleton_without_it(biped, monkeypatch):
    sample, character = biped
    joints = sample.joints.copy()
    joints[sample.names.index("hair.002"), 2] += 1.0  # a bone tip a whole body height above the head
    library = build_rig_library([replace(sample, joints=joints)])
    monkeypatch.setattr(rig_library, "shipped_library", lambda: library)
    votes = predict.predict_votes(character.mesh)
    assert predict.chosen_template(votes)[0] == "known rig"
    poor = predict.skeleton_quality(votes, predict.skeleton_from_votes(votes))
    assert poor and any("hair.001" in problem for problem in poor)
    checked = predict.checked_skeleton(votes)
    assert (checked.problems, checked.known_rig) == ((), False)
    assert len(checked.skeleton.names) == 22 and "neck" in checked.skeleton.names  # the standard biped (mitten hands)
    assert checked.notes == (f"The rig of the closest known character, procedural/biped_0, looks poor on this body "
                             f"({'; '.join(poor)}): it was not used.",)
    # Built first as a standard biped, as asked, the poor known rig is turned down too: choosing Auto later (the live
    # panel) cannot bring it back.
    asked = predict.checked_skeleton(votes, template="biped")
    assert (asked.known_rig, asked.notes) == (False, ()) and len(asked.skeleton.names) == 22
    # A sound known rig is kept.
    monkeypatch.setattr(rig_library, "shipped_library", lambda: build_rig_library([sample]))
    sound = predict.checked_skeleton(predict.predict_votes(character.mesh))
    assert sound.known_rig and sound.notes == () and "hair.002" in sound.skeleton.names


def test_the_shipped_library_can_leave_characters_out_for_a_while():
    """shipped_library_without: inside, the shipped library lacks the names (nested: both sets); after, whole."""
    whole = list(rig_library.shipped_library().names)
    first, second = whole[0], whole[-1]
    with rig_library.shipped_library_without({first}):
        assert list(rig_library.shipped_library().names) == whole[1:]
        with rig_library.shipped_library_without({first, second}):
            assert list(rig_library.shipped_library().names) == whole[1:-1]
        assert list(rig_library.shipped_library().names) == whole[1:]
    assert list(rig_library.shipped_library().names) == whole
