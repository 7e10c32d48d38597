"""Rigged characters from files: the skinned meshes, rest skeleton and artist weights as arrays.

:func:`load_character` turns a rigged file (anything ``scene_io`` reads)
into arrays: every mesh skinned to the chosen armature, concatenated in world
space at the rest pose, the rest skeleton (with bone tails fit to measure
along, ``core.skeleton.tails``) and the artist's weights. It is what the
evaluation (``python -m autorig_addon eval``) and the sample cache
(:func:`build_character_samples`) read. Checking a file's bind pose is in
``bind_pose``, resampling in ``simplify``, Blender's bone heat in
``bone_heat``.

Loading replaces the current scene (``scene_io.load_scene``); use it from the
command line, tests and batch jobs, not from an artist's open file.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Iterable, Optional

import bpy
import numpy as np

from ..core import dataset
from ..core.dataset.weight_checks import check_named_weights, has_mixamo_names
from ..core.errors import InputError
from ..core.geometry.bounding_box import character_size
from ..core.messages import listed_names
from ..core.progress import ProgressCallback
from ..core.skeleton.rest_pose import arm_pose
from ..core.skeleton.tails import with_reliable_tails
from ..core.types import Mesh, Skeleton, Weights
from ..core.weights import INFLUENCE_EPSILON, normalize_rows
from . import convert, scene_io
from .armature_binding import deforms, pose_position
from .simplify import simplify


@dataclass(frozen=True)
class RiggedCharacter:
    """A rigged character read from a file.

    Attributes
    ----------
    name : str
    path : str, the file it was read from
    mesh : Mesh
        Every mesh bound to the armature, concatenated in world space at the
        rest pose (``object_names`` and ``object_offsets`` tell them apart).
    skeleton : Skeleton
        World-space rest skeleton. ``deform`` is set for bones that deform
        (``Bone.use_deform``) *and* carry weight on some vertex: importers
        mark every joint as deforming, including IK and pole-target controls.
        Tails are the armature's own unless they are unusable
        (``core.skeleton.tails.with_reliable_tails``): glTF stores joints,
        not bones, and Blender's importer makes point-like bones of
        armatures scaled up (every Quaternius character), so those get
        tails derived from the joints (heads unchanged); a note says which
        tails were used and why.
    weights : Weights
        ``(n, d)``, columns the deform bones in joint order, rows normalised;
        rows of vertices the file leaves unweighted are zero.
    category : str
    armature_name : str, the armature object in the loaded scene
    notes : tuple of str
        What the loader chose or skipped and why (several armatures, meshes
        not bound to the armature, unweighted vertices, bone tails derived
        from the joints, ...).
    source_vertex_count : int
        Vertices of the mesh as loaded, before any simplification.
    sides_named_from_the_viewer : bool
        ``data_split.json`` says its artist named the sides from the viewer
        (set by :func:`build_character_samples`; its sample is normalised so).
    """

    name: str
    path: str
    mesh: Mesh
    skeleton: Skeleton
    weights: Weights
    category: str = ""
    armature_name: str = ""
    notes: tuple = ()
    source_vertex_count: int = 0
    sides_named_from_the_viewer: bool = False

    @property
    def unweighted(self) -> np.ndarray:
        """(n,) bool: vertices the file gives no weight."""
        return ~(self.weights.matrix > INFLUENCE_EPSILON).any(axis=1)

    @property
    def unweighted_count(self) -> int:
        return int(np.count_nonzero(self.unweighted))

    @property
    def size(self) -> float:
        """Bounding-box diagonal of the rest mesh."""
        return character_size(self.mesh.vertices)


# --------------------------------------------------------------------------- scene inspection


def skinned_meshes(armature_obj) -> list:
    """Mesh objects of the scene the armature deforms
    (:func:`.armature_binding.deforms`), in name order.

    A mesh parented to the armature object or to one of its bones without
    an Armature modifier is attached rigidly (a sword, a hat), not skinned.
    """
    found = [obj for obj in bpy.context.scene.objects if obj.type == "MESH" and deforms(armature_obj, obj)]
    return sorted(found, key=lambda obj: obj.name)


def choose_armature() -> tuple:
    """The armature of the current scene with the most skinned vertices.

    Returns
    -------
    armature : bpy.types.Object
    meshes : list of mesh objects it deforms (:func:`skinned_meshes`)
    notes : list of str, what was chosen and what was left out

    Raises
    ------
    InputError when no armature deforms any mesh.
    """
    candidates = []
    for obj in bpy.context.scene.objects:
        if obj.type == "ARMATURE":
            meshes = skinned_meshes(obj)
            candidates.append((sum(len(mesh.data.vertices) for mesh in meshes), obj.name, obj, meshes))
    candidates = [candidate for candidate in candidates if candidate[0] > 0]
    if not candidates:
        raise InputError(
            "No armature in this file deforms a mesh: a rigged character needs a mesh with an "
            "Armature modifier (or armature parenting) and vertex groups."
        )
    candidates.sort(key=lambda candidate: (-candidate[0], candidate[1]))
    count, _, armature, meshes = candidates[0]
    notes = []
    if len(candidates) > 1:
        others = ", ".join(f"'{name}' ({other} vertices)" for other, name, _, _ in candidates[1:])
        notes.append(f"several armatures deform meshes: using '{armature.name}' ({count} skinned vertices), "
                     f"not {others}")
    chosen = {mesh.name for mesh in meshes}
    skipped = sorted(
        obj.name for obj in bpy.context.scene.objects if obj.type == "MESH" and obj.name not in chosen
    )
    if skipped:
        notes.append(f"meshes not skinned to '{armature.name}' left out: {', '.join(skipped)}")
    return armature, meshes, notes


def read_character(name: str, path: str = "", category: str = "") -> RiggedCharacter:
    """The rigged character of the current scene (see :class:`RiggedCharacter`).

    Raises
    ------
    InputError when no armature deforms a mesh, or no vertex carries weight.
    """
    armature, meshes, notes = choose_armature()
    faceless = [obj.name for obj in meshes if not len(obj.data.polygons)]
    if faceless:
        notes.append(f"skinned meshes without faces left out: {', '.join(faceless)}")
        meshes = [obj for obj in meshes if len(obj.data.polygons)]
        if not meshes:
            raise InputError(f"The meshes skinned to '{armature.name}' have no faces: there is no surface to weight.")
    with pose_position([armature]):
        mesh = convert.read_mesh(meshes, bpy.context.evaluated_depsgraph_get())
    full_skeleton = convert.read_skeleton(armature)
    deforming = [bone for bone, deforms in zip(full_skeleton.names, full_skeleton.deform) if deforms]
    raw = np.concatenate([convert.read_group_weights(obj, deforming) for obj in meshes])
    carries_weight = (raw > INFLUENCE_EPSILON).any(axis=0)
    if not carries_weight.any():
        raise InputError(
            f"No vertex of the meshes skinned to '{armature.name}' has weight on a deform bone: "
            "the file has no skin weights to compare against."
        )
    idle = [bone for bone, used in zip(deforming, carries_weight) if not used]
    if idle:
        notes.append(f"{len(idle)} deform bones carry no weight and are treated as non-deform (left out of the "
                     f"skeleton targets): {listed_names(idle)}")
    weighted_bones = set(bone for bone, used in zip(deforming, carries_weight) if used)
    deform = np.array([bone in weighted_bones for bone in full_skeleton.names], dtype=bool)
    skeleton, tail_decision = with_reliable_tails(replace(full_skeleton, deform=deform), character_size(mesh.vertices))
    notes.append(tail_decision.note)
    deform_names = skeleton.deform_subset().names
    column_of = {bone: column for column, bone in enumerate(deforming)}
    matrix = normalize_rows(raw[:, [column_of[bone] for bone in deform_names]])
    weights = Weights(matrix, deform_names)
    character = RiggedCharacter(
        name=name, path=str(path), mesh=mesh, skeleton=skeleton, weights=weights, category=category,
        armature_name=armature.name, notes=(), source_vertex_count=mesh.vertex_count,
    )
    if character.unweighted_count:
        notes.append(f"{character.unweighted_count} of {mesh.vertex_count} vertices have no weight")
    notes.extend(weight_and_pose_notes(character))
    return replace(character, notes=tuple(notes))


def weight_and_pose_notes(character: RiggedCharacter) -> list[str]:
    """What the loader finds about a character's weights and rest pose:
    rigid weights (every weighted vertex on one bone), the Mixamo-name
    weight check (``core.dataset.weight_checks``) for rigs with Mixamo's
    names, and the arms' rest pose (``core.skeleton.rest_pose``) of a
    humanoid (its category, the split's kind)."""
    notes = []
    influences = (character.weights.matrix > INFLUENCE_EPSILON).sum(axis=1)
    if influences.max(initial=0) == 1:
        notes.append("rigid weights: every weighted vertex follows one bone")
    if has_mixamo_names(character.skeleton.names):
        notes.append(check_named_weights(character.mesh, character.skeleton, character.weights).note)
    if character.category == dataset.HUMANOID:
        pose = arm_pose(character.skeleton)
        notes.append(pose.note if pose is not None else "rest pose: no left and right arm found by name")
    return notes


def load_character(path: str | os.PathLike, name: Optional[str] = None, category: str = "") -> RiggedCharacter:
    """Open a rigged file and read its character (replaces the current scene).

    Parameters
    ----------
    path : file Blender can read (.blend, .glb, .gltf, .fbx)
    name : str, default the file's stem
    category : str

    Returns
    -------
    RiggedCharacter; the file stays loaded, so Blender-based methods
    (bone heat) can run on the armature named ``armature_name``.
    """
    path = Path(path)
    scene_io.load_scene(path)
    return read_character(name or path.stem, str(path), category)




def load_simplified(
    path: str | os.PathLike, target_vertices: Optional[int], name: Optional[str] = None, category: str = "",
) -> RiggedCharacter:
    """:func:`load_character`, then :func:`simplify` when ``target_vertices`` is set."""
    character = load_character(path, name, category)
    if target_vertices is None:
        return character
    mesh, weights = simplify(character.mesh, character.weights, int(target_vertices))
    return replace(character, mesh=mesh, weights=weights)


def build_character_samples(
    paths: Iterable[str | os.PathLike],
    cache_dir: str | os.PathLike | None = None,
    target_vertices: Optional[int] = dataset.DEFAULT_TARGET_VERTICES,
    root: str | os.PathLike | None = None,
    split: Optional[dataset.DataSplit] = None,
    progress: Optional[ProgressCallback] = None,
) -> list:
    """Normalised, cached samples of rigged files (:func:`core.dataset.build_samples`).

    Parameters
    ----------
    paths : rigged files
    cache_dir : folder, default ``core.dataset.default_cache_dir()``
    target_vertices : int or None, see :func:`simplify`
    root : folder the names and categories are taken relative to
        (e.g. the characters folder); default each file's own folder
    split : DataSplit giving categories, optional
    progress : ProgressCallback, optional

    Returns
    -------
    list of core.dataset.CharacterSample
    """

    def named_from_the_viewer(path: Path) -> bool:
        listed = split.sides_named_from_the_viewer if split is not None else {}
        return dataset.relative_name(path, root) + path.suffix in listed

    def load(path: Path, target: Optional[int]):
        name = dataset.relative_name(path, root)
        character = load_simplified(path, target, name, dataset.category_of(name + path.suffix, split))
        return replace(character, sides_named_from_the_viewer=named_from_the_viewer(path))

    def key_extras(path: Path) -> dict:
        # Only a flagged character's key changes: every other cached sample stays valid.
        return {"sides_named_from_the_viewer": True} if named_from_the_viewer(path) else {}

    return dataset.build_samples(paths, load, cache_dir, target_vertices, progress, key_extras)
