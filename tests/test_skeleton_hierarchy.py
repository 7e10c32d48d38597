"""Parent-array hierarchies (autorig_addon.core.skeleton.hierarchy), worked by hand."""

import numpy as np
import pytest

from autorig_addon.core.skeleton.hierarchy import (
    children_lists,
    descendant_counts,
    parents_first_order,
    reindexed_parents,
    root_indices,
    subset_parents,
)

# Joint 1 is the root; 0 and 2 are its children, 3 is the child of 0.
#        1
#       / \
#      0   2
#      |
#      3
CHILD_BEFORE_PARENT = [1, -1, 1, 0]

# Two trees, children listed before parents: 1 -> 2 -> 0 and 3 -> 4.
FOREST = [2, -1, 1, -1, 3]


def test_children_and_roots_of_a_tree():
    assert children_lists(CHILD_BEFORE_PARENT) == [[3], [0, 2], [], []]
    np.testing.assert_array_equal(root_indices(CHILD_BEFORE_PARENT), [1])
    assert children_lists(FOREST) == [[], [2], [0], [4], []]
    np.testing.assert_array_equal(root_indices(FOREST), [1, 3])


def test_parents_first_order_and_reindexed_parents():
    order = parents_first_order(CHILD_BEFORE_PARENT)
    np.testing.assert_array_equal(order, [1, 0, 2, 3])
    np.testing.assert_array_equal(reindexed_parents(CHILD_BEFORE_PARENT, order), [-1, 0, 0, 1])

    # Ready joints: {1, 3} -> 1; {2, 3} -> 2; {0, 3} -> 0; {3} -> 3; {4} -> 4.
    order = parents_first_order(FOREST)
    np.testing.assert_array_equal(order, [1, 2, 0, 3, 4])
    np.testing.assert_array_equal(reindexed_parents(FOREST, order), [-1, 0, 1, -1, 3])


def test_parents_first_order_keeps_an_order_that_already_is():
    # A depth-first walk would give 0, 1, 3, 2, 4; the stable order keeps the input.
    parents = [-1, 0, 0, 1, 2]
    np.testing.assert_array_equal(parents_first_order(parents), np.arange(5))
    np.testing.assert_array_equal(reindexed_parents(parents, np.arange(5)), parents)


def test_parents_first_order_leaves_out_joints_on_a_cycle():
    # 1 and 2 are each other's parent, 3 hangs below them: only the root is reachable.
    np.testing.assert_array_equal(parents_first_order([-1, 2, 1, 1]), [0])
    with pytest.raises(ValueError, match="The parent array has a cycle."):
        descendant_counts([-1, 2, 1, 1])
    with pytest.raises(ValueError, match="The parent array has a cycle."):
        subset_parents([-1, 2, 1, 1], [True, True, False, True])


def test_descendant_counts():
    np.testing.assert_array_equal(descendant_counts(CHILD_BEFORE_PARENT), [1, 3, 0, 0])
    np.testing.assert_array_equal(descendant_counts(FOREST), [0, 2, 1, 1, 0])
    np.testing.assert_array_equal(descendant_counts([-1, 0, 1, 2]), [3, 2, 1, 0])


def test_subset_parents_link_to_the_nearest_kept_ancestor():
    chain = [-1, 0, 1, 2]
    np.testing.assert_array_equal(subset_parents(chain, [True, False, False, True]), [-1, 0])
    np.testing.assert_array_equal(subset_parents(chain, [False, True, False, True]), [-1, 0])
    # 0 -> 1 -> 2 and 0 -> 3 -> 4, keeping 1, 2 and 4: 4's ancestors 3 and 0 are dropped.
    branching = [-1, 0, 1, 0, 3]
    np.testing.assert_array_equal(subset_parents(branching, [False, True, True, False, True]), [-1, 0, -1])
    # Children listed before parents: keep 0 and 1 of FOREST (0's parent 2 is dropped, 2's is 1).
    np.testing.assert_array_equal(subset_parents(FOREST, [True, True, False, False, False]), [1, -1])
    np.testing.assert_array_equal(subset_parents(chain, [True] * 4), chain)


def test_empty_hierarchy():
    assert children_lists([]) == []
    assert len(parents_first_order([])) == 0
    assert len(descendant_counts([])) == 0


def test_invalid_input_is_refused():
    with pytest.raises(ValueError, match="A parent index refers to a joint that does not exist."):
        children_lists([-1, 5])
    with pytest.raises(ValueError, match="A parent index refers to a joint that does not exist."):
        parents_first_order([-2, 0])
    with pytest.raises(ValueError, match="The order must list every joint exactly once."):
        reindexed_parents([-1, 0, 0], [0, 1, 1])
    with pytest.raises(ValueError, match="keep needs one entry per joint."):
        subset_parents([-1, 0], [True])
