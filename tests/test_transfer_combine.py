"""How transferred weights combine with a target's existing weights
(core.transfer.combine), on rows whose answers are worked by hand."""

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.transfer.combine import (
    MIX,
    REPLACE,
    REPLACE_ALL,
    check_write_mode,
    combine_with_existing,
    needs_existing_weights,
)

# Three bones; the target already weighs row 0 to bone 1 and row 1 half to bones 1 and 2.
EXISTING = np.array([[0.0, 1.0, 0.0], [0.0, 2.0, 2.0]])  # raw, rows not normalised
INCOMING = np.array([[1.0, 0.0, 0.0], [0.5, 0.5, 0.0]])
ALL_BONES = np.array([0, 1, 2])


@pytest.mark.parametrize(
    ("mode", "transferred", "bones", "expected"),
    [(REPLACE, 3, 3, False), (REPLACE_ALL, 3, 3, False), (MIX, 3, 3, True), (REPLACE, 1, 3, True),
     (REPLACE_ALL, 2, 3, True)],
)
def test_existing_weights_matter_for_mixing_and_bone_subsets(mode, transferred, bones, expected):
    assert needs_existing_weights(mode, transferred, bones) is expected


def test_replacing_every_bone_returns_the_transferred_weights_untouched():
    assert combine_with_existing(EXISTING, INCOMING, ALL_BONES, REPLACE) is INCOMING
    assert combine_with_existing(EXISTING, INCOMING, ALL_BONES, REPLACE_ALL) is INCOMING


def test_mix_blends_every_bone_by_the_factor():
    combined = combine_with_existing(EXISTING, INCOMING, ALL_BONES, MIX, mix_factor=0.25)
    # Row 0: 0.75 * (0, 1, 0) + 0.25 * (1, 0, 0). Row 1: 0.75 * (0, .5, .5) + 0.25 * (.5, .5, 0).
    np.testing.assert_allclose(combined, [[0.25, 0.75, 0.0], [0.125, 0.5, 0.375]], atol=1e-12)


def test_replace_of_a_bone_subset_keeps_the_other_bones_and_renormalises():
    combined = combine_with_existing(EXISTING, INCOMING, np.array([0]), REPLACE)
    # Bone 0 takes the transferred value, bones 1 and 2 keep their normalised share.
    np.testing.assert_allclose(combined, [[0.5, 0.5, 0.0], [0.5 / 1.5, 0.5 / 1.5, 0.5 / 1.5]], atol=1e-12)


def test_replace_all_of_a_bone_subset_drops_the_existing_weights():
    combined = combine_with_existing(EXISTING, INCOMING, np.array([0, 1]), REPLACE_ALL)
    np.testing.assert_allclose(combined, [[1.0, 0.0, 0.0], [0.5, 0.5, 0.0]], atol=1e-12)


def test_influence_limit_applies_after_mixing():
    combined = combine_with_existing(EXISTING, INCOMING, ALL_BONES, MIX, mix_factor=0.25, max_influences=1)
    np.testing.assert_allclose(combined, [[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]], atol=1e-12)


def test_bad_write_modes_are_input_errors():
    with pytest.raises(InputError, match=r"^Unknown write mode 'COPY': use one of REPLACE, MIX, REPLACE_ALL\.$"):
        check_write_mode("COPY", 1.0)
    with pytest.raises(InputError, match=r"^The mix factor must lie between 0 and 1, got 1\.5\.$"):
        combine_with_existing(EXISTING, INCOMING, ALL_BONES, MIX, mix_factor=1.5)
