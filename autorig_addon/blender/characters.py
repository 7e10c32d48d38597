"""Rigged characters from files: loading, bind-pose checks, simplification.

:func:`load_character` turns a rigged file (anything ``scene_io`` reads)
into arrays: every mesh skinned to the chosen armature, concatenated in world
space at the rest pose, the rest skeleton and the artist's weights. It is
what the evaluation (``python -m autorig_addon eval``) and the sample cache
(:func:`build_character_samples`) read.

Loading replaces the current scene (``scene_io.load_scene``); use it from the
command line, tests and batch jobs, not from an artist's open file.

Bind pose
---------
Blender keeps no bind matrices: the armature modifier moves a vertex by
``pose @ rest^-1`` of its bones, so the rest pose *is* the bind pose and a
rest pose edited after binding leaves no trace in a ``.blend`` file. What
can go wrong is elsewhere, and :func:`check_bind_pose` measures it:

* with the armature in REST position the evaluated mesh must equal the
  undeformed mesh; active shape keys and modifiers before the Armature
  modifier make it differ (``rest_error``);
* an imported file (glTF, FBX) also has a default pose, the joints' node
  transforms. The glTF importer makes Blender's rest pose the bind pose it
  reads from the inverse bind matrices and puts the node transforms in the
  pose bones. When the two differ the file's skeleton, as stored, does not
  fit its own mesh (``pose_error``, measured on the file imported without
  animations so the pose is the node transforms, not frame 0 of a clip).
"""

from __future__ import annotations

import contextlib
import json
import os
import struct
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Iterable, Optional, Sequence
from urllib.parse import quote, unquote

import bpy
import numpy as np

from ..core import dataset
from ..core.errors import InputError
from ..core.geometry.bounding_box import character_size
from ..core.geometry.subdivision import subdivide_midpoints
from ..core.geometry.weld import weld_objects, weld_seams
from ..core.progress import ProgressCallback
from ..core.skeleton.tails import with_reliable_tails
from ..core.types import Mesh, Skeleton, Weights
from ..core.weights import INFLUENCE_EPSILON, normalize_rows
from . import convert, scene_io

#: A character deforms to itself when no vertex moves farther than this share
#: of its size (bounding-box diagonal) between the undeformed mesh and the
#: armature-evaluated one: 1e-4 of a 2 m character is 0.2 mm, far below any
#: visible error and far above float32 round-off (about 1e-7).
BIND_POSE_TOLERANCE = 1e-4
#: A bone counts as moved away from its rest pose when its pose matrix differs
#: from the rest matrix by more than this (rotation entries, and translations
#: as a share of the character size).
POSE_MATRIX_TOLERANCE = 1e-4
#: Bones listed by name in a message before "and N more".
MAX_LISTED_BONES = 5

#: The simplified mesh may miss the target vertex count by this share.
SIMPLIFY_COUNT_TOLERANCE = 0.05
#: Decimation ratio refinements tried to hit the target vertex count.
SIMPLIFY_MAX_STEPS = 6
#: Name prefix of the point attributes that carry weights through decimation.
WEIGHT_ATTRIBUTE_PREFIX = "autorig_weight_"
#: Name of the temporary objects this module creates (and always removes).
SCRATCH_NAME = "AutoRig scratch"

_GLB_MAGIC = 0x46546C67
_GLB_JSON_CHUNK = 0x4E4F534A
_GLB_HEADER = struct.Struct("<III")
_GLB_CHUNK_HEADER = struct.Struct("<II")


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
    """Mesh objects the armature deforms, in name order: those with an
    Armature modifier on it, or parented to it with parent type ARMATURE.

    A mesh parented to the armature object or to one of its bones without
    either is attached rigidly (a sword, a hat), not skinned.
    """
    found = []
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH":
            continue
        by_modifier = any(
            modifier.type == "ARMATURE" and modifier.object == armature_obj for modifier in obj.modifiers
        )
        by_parent = obj.parent == armature_obj and obj.parent_type == "ARMATURE"
        if by_modifier or by_parent:
            found.append(obj)
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
        notes.append(f"several armatures deform meshes: using '{armature.name}' ({count} skinned vertices), not {others}")
    chosen = {mesh.name for mesh in meshes}
    skipped = sorted(
        obj.name for obj in bpy.context.scene.objects if obj.type == "MESH" and obj.name not in chosen
    )
    if skipped:
        notes.append(f"meshes not skinned to '{armature.name}' left out: {', '.join(skipped)}")
    return armature, meshes, notes


@contextlib.contextmanager
def rest_position(armature_obj):
    """Show the armature in its REST position inside the block (restored after)."""
    previous = armature_obj.data.pose_position
    armature_obj.data.pose_position = "REST"
    bpy.context.view_layer.update()
    try:
        yield
    finally:
        armature_obj.data.pose_position = previous
        bpy.context.view_layer.update()


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
    with rest_position(armature):
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
        notes.append(f"{len(idle)} deform bones carry no weight and are treated as non-deform: {_listed(idle)}")
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
    return replace(character, notes=tuple(notes))


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


def _listed(names: Sequence[str]) -> str:
    shown = ", ".join(names[:MAX_LISTED_BONES])
    return shown + (f" and {len(names) - MAX_LISTED_BONES} more" if len(names) > MAX_LISTED_BONES else "")


# --------------------------------------------------------------------------- bind pose


@dataclass(frozen=True)
class BindPoseCheck:
    """How far a character's mesh moves when nothing should move it.

    Attributes
    ----------
    rest_error : float
        Largest distance between the armature-evaluated mesh in REST position
        and the undeformed mesh, as a share of the character size.
    pose_error : float
        The same with the skeleton in its default pose (NaN when not measured).
    reasons : tuple of str
        Why the mesh moves, as far as the scene tells.
    vertex_count : int
    """

    rest_error: float
    pose_error: float
    reasons: tuple = ()
    vertex_count: int = 0

    @property
    def error(self) -> float:
        values = [value for value in (self.rest_error, self.pose_error) if not np.isnan(value)]
        return max(values) if values else 0.0

    @property
    def deforms_to_itself(self) -> bool:
        return self.error <= BIND_POSE_TOLERANCE


def _world_vertices(obj, mesh_data) -> np.ndarray:
    matrix = np.array([list(row) for row in obj.matrix_world], dtype=np.float64)
    positions = np.empty(len(mesh_data.vertices) * 3, dtype=np.float32)
    mesh_data.vertices.foreach_get("co", positions)
    return positions.reshape(-1, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]


def _evaluated_vertices(obj) -> Optional[np.ndarray]:
    """World positions of the evaluated mesh, None when modifiers change the count."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    data = evaluated.to_mesh()
    try:
        if len(data.vertices) != len(obj.data.vertices):
            return None
        return _world_vertices(obj, data)
    finally:
        evaluated.to_mesh_clear()


@contextlib.contextmanager
def _only_modifiers_up_to_armature(mesh_objects):
    """Hide modifiers after the Armature modifier (subdivision, solidify...):
    they do not change the binding but may change the vertex count."""
    hidden = []
    for obj in mesh_objects:
        seen_armature = False
        for modifier in obj.modifiers:
            if seen_armature and modifier.show_viewport:
                modifier.show_viewport = False
                hidden.append(modifier)
            seen_armature |= modifier.type == "ARMATURE"
    try:
        yield
    finally:
        for modifier in hidden:
            modifier.show_viewport = True


def _mesh_reasons(obj) -> list:
    reasons = []
    keys = obj.data.shape_keys
    if keys is not None:
        if not keys.use_relative:
            reasons.append(f"'{obj.name}' uses absolute shape keys, which move the mesh at rest")
        active = [block.name for block in keys.key_blocks[1:] if not block.mute and abs(block.value) > 0.0]
        if active:
            reasons.append(f"'{obj.name}' has active shape keys: {_listed(active)}")
    before = []
    for modifier in obj.modifiers:
        if modifier.type == "ARMATURE":
            break
        if modifier.show_viewport:
            before.append(f"{modifier.name} ({modifier.type.title()})")
    if before:
        reasons.append(f"'{obj.name}' has modifiers before its Armature modifier: {', '.join(before)}")
    return reasons


def _moved_bones(armature_obj, size: float) -> list:
    """Names of bones whose current pose differs from their rest pose."""
    moved = []
    for pose_bone in armature_obj.pose.bones:
        pose = np.array([list(row) for row in pose_bone.matrix])
        rest = np.array([list(row) for row in pose_bone.bone.matrix_local])
        rotation_change = np.abs(pose[:3, :3] - rest[:3, :3]).max()
        translation_change = np.abs(pose[:3, 3] - rest[:3, 3]).max() / size
        if max(rotation_change, translation_change) > POSE_MATRIX_TOLERANCE:
            moved.append(pose_bone.name)
    return moved


def _largest_distance(moved: list, undeformed: np.ndarray, size: float) -> float:
    if any(positions is None for positions in moved):
        return float("inf")
    return float(np.linalg.norm(np.concatenate(moved) - undeformed, axis=1).max(initial=0.0)) / size


def bind_pose_error(armature_obj, mesh_objects: Sequence, measure_pose: bool = True) -> BindPoseCheck:
    """Measure whether the meshes deform to themselves (see the module docstring).

    Parameters
    ----------
    armature_obj : bpy.types.Object of type 'ARMATURE'
    mesh_objects : mesh objects it deforms
    measure_pose : bool
        Also measure the current pose (the file's default pose when loaded
        with :func:`load_default_pose`); False leaves ``pose_error`` NaN.

    Returns
    -------
    BindPoseCheck; the armature's pose position is restored afterwards.
    """
    if not mesh_objects:
        raise InputError(f"The armature '{armature_obj.name}' deforms no mesh, so there is nothing to check.")
    undeformed = np.concatenate([_world_vertices(obj, obj.data) for obj in mesh_objects])
    size = character_size(undeformed)
    reasons = [reason for obj in mesh_objects for reason in _mesh_reasons(obj)]
    with _only_modifiers_up_to_armature(mesh_objects):
        with rest_position(armature_obj):
            rest_error = _largest_distance([_evaluated_vertices(obj) for obj in mesh_objects], undeformed, size)
        pose_error = float("nan")
        if measure_pose:
            previous = armature_obj.data.pose_position
            armature_obj.data.pose_position = "POSE"
            bpy.context.view_layer.update()
            try:
                pose_error = _largest_distance([_evaluated_vertices(obj) for obj in mesh_objects], undeformed, size)
                moved = _moved_bones(armature_obj, size)
            finally:
                armature_obj.data.pose_position = previous
                bpy.context.view_layer.update()
            if pose_error > BIND_POSE_TOLERANCE and moved:
                reasons.append(
                    f"the default pose differs from the rest (bind) pose in {len(moved)} bones: {_listed(moved)}"
                )
    if np.isinf(rest_error) or np.isinf(pose_error):
        reasons.append("a modifier before the Armature modifier changes the vertex count, so positions cannot be compared")
    return BindPoseCheck(rest_error, pose_error, tuple(reasons), len(undeformed))


def _glb_without_animations(source: Path, target: Path) -> None:
    data = source.read_bytes()
    magic, version, _ = _GLB_HEADER.unpack_from(data, 0)
    if magic != _GLB_MAGIC:
        raise InputError(f"'{source.name}' is not a binary glTF file (bad magic number).")
    json_length, json_type = _GLB_CHUNK_HEADER.unpack_from(data, _GLB_HEADER.size)
    if json_type != _GLB_JSON_CHUNK:
        raise InputError(f"'{source.name}' does not start with a JSON chunk.")
    json_start = _GLB_HEADER.size + _GLB_CHUNK_HEADER.size
    document = json.loads(data[json_start:json_start + json_length].decode("utf-8"))
    document.pop("animations", None)
    text = json.dumps(document).encode("utf-8")
    text += b" " * (-len(text) % 4)
    rest = data[json_start + json_length:]
    total = _GLB_HEADER.size + _GLB_CHUNK_HEADER.size + len(text) + len(rest)
    target.write_bytes(
        _GLB_HEADER.pack(_GLB_MAGIC, version, total) + _GLB_CHUNK_HEADER.pack(len(text), _GLB_JSON_CHUNK) + text + rest
    )


def _gltf_without_animations(source: Path, target: Path) -> None:
    document = json.loads(source.read_text(encoding="utf-8"))
    document.pop("animations", None)
    # The copy lives elsewhere, so its relative references must point back.
    for collection in ("buffers", "images"):
        for item in document.get(collection, []):
            uri = item.get("uri", "")
            if uri and not uri.startswith("data:"):
                item["uri"] = _path_from(target.parent, source.parent / unquote(uri))
    target.write_text(json.dumps(document), encoding="utf-8")


def _path_from(folder: Path, path: Path) -> str:
    """``path`` relative to ``folder`` as a glTF URI (absolute across drives)."""
    try:
        return quote(Path(os.path.relpath(path.resolve(), folder.resolve())).as_posix())
    except ValueError:
        return quote(path.resolve().as_posix())


def load_default_pose(path: str | os.PathLike) -> bool:
    """Load a file with its skeleton in the file's default pose.

    glTF files are imported from a copy without animations (the importer
    would otherwise pose the skeleton at frame 0 of the first clip), FBX
    files without animation. Other formats load as they are.

    Returns
    -------
    bool: whether the format has a default pose apart from the rest pose
    (glTF and FBX do, ``.blend`` files do not).
    """
    path = Path(path)
    extension = path.suffix.lower()
    if extension in (".glb", ".gltf"):
        with tempfile.TemporaryDirectory(prefix="autorig_pose_") as folder:
            copy = Path(folder) / path.name
            (_glb_without_animations if extension == ".glb" else _gltf_without_animations)(path, copy)
            scene_io.load_scene(copy)
        return True
    if extension == ".fbx":
        if not path.is_file():
            raise InputError(f"The file '{path}' does not exist.")
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.import_scene.fbx(filepath=str(path.resolve()), use_anim=False)
        return True
    scene_io.load_scene(path)
    return False


def check_bind_pose(path: str | os.PathLike) -> BindPoseCheck:
    """Load ``path`` in its default pose and run :func:`bind_pose_error`
    on the armature :func:`choose_armature` picks (replaces the current scene)."""
    has_default_pose = load_default_pose(path)
    armature, meshes, _ = choose_armature()
    check = bind_pose_error(armature, meshes, measure_pose=has_default_pose)
    if has_default_pose and check.pose_error > BIND_POSE_TOLERANCE and Path(path).suffix.lower() in (".glb", ".gltf"):
        hint = "the joints' node transforms differ from the bind pose of the inverse bind matrices"
        check = replace(check, reasons=check.reasons + (hint,))
    return check


# --------------------------------------------------------------------------- simplification


def _scratch_object(mesh: Mesh):
    data = bpy.data.meshes.new(SCRATCH_NAME)
    data.vertices.add(mesh.vertex_count)
    data.vertices.foreach_set("co", mesh.vertices.astype(np.float32).ravel())
    triangle_count = len(mesh.triangles)
    data.loops.add(3 * triangle_count)
    data.loops.foreach_set("vertex_index", mesh.triangles.astype(np.int32).ravel())
    data.polygons.add(triangle_count)
    data.polygons.foreach_set("loop_start", np.arange(0, 3 * triangle_count, 3, dtype=np.int32))
    data.update(calc_edges=True)
    obj = bpy.data.objects.new(SCRATCH_NAME, data)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _remove_scratch(obj) -> None:
    data = obj.data
    bpy.data.objects.remove(obj, do_unlink=True)
    if data is not None and data.users == 0:
        bpy.data.meshes.remove(data)


def _decimated(obj, ratio: float, columns: Sequence[int]) -> tuple:
    modifier = obj.modifiers.get("Decimate") or obj.modifiers.new("Decimate", "DECIMATE")
    modifier.decimate_type = "COLLAPSE"
    modifier.use_collapse_triangulate = True
    modifier.ratio = float(min(max(ratio, 1e-4), 1.0))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    data = evaluated.to_mesh()
    try:
        count = len(data.vertices)
        positions = np.empty(count * 3, dtype=np.float32)
        data.vertices.foreach_get("co", positions)
        data.calc_loop_triangles()
        triangles = np.empty(len(data.loop_triangles) * 3, dtype=np.int32)
        data.loop_triangles.foreach_get("vertices", triangles)
        values = np.zeros((count, len(columns)), dtype=np.float32)
        for index, column in enumerate(columns):
            data.attributes[f"{WEIGHT_ATTRIBUTE_PREFIX}{column}"].data.foreach_get("value", values[:, index])
    finally:
        evaluated.to_mesh_clear()
    return positions.reshape(-1, 3).astype(np.float64), triangles.reshape(-1, 3).astype(np.int64), values


def simplify(mesh: Mesh, weights: Weights, target_vertices: int) -> tuple:
    """Resample a skinned mesh to about ``target_vertices`` vertices.

    Seams are welded first (:func:`weld_seams`). A welded mesh smaller than
    the target is first refined by midpoint subdivision
    (:func:`core.geometry.subdivision.subdivide_midpoints`, the shape is unchanged) until
    it is larger. Then Blender's Decimate modifier (COLLAPSE) runs with every
    bone's weights stored as a point attribute, which the collapse
    interpolates like positions, so each new vertex carries the weights of
    the surface it came from (no closest-point lookup that could jump
    between touching limbs). Rows are renormalised.

    Parameters
    ----------
    mesh : Mesh
    weights : Weights (n, b)
    target_vertices : int, at least :data:`core.dataset.MIN_TARGET_VERTICES`

    Returns
    -------
    mesh : Mesh, one object, within :data:`SIMPLIFY_COUNT_TOLERANCE` of the
        target (a welded mesh already that close is returned as it is)
    weights : Weights (n', b)
    """
    if target_vertices < dataset.MIN_TARGET_VERTICES:
        raise InputError(f"Simplify to at least {dataset.MIN_TARGET_VERTICES} vertices, not {target_vertices}.")
    welded, welded_weights = weld_seams(mesh, weights)
    if abs(welded.vertex_count - target_vertices) <= SIMPLIFY_COUNT_TOLERANCE * target_vertices:
        return welded, welded_weights
    vertices, triangles, matrix = welded.vertices, welded.triangles, welded_weights.matrix
    while len(vertices) < target_vertices:
        vertices, triangles, matrix = subdivide_midpoints(vertices, triangles, matrix)
    refined = Mesh(vertices, triangles, object_names=welded.object_names)
    columns = np.flatnonzero(matrix.max(axis=0) > 0.0)
    obj = _scratch_object(refined)
    try:
        for column in columns:
            attribute = obj.data.attributes.new(f"{WEIGHT_ATTRIBUTE_PREFIX}{column}", "FLOAT", "POINT")
            attribute.data.foreach_set("value", matrix[:, column].astype(np.float32))
        ratio = target_vertices / refined.vertex_count
        for _ in range(SIMPLIFY_MAX_STEPS):
            vertices, triangles, values = _decimated(obj, ratio, columns)
            if abs(len(vertices) - target_vertices) <= SIMPLIFY_COUNT_TOLERANCE * target_vertices:
                break
            ratio *= target_vertices / max(len(vertices), 1)
    finally:
        _remove_scratch(obj)
    result = np.zeros((len(vertices), matrix.shape[1]))
    result[:, columns] = values
    return Mesh(vertices, triangles, object_names=welded.object_names), Weights(normalize_rows(result), weights.bone_names)


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

    def load(path: Path, target: Optional[int]):
        name = dataset.relative_name(path, root)
        return load_simplified(path, target, name, dataset.category_of(name + path.suffix, split))

    return dataset.build_samples(paths, load, cache_dir, target_vertices, progress)


# --------------------------------------------------------------------------- Blender's bone heat


@contextlib.contextmanager
def _armature_with_tails(armature_obj, skeleton: Skeleton):
    """A temporary copy of ``armature_obj`` whose bones end at ``skeleton.tails``.

    Blender's bone heat diffuses from the armature's own bones, so they must
    be the bones measured with: the skeleton's tails (derived from the joints
    when the stored ones are point-like, ``core.skeleton.tails``) are set on
    a copy of the object and its armature data, so nothing of the loaded
    file changes. World-space tails go through the inverse of the
    armature's ``matrix_world``; heads stay as stored. Every bone of the copy
    is disconnected first, since a connected child's head follows its
    parent's tail (roll changes with the tail, which bone heat ignores).
    ``Bone.use_deform`` is set from ``skeleton.deform``. The copy is removed
    on leaving the block.
    """
    data = armature_obj.data.copy()
    rig = armature_obj.copy()
    rig.data = data
    rig.name = SCRATCH_NAME
    rig.animation_data_clear()
    bpy.context.scene.collection.objects.link(rig)
    try:
        rig.hide_viewport = False
        rig.hide_select = False
        rig.hide_set(False)
        if bpy.context.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        for obj in bpy.context.view_layer.objects:
            obj.select_set(False)
        rig.select_set(True)
        bpy.context.view_layer.objects.active = rig
        bpy.context.view_layer.update()
        inverse = np.linalg.inv(np.array([list(row) for row in armature_obj.matrix_world], dtype=np.float64))
        local_tails = skeleton.tails @ inverse[:3, :3].T + inverse[:3, 3]
        bpy.ops.object.mode_set(mode="EDIT")
        try:
            edit_bones = data.edit_bones
            for bone in edit_bones:
                bone.use_connect = False
            for name, tail in zip(skeleton.names, local_tails):
                bone = edit_bones.get(name)
                if bone is not None:
                    bone.tail = tail.tolist()
        finally:
            bpy.ops.object.mode_set(mode="OBJECT")
        wanted = dict(zip(skeleton.names, skeleton.deform.tolist()))
        for bone in data.bones:
            bone.use_deform = bool(wanted.get(bone.name, False))
        yield rig
    finally:
        if bpy.context.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        bpy.data.objects.remove(rig, do_unlink=True)
        if data.users == 0:
            bpy.data.armatures.remove(data)


def bone_heat_weights(mesh: Mesh, skeleton: Skeleton, armature_obj) -> Weights:
    """Blender's Automatic Weights (bone heat) on a copy of ``mesh``.

    Each object of ``mesh`` becomes a new mesh object built from the arrays
    alone, so no existing vertex group can leak in. Coincident vertices are
    welded first, as an artist runs Merge by Distance before Ctrl+P: bone
    heat fails ("failed to find solution for one or more bones") on meshes
    split at UV seams, which every glTF import is. Bone heat measures from
    the bones, so it runs against a temporary copy of the armature whose
    bones have ``skeleton.tails`` (:func:`_armature_with_tails`): with the
    point-like bones Blender's glTF importer makes for the Quaternius
    characters it scores L1 0.33 on the T-rex, with the derived tails of
    :func:`read_character` 0.055. The copies are parented to it with
    ``parent_set(type='ARMATURE_AUTO')`` in REST position, their weights
    read back onto the original vertices and every copy removed.

    Parameters
    ----------
    mesh : Mesh, world space, rest pose
    skeleton : Skeleton whose ``deform`` flags choose the bones that get
        weights and whose ``tails`` end the bones (world space)
    armature_obj : bpy.types.Object of type 'ARMATURE', with bones named as
        in ``skeleton``; never changed

    Returns
    -------
    Weights (n, d) over the deform bones; rows of vertices bone heat left
    unweighted (it still fails on some meshes) are zero. Not renormalised.
    """
    deform_names = skeleton.deform_subset().names
    parts, to_welded = weld_objects(mesh)
    with _armature_with_tails(armature_obj, skeleton) as rig:
        copies = []
        try:
            copies.extend(_scratch_object(part) for part in parts)
            with rest_position(rig):
                for obj in bpy.context.view_layer.objects:
                    obj.select_set(False)
                for copy in copies:
                    copy.select_set(True)
                rig.select_set(True)
                bpy.context.view_layer.objects.active = rig
                try:
                    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
                except RuntimeError as error:
                    raise InputError(f"Blender's Automatic Weights failed: {error}") from None
                matrix = np.concatenate([convert.read_group_weights(copy, deform_names) for copy in copies])
        finally:
            for copy in copies:
                _remove_scratch(copy)
    return Weights(matrix[to_welded], deform_names)
