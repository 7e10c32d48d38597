"""The learning-free rig baseline (autorig_addon.core.rigging.nearest_character)
and its registration as ``eval rig --method nearest_character``."""

import re
from dataclasses import replace

import numpy as np
import pytest

from autorig_addon.cli import evaluation_methods
from autorig_addon.core.dataset import cache
from autorig_addon.core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split
from autorig_addon.core.errors import InputError
from autorig_addon.core.rigging.nearest_character import box_map, nearest_character, surface_points
from autorig_addon.core.types import Mesh
from geometry_fixtures import procedural_sample

NO_POOL = ("No training character with deform bones to choose a skeleton from (the pool is empty once the "
           "validation characters are left out).")


@pytest.fixture(scope="module")
def pool():
    """Four procedural characters of different kinds, normalised as cached
    samples: a fish (seed 0), a winged creature (1), a long chain (5) and a
    quadruped (11)."""
    return [procedural_sample(seed) for seed in (0, 1, 5, 11)]


def world_copy(sample, scale, offset):
    """The sample's normalised surface moved into a world space: ``p * scale + offset``
    (``scale`` a number or per-axis factors)."""
    return Mesh(sample.vertices * scale + offset, sample.triangles)


def test_a_scaled_and_moved_copy_picks_its_character_and_its_skeleton(pool):
    quadruped = pool[3]
    offset = np.array([3.0, -1.5, 0.25])
    chosen = nearest_character(world_copy(quadruped, 2.5, offset), pool)
    assert chosen.name == "procedural_11"
    assert chosen.distance < 1e-12  # the same surface, drawn with the same seed
    bones = quadruped.skeleton.deform_subset()
    size = 2.5  # the copy's largest side: the sample's is 1
    np.testing.assert_allclose(chosen.skeleton.joints, bones.joints * 2.5 + offset, rtol=0, atol=1e-6 * size)
    np.testing.assert_allclose(chosen.skeleton.tails, bones.tails * 2.5 + offset, rtol=0, atol=1e-6 * size)
    assert chosen.skeleton.names == bones.names
    np.testing.assert_array_equal(chosen.skeleton.parents, bones.parents)
    assert chosen.skeleton.deform.all()
    assert chosen.note == "nearest training character: procedural_11 (surface Chamfer distance 0.0000)"


def test_only_deform_bones_are_kept(pool):
    fish = pool[0]  # 31 bones, 30 deform
    chosen = nearest_character(world_copy(fish, 1.0, 0.0), pool)
    assert (chosen.name, chosen.skeleton.bone_count) == ("procedural_0", 30)
    assert chosen.skeleton.names == fish.deform_names


def test_a_stretched_copy_gets_joints_stretched_by_the_same_factors(pool):
    winged = pool[1]
    factors, offset = np.array([1.15, 0.9, 1.05]) * 1.8, np.array([-0.4, 0.2, 1.0])
    chosen = nearest_character(world_copy(winged, factors, offset), pool)
    assert chosen.name == "procedural_1"
    bones = winged.skeleton.deform_subset()
    np.testing.assert_allclose(chosen.skeleton.joints, bones.joints * factors + offset, rtol=0,
                               atol=1e-6 * factors.max())
    np.testing.assert_allclose(chosen.skeleton.tails, bones.tails * factors + offset, rtol=0, atol=1e-6 * factors.max())


def test_excluded_names_are_never_picked(pool):
    target = world_copy(pool[2], 0.5, 0.0)
    assert nearest_character(target, pool).name == "procedural_5"
    chosen = nearest_character(target, pool, exclude={"procedural_5"})
    assert chosen.name != "procedural_5" and chosen.distance > 0.0
    with pytest.raises(InputError, match=rf"^{re.escape(NO_POOL)}$"):
        nearest_character(target, pool, exclude=[sample.name for sample in pool])
    with pytest.raises(InputError, match=rf"^{re.escape(NO_POOL)}$"):
        nearest_character(target, [])


def test_a_mesh_without_surface_is_refused(pool):
    points_only = Mesh(pool[0].vertices, np.zeros((0, 3), dtype=np.int64))
    with pytest.raises(InputError, match="^The mesh has no faces with an area, so there is no surface to compare"):
        nearest_character(points_only, pool)


def test_surface_points_are_drawn_by_area():
    # Two triangles side by side, areas 1/2 (x in [0, 1]) and 3/2 (x in [1, 4]).
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [4.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    triangles = np.array([[0, 1, 2], [1, 3, 4]])
    points = surface_points(vertices, triangles, count=20_000, seed=3)
    assert points.shape == (20_000, 3) and np.all(points[:, 2] == 0.0)
    in_first = points[:, 0] + points[:, 1] <= 1.0 + 1e-12
    assert in_first.mean() == pytest.approx(0.25, abs=0.01)  # 1/2 of the total area 2
    # Uniform inside a triangle: the mean is its centroid.
    np.testing.assert_allclose(points[in_first].mean(axis=0), [1 / 3, 1 / 3, 0.0], atol=0.01)
    np.testing.assert_array_equal(points, surface_points(vertices, triangles, count=20_000, seed=3))


def test_box_map_by_hand():
    source = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]])  # flat in z
    target = np.array([[1.0, 0.0, -1.0], [3.0, 1.0, 0.0]])
    mapped = box_map([[0.5, 0.5, 0.0], [1.0, 0.0, 0.2]], source, target)
    # x: [0, 1] -> [1, 3]; y unchanged; z only shifted from centre 0 to centre -0.5.
    np.testing.assert_allclose(mapped, [[2.0, 0.5, -0.5], [3.0, 0.0, -0.3]])


@pytest.fixture
def fresh_pool_cache():
    evaluation_methods._nearest_character_pool.cache_clear()
    yield
    evaluation_methods._nearest_character_pool.cache_clear()


def test_registered_method_leaves_validation_characters_out(pool, monkeypatch, fresh_pool_cache):
    # A cache that (wrongly) returns a validation character beside training ones: it is never chosen.
    validation_name = read_data_split(DEFAULT_SPLIT_FILE).validation[0].rsplit(".", 1)[0]
    leaked = replace(pool[3], name=validation_name)
    monkeypatch.setattr(cache, "training_samples", lambda *args, **kwargs: [leaked, pool[0], pool[2]])
    predict = evaluation_methods.RIG_METHODS["nearest_character"].predict
    prediction = predict(world_copy(pool[3], 1.0, 0.0))
    assert isinstance(prediction, evaluation_methods.RigPrediction)
    assert prediction.notes[0].startswith("nearest training character: procedural_")
    assert validation_name not in prediction.notes[0]
    pool_samples, validation = evaluation_methods._nearest_character_pool()
    assert [sample.name for sample in pool_samples] == ["procedural_0", "procedural_5"]
    assert validation_name in validation
