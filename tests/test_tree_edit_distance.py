"""Tree edit distance between joint hierarchies
(autorig_addon.core.evaluation.tree_edit_distance)."""

import itertools

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.evaluation.tree_edit_distance import constrained_tree_edit_distance, tree_edit_distance


def test_tree_edit_identical_chains():
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1], [0, 1, 2]) == 0


def test_tree_edit_chain_with_extra_leaf():
    # pred is the reference chain plus an unmatched leaf under joint 1.
    assert tree_edit_distance([-1, 0, 1, 1], [-1, 0, 1], [0, 1, 2, -1]) == 1
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1, 2], [0, 1, 2]) == 1


def test_tree_edit_reparented_joint_costs_two():
    # Reference: 1 and 2 both children of 0. Prediction: chain 0-1-2.
    # No mapping keeps 1 above 2 and both matched: delete and re-insert 2.
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 0], [0, 1, 2]) == 2


def test_tree_edit_relabels_only_when_labelled():
    # Same shape, but predicted joint 2 matched no reference joint: the
    # hierarchy alone (RigNet) costs nothing, the labelled variant 1.
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1], [0, 1, -1]) == 0
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1], [0, 1, -1], labelled=True) == 1
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1], [0, 1, 2], labelled=True) == 0


def test_tree_edit_ignores_sibling_order():
    # Reference: root with a leaf (1) and a joint with a child (2 -> 3).
    # Prediction: the same shape with the children listed the other way
    # round (1 -> 3, 2 leaf). An ordered distance would give 2.
    assert tree_edit_distance([-1, 0, 0, 1], [-1, 0, 0, 2]) == 0
    assert tree_edit_distance([-1, 0, 0, 1], [-1, 0, 0, 2], [0, 2, 1, 3], labelled=True) == 0


def test_tree_edit_star_against_chain():
    # r(a, b, c) vs r(a(b(c))): leaves of the star are unrelated, nodes of
    # the chain all related, so besides the roots only one joint can map:
    # 2 deletions + 2 insertions.
    assert tree_edit_distance([-1, 0, 0, 0], [-1, 0, 1, 2]) == 4


def test_tree_edit_forests_join_under_a_free_root():
    # Two roots each side, same structure: 0; one root short: 1.
    assert tree_edit_distance([-1, -1, 1], [-1, -1, 1]) == 0
    assert tree_edit_distance([-1, 0], [-1, -1, 1]) == 1


def test_tree_edit_labelled_paper_example():
    # Zhang & Shasha (1989): f(d(a, c(b)), e) vs f(c(d(a, b)), e) = 2:
    # delete c under d, insert c above d. Labels a..f = 0..5.
    #            f  d  a  c  b  e
    parents_1 = [-1, 0, 1, 1, 3, 0]
    labels_1 = [5, 3, 0, 2, 1, 4]
    #            f  c  d  a  b  e
    parents_2 = [-1, 0, 1, 2, 2, 0]
    labels_2 = [5, 2, 3, 0, 1, 4]
    assert constrained_tree_edit_distance(parents_1, labels_1, parents_2, labels_2) == 2
    assert constrained_tree_edit_distance(parents_1, labels_1, parents_2, labels_2, relabel_cost=0) == 2


def _ancestors(parents):
    result = []
    for node in range(len(parents)):
        chain, parent = set(), parents[node]
        while parent >= 0:
            chain.add(parent)
            parent = parents[parent]
        result.append(chain)
    return result


def _lowest_common_ancestor(ancestors, a, b):
    common = (ancestors[a] | {a}) & (ancestors[b] | {b})
    return max(common, key=lambda node: len(ancestors[node]))


def _brute_force_distance(parents_a, labels_a, parents_b, labels_b):
    """Cheapest constrained mapping by enumerating all of them (tiny trees).

    Zhang (1996): a mapping keeps ancestry, and lca(t1, t2) is a proper
    ancestor of t3 exactly when lca(s1, s2) is one of s3.
    """
    trees = []
    for parents, labels in ((parents_a, labels_a), (parents_b, labels_b)):
        count = len(parents)
        joined = [count if p < 0 else p for p in parents] + [-1]
        trees.append((joined, list(labels) + [-1], _ancestors(joined)))
    (par_a, lab_a, anc_a), (par_b, lab_b, anc_b) = trees
    best = len(par_a) + len(par_b)
    for k in range(min(len(par_a), len(par_b)) + 1):
        for nodes_a in itertools.combinations(range(len(par_a)), k):
            for nodes_b in itertools.permutations(range(len(par_b)), k):
                pairs = list(zip(nodes_a, nodes_b))
                if any(
                    (t1 in anc_a[t2]) != (s1 in anc_b[s2]) for (t1, s1), (t2, s2) in itertools.permutations(pairs, 2)
                ):
                    continue
                if any(
                    (_lowest_common_ancestor(anc_a, t1, t2) in anc_a[t3])
                    != (_lowest_common_ancestor(anc_b, s1, s2) in anc_b[s3])
                    for (t1, s1), (t2, s2), (t3, s3) in itertools.permutations(pairs, 3)
                ):
                    continue
                relabels = sum(lab_a[t] != lab_b[s] for t, s in pairs)
                best = min(best, len(par_a) + len(par_b) - 2 * k + relabels)
    return best


def test_constrained_distance_agrees_with_brute_force():
    rng = np.random.default_rng(4)
    for _ in range(40):
        trees = []
        for _ in range(2):
            count = int(rng.integers(1, 5))
            parents = [-1] + [int(rng.integers(-1, j)) for j in range(1, count)]
            trees.append((parents, [int(x) for x in rng.integers(0, 3, count)]))
        (parents_a, labels_a), (parents_b, labels_b) = trees
        expected = _brute_force_distance(parents_a, labels_a, parents_b, labels_b)
        assert constrained_tree_edit_distance(parents_a, labels_a, parents_b, labels_b) == expected


def test_tree_edit_is_invariant_to_joint_order():
    # A random 30-joint hierarchy against itself with indices shuffled
    # (parents kept first): 0; against itself minus a leaf: 1.
    rng = np.random.default_rng(9)
    parents = np.array([-1] + [int(rng.integers(0, j)) for j in range(1, 30)])
    depth = np.zeros(30, dtype=int)
    for j in range(1, 30):
        depth[j] = depth[parents[j]] + 1
    permutation = np.lexsort((rng.random(30), depth))  # parents stay before children
    new_index = np.empty(30, dtype=int)
    new_index[permutation] = np.arange(30)
    shuffled = np.where(parents[permutation] >= 0, new_index[parents[permutation]], -1)
    assert tree_edit_distance(shuffled, parents) == 0
    leaf = int(np.setdiff1d(np.arange(30), parents)[0])
    keep = np.delete(np.arange(30), leaf)
    old_to_new = -np.ones(30, dtype=int)
    old_to_new[keep] = np.arange(29)
    pruned = np.where(parents[keep] >= 0, old_to_new[parents[keep]], -1)
    assert tree_edit_distance(pruned, parents) == 1


def test_tree_edit_rejects_bad_matching():
    with pytest.raises(InputError, match="The matching uses a reference joint twice; it must be one-to-one"):
        tree_edit_distance([-1, 0], [-1, 0], [0, 0])
    with pytest.raises(InputError, match="The matching has 1 entries for 2 predicted joints"):
        tree_edit_distance([-1, 0], [-1, 0], [0])
    with pytest.raises(InputError, match="The matching refers to a reference joint that does not exist"):
        tree_edit_distance([-1, 0], [-1, 0], [0, 2])
    with pytest.raises(InputError, match="A labelled tree edit distance needs the joint matching"):
        tree_edit_distance([-1, 0], [-1, 0], labelled=True)
