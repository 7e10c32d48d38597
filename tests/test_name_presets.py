"""Bone-name presets of the standard biped: every engine's names, and back."""

import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.skeleton.name_presets import PRESETS, RIGIFY_BONES, preset_names, preset_of, renamed


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_every_preset_names_every_bone_once_and_round_trips(preset):
    names = [PRESETS[preset][bone] for bone in RIGIFY_BONES]
    assert len(set(names)) == len(RIGIFY_BONES)
    there = renamed(RIGIFY_BONES, preset)
    assert [there[bone] for bone in RIGIFY_BONES] == names
    back = renamed(names, "rigify")
    assert [back[name] for name in names] == list(RIGIFY_BONES)


def test_known_engine_names():
    assert renamed(RIGIFY_BONES, "mixamo")["forearm.L"] == "mixamorig:LeftForeArm"
    assert renamed(RIGIFY_BONES, "mixamo")["spine"] == "mixamorig:Hips"
    assert renamed(RIGIFY_BONES, "unreal")["shin.R"] == "calf_r"
    assert renamed(RIGIFY_BONES, "unity")["spine.003"] == "UpperChest"
    assert renamed(RIGIFY_BONES, "vrm")["toe.L"] == "leftToes"
    # From one engine's names to another's directly.
    unreal = [PRESETS["unreal"][bone] for bone in RIGIFY_BONES]
    assert renamed(unreal, "mixamo")["upperarm_l"] == "mixamorig:LeftArm"


def test_the_preset_of_a_skeleton_and_bones_no_preset_knows():
    names = [PRESETS["vrm"][bone] for bone in RIGIFY_BONES] + ["sword"]
    assert preset_of(names) == "vrm"
    # Unity's and Godot's humanoid names are the same: the first listed is reported.
    assert preset_of([PRESETS["godot"][bone] for bone in RIGIFY_BONES]) == "unity"
    new, applied = preset_names(names, "mixamo")
    assert applied and new[-1] == "sword" and new[0] == "mixamorig:Hips"


def test_a_quadruped_keeps_its_names_and_an_unknown_preset_is_refused():
    quadruped = ["spine", "neck", "head", "front_thigh.L", "front_thigh.R", "thigh.L", "thigh.R"]
    assert preset_of(quadruped) is None
    assert preset_names(quadruped, "mixamo") == (tuple(quadruped), False)
    with pytest.raises(InputError, match="Only a standard biped skeleton can take engine bone names"):
        renamed(quadruped, "unreal")
    with pytest.raises(InputError, match="Unknown bone-name preset 'maya': use one of rigify, mixamo"):
        preset_names(RIGIFY_BONES, "maya")
