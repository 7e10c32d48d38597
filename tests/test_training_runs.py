"""What every training run shares (training/runs.py): which family each
character belongs to and how an epoch samples families evenly."""

import json
from collections import Counter

import numpy as np
import pytest

pytest.importorskip("torch")
pytestmark = pytest.mark.torch

from autorig_addon.training.runs import character_families, epoch_step_count, epoch_steps  # noqa: E402

#: Examples per character (the character and its variants) of the epoch tests.
EXAMPLES = {"fish/a": 3, "fish/b": 3, "fish/c": 3, "fish/d": 3, "fish/e": 3, "horse/a": 2, "lone/x": 1}
FAMILIES = {"fish/a": 0, "fish/b": 0, "fish/c": 0, "fish/d": 0, "fish/e": 0, "horse/a": 1, "lone/x": 2}


def example_characters():
    return [character for character, count in EXAMPLES.items() for _ in range(count)]


def test_an_epoch_takes_at_most_the_cap_of_a_family_each_once_with_one_of_its_examples():
    characters = example_characters()
    rng = np.random.default_rng(0)
    # 5 fish capped at 2, the horse and the lone character: 4 steps.
    assert epoch_step_count(characters, FAMILIES, per_family=2) == 4
    seen_examples = Counter()
    seen_fish = Counter()
    for _ in range(300):
        steps = epoch_steps(characters, FAMILIES, rng, per_family=2)
        picked = [characters[index] for index in steps]
        assert len(steps) == 4 and len(set(picked)) == 4
        assert Counter(FAMILIES[name] for name in picked) == {0: 2, 1: 1, 2: 1}
        seen_examples.update(steps)
        seen_fish.update(name for name in picked if name.startswith("fish/"))
    # Over many epochs every example is drawn, and the fish share their two steps evenly
    # (each fish 2/5 of the epochs: 120 of 300, within about four standard deviations).
    assert set(seen_examples) == set(range(len(characters)))
    assert all(abs(count - 120) <= 35 for count in seen_fish.values())


def test_epochs_draw_anew_and_the_same_seed_draws_the_same():
    characters = example_characters()
    first = [epoch_steps(characters, FAMILIES, np.random.default_rng(3), per_family=2) for _ in range(2)]
    rng = np.random.default_rng(3)
    again = [epoch_steps(characters, FAMILIES, rng, per_family=2), epoch_steps(characters, FAMILIES, rng, per_family=2)]
    assert first[0] == first[1] == again[0]
    assert again[1] != again[0]


def test_families_come_from_the_split_and_unlisted_characters_are_their_own(tmp_path):
    split = {"train": ["pack/a.glb", "pack/b.glb", "solo/c.glb"], "validation": [],
             "categories": {"fish": ["pack/a.glb", "pack/b.glb", "solo/c.glb"]},
             "families": [{"members": ["solo/c.glb"]}, {"members": ["pack/a.glb", "pack/b.glb"]}]}
    (tmp_path / "split.json").write_text(json.dumps(split))
    families = character_families(["pack/a", "pack/b", "solo/c", "procedural/biped_0", "procedural/biped_1"],
                                  str(tmp_path / "split.json"))
    assert families == {"pack/a": 1, "pack/b": 1, "solo/c": 0, "procedural/biped_0": 2, "procedural/biped_1": 3}
