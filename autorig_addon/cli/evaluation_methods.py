"""The methods ``eval`` can score: one registry per task, and the built-in methods.

A method is registered under a name with ``predict`` and a one-line
description; ``--method NAME`` picks it. Learned networks register here too
(:func:`register_rig_method` for a skeleton predictor). What ``predict``
gets and returns, per task:

skin
    ``predict(SkinInput) -> Weights`` over the deform bones.
rig
    ``predict(mesh: Mesh) -> Skeleton`` in the world space of the mesh, or
    a :class:`RigPrediction` when the method has notes for the report.
transfer
    ``predict(source_mesh, source_weights, target_mesh) -> Weights``.

Besides the registered ones, ``--method reference`` (:data:`REFERENCE_METHOD`)
returns a skin task's reference weights, and ``--method file:DIR``
(:data:`FILE_METHOD_PREFIX`) reads predicted rigs from a folder.
Built-in methods import what they run only when called, so ``--help`` does
not load Blender.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Callable

from ..core.dataset.split import DataItem
from ..core.errors import InputError
from ..core.skinning.learned.ensemble import ENSEMBLE
from ..core.skinning.learned.networks import NETWORK_NAMES
from ..core.skinning.methods import SKIN_METHOD_DESCRIPTIONS

#: Skin method that returns the reference itself: a sanity check of the
#: pipeline (its scores must be perfect), not a method.
REFERENCE_METHOD = "reference"
#: Prefix of the rig method that reads predicted rigs from a folder.
FILE_METHOD_PREFIX = "file:"


@dataclass(frozen=True)
class SkinInput:
    """What a skin method may look at.

    Attributes
    ----------
    mesh : core.types.Mesh, world space, rest pose
    skeleton : core.types.Skeleton; weights go to its deform bones
    armature_name : str, the armature object in the loaded scene (for
        methods that run inside Blender), "" when there is none
    """

    mesh: object
    skeleton: object
    armature_name: str = ""


@dataclass(frozen=True)
class RigPrediction:
    """What a rig method gives: the skeleton and notes for the report.

    Attributes
    ----------
    skeleton : core.types.Skeleton, world space of the mesh
    notes : tuple of str, e.g. which training character a baseline chose
    """

    skeleton: object
    notes: tuple = ()


@dataclass(frozen=True)
class Method:
    """A registered method: ``predict`` and a one-line description."""

    predict: Callable
    description: str


#: skin methods: ``predict(SkinInput) -> Weights``.
SKIN_METHODS: dict[str, Method] = {}
#: rig methods: ``predict(mesh) -> Skeleton`` (world space of the mesh).
RIG_METHODS: dict[str, Method] = {}
#: transfer methods: ``predict(source_mesh, source_weights, target_mesh) -> Weights``.
TRANSFER_METHODS: dict[str, Method] = {}

_REGISTRIES = {"skin": SKIN_METHODS, "rig": RIG_METHODS, "transfer": TRANSFER_METHODS}


def register_skin_method(name: str, predict: Callable, description: str) -> None:
    """Add a skin weight predictor: ``predict(SkinInput) -> Weights``."""
    SKIN_METHODS[name] = Method(predict, description)


def register_rig_method(name: str, predict: Callable, description: str) -> None:
    """Add a skeleton predictor: ``predict(mesh: Mesh) -> Skeleton``."""
    RIG_METHODS[name] = Method(predict, description)


def register_transfer_method(name: str, predict: Callable, description: str) -> None:
    """Add a weight transfer: ``predict(source_mesh, source_weights, target_mesh) -> Weights``."""
    TRANSFER_METHODS[name] = Method(predict, description)


def method_names(task: str) -> list[str]:
    """What ``--method`` accepts for ``task``: the registered names, sorted,
    then the pseudo-methods (``reference`` for skin, ``file:DIR`` for rig)."""
    names = sorted(_REGISTRIES[task])
    if task == "skin":
        names.append(REFERENCE_METHOD)
    if task == "rig":
        names.append(FILE_METHOD_PREFIX + "DIR")
    return names


def rig_predictor(method: str) -> Callable:
    """``predict(mesh, item: DataItem) -> RigPrediction`` for a rig method name.

    Raises
    ------
    InputError for an unknown method or a ``file:DIR`` folder that does not exist.
    """
    if method.startswith(FILE_METHOD_PREFIX):
        folder = Path(method[len(FILE_METHOD_PREFIX):])
        if not folder.is_dir():
            raise InputError(f"The folder of predicted rigs '{folder}' does not exist.")

        def read_predicted(mesh, item: DataItem):
            from ..core.io.rignet_rig import read_rignet_rig

            candidates = [folder / f"{item.name}.txt", folder / f"{item.name}_rig.txt",
                          folder / f"{item.path.stem}.txt", folder / f"{item.path.stem}_rig.txt"]
            for candidate in candidates:
                if candidate.is_file():
                    # No armature is built: joints at their parent's position are scored as they are.
                    return RigPrediction(read_rignet_rig(candidate, for_armature=False)[0])
            raise InputError(f"No predicted rig for '{item.name}' in '{folder}' (looked for {candidates[0].name}).")

        return read_predicted
    if method not in RIG_METHODS:
        raise InputError(f"Unknown rig method '{method}': use {FILE_METHOD_PREFIX}DIR or one of {sorted(RIG_METHODS)}.")
    predict = RIG_METHODS[method].predict

    def predict_rig(mesh, item: DataItem) -> RigPrediction:
        with itself_left_out(item.path):
            result = predict(mesh)
        return result if isinstance(result, RigPrediction) else RigPrediction(result)

    return predict_rig


def check_method(task: str, method: str) -> None:
    """Raise InputError when ``method`` cannot run for ``task``."""

    if task == "skin":
        if method != REFERENCE_METHOD and method not in SKIN_METHODS:
            raise InputError(f"Unknown skin method '{method}': use one of {sorted(SKIN_METHODS) + [REFERENCE_METHOD]}.")
    elif task == "rig":
        rig_predictor(method)
    elif method not in TRANSFER_METHODS:
        raise InputError(f"Unknown transfer method '{method}': use one of {sorted(TRANSFER_METHODS)}.")


# --------------------------------------------------------------------------- built-in methods


def _bone_heat(task: SkinInput):
    import bpy

    from ..blender.bone_heat import bone_heat_weights

    armature = bpy.data.objects.get(task.armature_name) if task.armature_name else None
    if armature is None:
        raise InputError("Bone heat needs the character's armature in the loaded scene.")
    return bone_heat_weights(task.mesh, task.skeleton, armature)


def _nearest_bone(task: SkinInput):
    from ..core.skinning.nearest_bone import nearest_bone_weights

    return nearest_bone_weights(task.mesh, task.skeleton)


def _skin_method(name: str) -> Callable:
    """The skin method ``name`` (the geometric method or a shipped network)
    with the Skin job's defaults, as a user gets it (rigid loose parts included)."""

    def predict(task: SkinInput):
        from ..core.skinning.methods import skin_weights
        from ..core.skinning.options import SkinningOptions

        return skin_weights(task.mesh, task.skeleton, SkinningOptions(method=name))

    return predict


#: The characters the built-in rig methods may not copy while one is scored (:func:`itself_left_out`).
_LEFT_OUT: list = [frozenset()]


@lru_cache(maxsize=1)
def _repository_split():
    """The repository's ``data_split.json`` (``--split-file`` does not reach a registered method), read
    once; None where there is none (an installed extension)."""
    from ..core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split

    return read_data_split(DEFAULT_SPLIT_FILE) if DEFAULT_SPLIT_FILE.is_file() else None


@contextmanager
def itself_left_out(path: Path):
    """Inside, the built-in rig methods copy nothing of the character in the file ``path`` or its
    near-duplicates (``data_split.json``, which names the file whatever folder ``eval`` was given, in
    any format: a .blend saved from a listed .glb too):
    not their rigs from the rig library (``core.rigging.rig_library.shipped_library_without``), not
    their skeletons as the closest character. A validation character and its near-duplicates are in
    neither, so its score does not change; a training character is scored without its own artist's
    rig to copy (the networks still trained on it: numbers on training characters stay in-sample). A
    file the split does not name (or no split) leaves nothing out."""
    from ..core.dataset.split import split_entry
    from ..core.rigging.rig_library import shipped_library_without

    split = _repository_split()
    entry = split_entry(Path(path), split, any_extension=True)
    left_out = split.near_duplicate_names(os.path.splitext(entry)[0]) if entry is not None else frozenset()
    _LEFT_OUT.append(left_out)
    try:
        with shipped_library_without(left_out):
            yield
    finally:
        _LEFT_OUT.pop()


@lru_cache(maxsize=1)
def _nearest_character_pool() -> tuple:
    """The cached samples of the training characters of the repository's
    ``data_split.json`` (``--split-file`` does not reach a registered method),
    read once per process; its validation characters are left out by name
    whatever the cache holds."""
    from ..core.dataset.cache import training_samples
    from ..core.dataset.split import DEFAULT_SPLIT_FILE, PURPOSE_SKELETON, read_data_split

    validation = {os.path.splitext(path)[0] for path in read_data_split(DEFAULT_SPLIT_FILE).validation}
    pool = training_samples(purpose=PURPOSE_SKELETON)
    return tuple(sample for sample in pool if sample.name not in validation), frozenset(validation)


def _nearest_character(mesh) -> RigPrediction:
    from ..core.rigging.nearest_character import nearest_character

    pool, validation = _nearest_character_pool()
    chosen = nearest_character(mesh, pool, exclude=validation | _LEFT_OUT[-1])
    return RigPrediction(chosen.skeleton, (chosen.note,))


def _rignet_skeleton(mesh, template: str = "auto") -> RigPrediction:
    from ..core.rigging.predict import checked_skeleton, predict_votes, template_notes

    votes = predict_votes(mesh)
    checked = checked_skeleton(votes, template=template)  # as Auto-Rig builds it
    return RigPrediction(checked.skeleton, (*votes.notes, *template_notes(votes, template, known_rig=checked.known_rig),
                                            *checked.notes))


def _closest_point_transfer(source, source_weights, target):
    from ..core.transfer.matching import closest_point_weights

    return closest_point_weights(source, source_weights, target)


def _robust_transfer(source, source_weights, target):
    from ..core.transfer.transfer import transfer_weights

    return transfer_weights(source, source_weights, target).weights


register_skin_method("boneheat", _bone_heat, "Blender's Automatic Weights (bone heat) on a copy without vertex groups")
register_skin_method("nearest_bone", _nearest_bone, "each vertex wholly to its closest deform bone")
register_skin_method("geometric", _skin_method("geometric"),
                     "core.skinning.geometric with the Skin job's defaults (rigid loose parts)")
for _name in NETWORK_NAMES + (ENSEMBLE,):
    register_skin_method(_name, _skin_method(_name),
                         f"{SKIN_METHOD_DESCRIPTIONS[_name]} (core.skinning.learned; rigid loose parts)")
register_rig_method(
    "nearest_character", _nearest_character,
    "the learning-free baseline: the training character with the closest normalised surface (Chamfer), "
    "its skeleton fitted to the mesh's bounding box (core.rigging.nearest_character); samples from the cache",
)
register_rig_method(
    "rignet", _rignet_skeleton,
    "the skeleton predictor with its defaults: joint network, mean shift, bone and root networks "
    "(core.rigging.predict)",
)
register_rig_method(
    "rignet_free_form", lambda mesh: _rignet_skeleton(mesh, "free-form"),
    "the skeleton predictor's free-form skeleton (template free-form): the joint votes' skeleton whatever the body",
)
register_transfer_method("robust", _robust_transfer, "robust transfer with inpainting (core.transfer)")
register_transfer_method("closest_point", _closest_point_transfer, "weights of the closest surface point")
