"""The skinning networks run inside Blender: the finishing steps of
core/skinning/learned/predict.py and whole runs of each shipped network
(the networks' numpy and torch forwards are compared in
test_network_twins.py)."""

from dataclasses import replace

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.nn.graph import mesh_edges
from autorig_addon.core.nn.spec import forget_shipped_weights
from autorig_addon.core.skinning.learned import predict
from autorig_addon.core.skinning.learned.features import skin_graph
from autorig_addon.core.skinning.learned.networks import NETWORK_NAMES, SKIN_NETWORKS
from autorig_addon.core.types import Mesh, Skeleton
from geometry_fixtures import box_mesh, cylinder, procedural_sample, subdivided, two_bone_skeleton

#: Voxel resolution of the tests' distances (the default 88 is slower and
#: changes nothing these tests check).
RESOLUTION = 32


def test_dense_weights_spread_the_candidates_into_bone_columns():
    chain = skin_graph(Mesh([[1.0, 0, 0.2], [1, 1, 0.9], [1, 0, 0.5]], [[0, 1, 2]]), two_bone_skeleton(),
                       np.array([[0.2, 0.8], [0.9, 0.3], [0.4, 0.4]]), np.full((3, 2), 0.5))
    assert chain.candidates[:, :2].tolist() == [[0, 1], [1, 0], [0, 1]]
    candidate = np.array([[0.7, 0.3, 0, 0, 0], [0.6, 0.4, 0, 0, 0], [0.5, 0.5, 0.9, 0.9, 0.9]])
    # Invalid slots (all candidate 0) are left out even when they hold a value.
    np.testing.assert_allclose(predict.dense_weights(chain, candidate), [[0.7, 0.3], [0.4, 0.6], [0.5, 0.5]])


def test_pruned_weights_limit_prune_and_normalise():
    weights = np.zeros((4, 40))
    weights[0, :5] = [0.5, 0.3, 0.1, 0.06, 0.04]
    weights[1, :5] = [0.4, 0.3, 0.26, 0.02, 0.02]
    weights[2, :2] = [predict.PRUNE_BELOW, 1 - predict.PRUNE_BELOW]
    weights[3] = 0.025  # every weight below PRUNE_BELOW (0.08): the largest (the first) is kept
    finished = predict.pruned_weights(weights, max_influences=4)
    # Row 0: the 5th weight is cut by the limit, then the 4th (0.06 / 0.96) by pruning.
    np.testing.assert_allclose(finished[0, :5], np.array([0.5, 0.3, 0.1, 0, 0]) / 0.9)
    # Row 1: one 0.02 is cut by the limit, the other (0.02 / 0.98) by pruning.
    np.testing.assert_allclose(finished[1, :5], np.array([0.4, 0.3, 0.26, 0, 0]) / 0.96)
    # Row 2: a weight exactly at PRUNE_BELOW goes.
    np.testing.assert_allclose(finished[2, :2], [0, 1])
    # Row 3: the limit keeps 4 of the equal weights (0.25 each, above the threshold).
    assert (finished[3] > 0).sum() == 4
    np.testing.assert_allclose(finished[3][finished[3] > 0], 0.25)
    unlimited = predict.pruned_weights(weights, max_influences=0)
    np.testing.assert_allclose(unlimited[3], np.eye(40)[0])
    for result in (finished, unlimited):
        np.testing.assert_allclose(result.sum(axis=1), 1)
        assert (result[:, :] >= 0).all()


def test_finished_weights_are_the_pruned_ones_sharpened():
    weights = np.zeros((2, 6))
    weights[0, :3] = [0.6, 0.3, 0.1]
    weights[1, :2] = [0.5, 0.5]
    finished = predict.finished_weights(weights, max_influences=4)
    # Nothing is pruned (all above 0.08); 0.6 : 0.3 : 0.1 becomes 0.6 ** 1.25 : 0.3 ** 1.25 : 0.1 ** 1.25.
    assert predict.SHARPEN_POWER == 1.25
    powered = np.array([0.6, 0.3, 0.1]) ** 1.25
    np.testing.assert_allclose(finished[0, :3], powered / powered.sum())
    assert finished[0, 0] > 0.6 and finished[0, 2] < 0.1
    np.testing.assert_allclose(finished[1, :2], [0.5, 0.5])  # an even blend stays even


def test_learned_weights_refuse_bad_input():
    mesh, skeleton = cylinder(radius=0.1, rings=6), two_bone_skeleton()
    with pytest.raises(InputError, match=r"^Unknown skinning network 'bone_heat': use one of rignet, heterskinnet, "
                                         r"skinningnet\.$"):
        predict.learned_weights(mesh, skeleton, "bone_heat")
    no_deform = Skeleton(skeleton.joints, skeleton.parents, skeleton.names, skeleton.tails, [False, False])
    with pytest.raises(InputError, match=r"^The armature has no deform bones; enable Deform on the bones that should "
                                         r"move the mesh\.$"):
        predict.learned_weights(mesh, no_deform, "rignet")
    with pytest.raises(InputError, match=r"^The mesh has no vertices\.$"):
        predict.learned_weights(Mesh(np.zeros((0, 3)), np.zeros((0, 3))), skeleton, "rignet")


def test_a_missing_weights_file_is_refused_before_any_work(monkeypatch, tmp_path):
    spec = SKIN_NETWORKS["skinningnet"]
    monkeypatch.setitem(SKIN_NETWORKS, "skinningnet", replace(spec, weights_file=tmp_path / "skinningnet.npz"))
    forget_shipped_weights()
    with pytest.raises(InputError, match=r"^The trained weights of 'skinningnet' are missing "
                                         r".*reinstall the extension"):
        predict.learned_weights(cylinder(radius=0.1, rings=6), two_bone_skeleton(), "skinningnet")




@pytest.mark.parametrize("name", NETWORK_NAMES)
def test_learned_weights_of_a_procedural_character(name):
    sample = procedural_sample(5)
    weights = predict.learned_weights(sample.mesh, sample.skeleton, name, resolution=RESOLUTION)
    assert weights.bone_names == sample.deform_names
    assert weights.matrix.shape == (sample.mesh.vertex_count, len(sample.deform_names))
    np.testing.assert_allclose(weights.matrix.sum(axis=1), 1, atol=1e-12)
    assert (weights.matrix >= 0).all() and ((weights.matrix > 0).sum(axis=1) <= 4).all()
    # A two-bone skeleton (fewer bones than candidates) is weighted as well
    # (RigNet's network through cut bones, its spec's min_deform_bones).
    two = predict.learned_weights(cylinder(radius=0.1, rings=11), two_bone_skeleton(), name, resolution=RESOLUTION)
    np.testing.assert_allclose(two.matrix.sum(axis=1), 1, atol=1e-12)


def test_split_bones_cuts_each_deform_bone_into_a_chain_of_equal_pieces():
    skeleton = Skeleton(np.array([[0, 0, 0.0], [0, 0, 1.0], [0.5, 0, 1.0]]), np.array([-1, 0, 1]),
                        ("lower", "upper", "prop"), np.array([[0, 0, 1.0], [0, 0, 2.0], [0.6, 0, 1.0]]),
                        np.array([True, True, False]))
    cut, owner = predict.split_bones(skeleton, 2)
    assert cut.names == ("lower#0", "lower#1", "upper#0", "upper#1")
    np.testing.assert_array_equal(cut.parents, [-1, 0, 1, 2])
    np.testing.assert_allclose(cut.joints[:, 2], [0.0, 0.5, 1.0, 1.5])
    np.testing.assert_allclose(cut.tails[:, 2], [0.5, 1.0, 1.5, 2.0])
    np.testing.assert_array_equal(owner, [0, 0, 1, 1])


#: Largest L1 difference between the weights of two vertices joined by a
#: mesh edge on the 12,162-vertex proxy case below, and its 99th
#: percentile. Measured with the trained networks: rignet 0.90 / 0.30,
#: heterskinnet 0.84 / 0.28, skinningnet 0.46 / 0.23 (the largest jumps sit
#: where the influence limit or pruning drops a bone); copying each
#: vertex's nearest proxy vertex instead gives 1.08 / 0.80.
SMOOTH_CARRY_MAX_JUMP = 1.0
SMOOTH_CARRY_P99_JUMP = 0.4


def test_learned_weights_of_a_big_mesh_run_on_a_proxy_and_come_back_smoothly():
    sample = procedural_sample(5)
    big = subdivided(sample.mesh, 2)
    assert big.vertex_count > 4 * predict.NETWORK_PROXY_VERTICES
    weights = predict.learned_weights(big, sample.skeleton, "heterskinnet", resolution=RESOLUTION).matrix
    assert weights.shape == (big.vertex_count, len(sample.deform_names))
    np.testing.assert_allclose(weights.sum(axis=1), 1, atol=1e-12)
    assert ((weights > 0).sum(axis=1) <= 4).all()
    edges = mesh_edges(big.triangles, big.vertex_count)
    jumps = np.abs(weights[edges[0]] - weights[edges[1]]).sum(axis=1)
    assert jumps.max() < SMOOTH_CARRY_MAX_JUMP
    assert np.percentile(jumps, 99) < SMOOTH_CARRY_P99_JUMP


@pytest.mark.parametrize("name", NETWORK_NAMES)
def test_several_objects_a_loose_prop_and_a_bone_outside_the_body_are_all_weighted(name):
    # A tube (two bones inside), a loose box prop floating beside it, and a
    # third bone in the air above the tube: every vertex of both objects gets
    # a full row, and the tube's lower end keeps its own bone.
    tube = cylinder(radius=0.1, height=2.0, rings=21)
    prop = box_mesh([0.4, -0.1, 1.6], [0.6, 0.1, 1.8], 0.05)
    mesh = Mesh.concatenate([Mesh(tube.vertices, tube.triangles, object_names=("Tube",)),
                             Mesh(prop.vertices, prop.triangles, object_names=("Prop",))])
    skeleton = Skeleton(np.array([[0, 0, 0.0], [0, 0, 1.0], [0, 0, 2.3]]), np.array([-1, 0, 1]),
                        ("lower", "upper", "floating"), np.array([[0, 0, 1.0], [0, 0, 2.0], [0, 0, 2.6]]),
                        np.ones(3, dtype=bool))
    weights = predict.learned_weights(mesh, skeleton, name, resolution=RESOLUTION).matrix
    assert weights.shape == (mesh.vertex_count, 3)
    np.testing.assert_allclose(weights.sum(axis=1), 1, atol=1e-12)
    assert np.isfinite(weights).all() and (weights >= 0).all()
    lower_end = mesh.vertices[:, 2] < 0.5
    assert weights[lower_end, 0].mean() > 0.8
