"""Skin weights as a job: settings, and the plain functions the Skin and
Auto-Rig operators and the command line run, for meshes and any armature,
by the geometric method or a trained network (``core.skinning.methods``).

As with transfer, nothing is written before everything is computed:

1. :func:`plan_skin` checks the armature and meshes and reads them once,
2. :func:`compute_skin` runs the core method (no ``bpy``: safe in a thread,
   :class:`SkinJob`),
3. :func:`write_skin` writes every mesh, restoring all of them if any
   write fails.

What the plan does with props parented to a bone or held (Auto-Rig), helper
objects, linked duplicates and stray vertices: :mod:`..object_roles` and
:mod:`autorig_addon.core.geometry.outliers`; each is named in the report.
The weights are computed on the shape the Armature modifier deforms, a
Mirror modifier's mirrored half included (:mod:`..modifier_stack`), and
the artist's own groups that share a bone's name are kept under a new name
(:mod:`..artist_groups`).
"""

from __future__ import annotations

from contextlib import ExitStack
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ...core.errors import InputError
from ...core.geometry.outliers import require_finite_positions, rows_for_strays
from ...core.geometry.outward_faces import inward_faces_note, outward_mesh
from ...core.messages import listed_names
from ...core.progress import ProgressCallback
from ...core.rigging.props import held_note, holding_bone, piece_text
from ...core.skeleton.tails import TailDecision, with_reliable_tails
from ...core.skinning.methods import SKIN_METHOD_LABELS, check_skin_method, skin_weights
from ...core.skinning.options import SkinningOptions
from ...core.types import Mesh, Skeleton, Weights
from .. import convert
from ..artist_groups import artist_group_renames, renamed_artist_groups, renames_note
from ..modifier_stack import REST_SHAPE_TYPES, binding_place, kept_armature_modifier, vertex_adders
from ..object_roles import (
    give_own_mesh,
    held_binding,
    left_rigid_note,
    shared_mesh_notes,
    split_bone_parented,
    without_helpers,
)
from ..snapshot import restored_on_failure
from ..weight_writer import bind_to_bone, write_weights
from .input_checks import check_mode, split_strays, stray_notes
from .worker_job import WorkerJob

#: When even the deform bone point nearest the mesh's bounding box is
#: farther than this many mesh diagonals from it, the armature was not
#: placed on the character.
MAX_ARMATURE_OFFSET = 0.5
#: The vertices a Mirror modifier (or another before the Armature
#: modifier) adds follow the wrong bones when, for a
#: bone, the weight they get from the modifier's groups and the weight
#: computed for them differ by more than this share of the larger (a left
#: bone the modifier does not swap for its right twin: about 1; a symmetric
#: skin: up to 0.3 measured, the networks' weights being nearly symmetric) ...
MAX_ADDED_BONE_MISMATCH = 0.6
#: ... counting only bones whose weight there sums to more than this share of those vertices.
MIN_ADDED_BONE_SHARE = 0.01


@dataclass(frozen=True)
class SkinSettings:
    """Everything a skinning run needs besides the objects: the core's
    options and how the result is written.

    Attributes
    ----------
    options : core.skinning.options.SkinningOptions (the method and its settings)
    replace_all : bool, remove every existing vertex group first
    """

    options: SkinningOptions = SkinningOptions()
    replace_all: bool = False

    @property
    def method_label(self) -> str:
        """The method's name as the reports say it ("HeterSkinNet")."""
        return SKIN_METHOD_LABELS[self.options.method]


@dataclass
class SkinPlan:
    """Checked inputs: the armature, the meshes and their arrays.

    ``skeleton`` holds the tails distances are measured along: the
    armature's own, or tails derived from the joints where its bones are
    point-like (``core.skeleton.tails.with_reliable_tails``; the armature
    itself is never changed). ``tail_decision`` says which and why.

    Attributes
    ----------
    armature : bpy.types.Object
    meshes : list of bpy.types.Object, the meshes skinned together
    mesh : Mesh of ``meshes`` (None when there are none): the shape their
        Armature modifiers deform, the vertices a Mirror modifier adds after
        each object's own (``rest``)
    skeleton : Skeleton
    settings : SkinSettings
    tail_decision : TailDecision
    strays : (n,) bool array over ``mesh``'s vertices, far strays left out of
        the computation and weighted like their nearest kept vertex
        (``core.geometry.outliers``), or None
    solved : Mesh the weights are computed on: ``mesh`` without ``strays`` and ``left_out``
    rigid : list of RigidBinding, props bound wholly to the bone they were parented to or that holds them
    notes : list of str, what the report adds about them, linked duplicates, props left rigid,
        the Armature modifier's place and the artist's groups kept
    rest : convert.RestShape or None, how ``mesh``'s rows map to each object's own vertices
    renames : list of dict, per mesh the artist's groups to keep under a new name (``artist_groups``)
    left_out : (n,) bool array over ``mesh``'s vertices or None, vertices left unweighted
        (Auto-Rig: what is not the character, ``core.rigging.character_parts``)
    held_pieces : tuple of ((k,) int array, int): props joined into the meshes (Auto-Rig,
        ``core.rigging.props``), their rows in ``mesh`` and the deform bone (its weight column) that holds
        them; left out of the computation and weighted wholly to that bone
    """

    armature: object
    meshes: list
    mesh: Mesh | None
    skeleton: Skeleton
    settings: SkinSettings
    tail_decision: TailDecision = TailDecision()
    strays: np.ndarray | None = None
    solved: Mesh | None = None
    rigid: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    rest: convert.RestShape | None = None
    renames: list = field(default_factory=list)
    left_out: np.ndarray | None = None
    held_pieces: tuple = ()

    @property
    def summary(self) -> str:
        """What the report adds to "Skinned ...": the derived tails, if any, and the notes."""
        text = f" ({self.tail_decision.note})" if self.tail_decision.any_derived else ""
        return text + "".join(f"; {note}" for note in self.notes)


def _check_skeleton_fits_mesh(skeleton: Skeleton, mesh: Mesh, armature_name: str) -> None:
    size = mesh.bounding_box_diagonal
    lo, hi = mesh.vertices.min(0), mesh.vertices.max(0)
    points = np.vstack([skeleton.joints, skeleton.tails])
    outside = np.maximum(lo - points, 0) + np.maximum(points - hi, 0)
    if np.linalg.norm(outside, axis=1).min() > MAX_ARMATURE_OFFSET * size:
        raise InputError(
            f"The armature '{armature_name}' lies far from the mesh: move it onto the character "
            "(or apply the object transforms) before skinning."
        )


def plan_skin(armature, meshes: list, settings: SkinSettings, depsgraph, *, named: bool = True,
              left_out: np.ndarray | None = None, held: Sequence = (), held_pieces: Sequence = ()) -> SkinPlan:
    """Read and check the inputs; raises :class:`InputError` on bad input.

    Parameters
    ----------
    armature : bpy.types.Object
    meshes : list of bpy.types.Object
    settings : SkinSettings
    depsgraph : bpy.types.Depsgraph
    named : bool
        True when the user named or selected ``meshes``; False when the run
        picked them itself (every mesh of a file): helper objects are then
        left out and props on a bone left rigid.
    left_out : (n,) bool array or None, vertices of the meshes' rest shape (their
        rows in ``SkinPlan.mesh``) to leave unweighted: the pieces Auto-Rig
        found not to be the character (a ground plane, a stray speck). Their
        Armature modifier leaves them where they are.
    held : sequence of (bpy.types.Object, (3,) array): props Auto-Rig found
        the character holds, not among ``meshes``, and their grip (world
        space, ``core.rigging.props``): each is bound wholly to the deform
        bone nearest to its grip.
    held_pieces : sequence of ((k,) int array, (3,) array): props Auto-Rig
        found joined into ``meshes``, their rows in the rest shape and their
        grip: each is weighted wholly to the deform bone nearest to its grip.
    """
    check_skin_method(settings.options.method)
    convert.require_armature_object(armature)
    meshes = list(dict.fromkeys(meshes))
    found = meshes
    if not named:
        meshes = without_helpers(meshes)
    if not meshes and found:
        raise InputError(
            f"Nothing to skin: the meshes found ({listed_names([obj.name for obj in found], quoted=True)}) are helpers "
            "(bone shapes, hidden from render). Name the meshes to skin them: --mesh on the command line, "
            "meshes= from Python."
        )
    if not meshes:
        raise InputError("Select the mesh(es) to skin together with the armature.")
    check_mode(armature, "skin")
    for obj in meshes:
        convert.require_mesh_object(obj, "mesh to skin")
        check_mode(obj, "skin")
    skeleton = convert.read_skeleton(armature)
    if not skeleton.deform.any():
        raise InputError(f"The armature '{armature.name}' has no deform bones: enable Deform on the bones to weight.")
    meshes, rigid, left_rigid = split_bone_parented(meshes, armature, named)
    rigid += [held_binding(obj, armature, grip, skeleton) for obj, grip in held]
    # Named props left rigid sit on a bone that does not deform.
    notes = [f"'{obj.name}' {left_rigid_note(obj)}" + (" (it does not deform)" if named else "") for obj in left_rigid]
    notes += [f"'{binding.obj.name}' {binding.note}" for binding in rigid]
    if not meshes and not rigid:
        raise InputError(f"Nothing to skin: {'; '.join(notes)}.")
    notes += [f"'{obj.name}' {note}" for obj, note in shared_mesh_notes(meshes + [b.obj for b in rigid]).items()]
    if not meshes:
        return SkinPlan(armature, [], None, skeleton, settings, rigid=rigid, notes=notes)
    places = [binding_place(obj, armature) for obj in meshes]
    rest = convert.read_rest_shape(meshes, places, depsgraph)
    mesh = rest.mesh
    require_finite_positions(mesh.vertices, mesh.object_names, mesh.object_offsets)
    notes += [note for obj, place in zip(meshes, places) if (note := _placement_note(obj, armature, place))]
    written = [name for name, deform in zip(skeleton.names, skeleton.deform) if deform]
    renames = [{} if settings.replace_all else artist_group_renames(obj, written, armature) for obj in meshes]
    notes += [renames_note(obj.name, renamed) for obj, renamed in zip(meshes, renames) if renamed]
    if left_out is not None and len(left_out) != mesh.vertex_count:
        raise InputError(f"{listed_names([obj.name for obj in meshes], quoted=True)} changed while being rigged: "
                         "run it again.")
    deform_names = [name for name, deform in zip(skeleton.names, skeleton.deform) if deform]
    if any(len(rows) == 0 or int(np.max(rows)) >= mesh.vertex_count for rows, _ in held_pieces):
        raise InputError(f"{listed_names([obj.name for obj in meshes], quoted=True)} changed while being rigged: "
                         "run it again.")
    pieces = []
    for rows, grip in held_pieces:
        bone = holding_bone(grip, skeleton)
        pieces.append((np.asarray(rows, dtype=np.int64), deform_names.index(bone)))
        owner = mesh.object_names[int(np.searchsorted(mesh.object_offsets, rows[0], side="right") - 1)]
        notes.append(f"'{owner}': {piece_text(len(rows))} {held_note(bone)}")
    excluded = left_out
    if pieces:
        excluded = np.zeros(mesh.vertex_count, dtype=bool) if left_out is None else left_out.copy()
        for rows, _ in pieces:
            excluded[rows] = True
    solved, strays = split_strays(mesh, excluded)
    if solved.bounding_box_diagonal <= 0:
        raise InputError("The mesh has zero size.")
    if strays is not None:
        notes += [f"'{name}': {note}" for name, note in stray_notes(mesh, strays, "the distances").items()]
    # The core turns them itself (``skin_weights``); the report says so.
    inward = outward_mesh(solved)[1]
    if inward.any():
        notes.append(inward_faces_note(int(inward.sum()), "the skinning"))
    # Point-like bones (glTF imports of scaled armatures) get tails derived
    # from the joints; a zero-length deform bone with no child is refused.
    skeleton, tail_decision = with_reliable_tails(skeleton, solved.bounding_box_diagonal)
    _check_skeleton_fits_mesh(skeleton.deform_subset(), solved, armature.name)
    return SkinPlan(armature, meshes, mesh, skeleton, settings, tail_decision, strays, solved, rigid, notes,
                    rest, renames, left_out, tuple(pieces))


def _placement_note(obj, armature, place: int) -> str:
    """What the report says when a new Armature modifier goes after modifiers
    that shape the rest pose ("" when the mesh keeps its own or none come before)."""
    if kept_armature_modifier(obj, armature) is not None:
        return ""
    before = [modifier.name for modifier in list(obj.modifiers)[:place] if modifier.type in REST_SHAPE_TYPES]
    if not before:
        return ""
    return (f"'{obj.name}': the Armature modifier goes after {listed_names(before, quoted=True)}, so posing deforms "
            "the shape the weights were computed on")


def compute_skin(plan: SkinPlan, progress: ProgressCallback | None = None) -> Weights:
    """(n, deform bones) weights for every vertex of every mesh; no ``bpy``.
    Far strays are left out of the computation and take the weights of the
    nearest kept vertex (``core.geometry.outliers.rows_for_strays``); the
    plan's ``left_out`` vertices get rows of zeros, its ``held_pieces`` a 1
    on the bone holding them."""
    if plan.mesh is None:
        names = tuple(name for name, deform in zip(plan.skeleton.names, plan.skeleton.deform) if deform)
        return Weights(np.zeros((0, len(names))), names)
    weights = skin_weights(plan.solved, plan.skeleton, plan.settings.options, progress=progress)
    if plan.strays is None and plan.left_out is None and not plan.held_pieces:
        return weights
    left_out = plan.left_out if plan.left_out is not None else np.zeros(plan.mesh.vertex_count, dtype=bool)
    strays = plan.strays if plan.strays is not None else np.zeros(plan.mesh.vertex_count, dtype=bool)
    held = np.zeros(plan.mesh.vertex_count, dtype=bool)
    for piece, _ in plan.held_pieces:
        held[piece] = True
    rows = rows_for_strays(weights.matrix, plan.mesh.vertices, plan.mesh.triangles, strays | left_out | held)
    rows[left_out] = 0.0
    for piece, column in plan.held_pieces:
        rows[piece] = 0.0
        rows[piece, column] = 1.0
    return Weights(rows, weights.bone_names)


def write_skin(plan: SkinPlan, weights: Weights) -> None:
    """Write each mesh's own rows, keeping the artist's groups that share a
    bone's name under a new name, and bind the props on a bone to it; on any
    failure every object is restored. Linked duplicates get their own mesh
    first. A mesh whose modifiers before the Armature modifier add vertices
    (a Mirror) is checked once written: the groups they give the added
    vertices must hold the weights computed for them
    (:func:`_check_added_vertices`)."""
    with restored_on_failure(plan.meshes + [binding.obj for binding in plan.rigid]), ExitStack() as renamed:
        for index, obj in enumerate(plan.meshes):
            give_own_mesh(obj)
            renamed.enter_context(renamed_artist_groups(obj, plan.renames[index]))
            added = plan.rest.added_count(index)
            # A Mirror modifier gives a copy the mirrored bone's group only when that group exists.
            write_weights(obj, Weights(weights.matrix[plan.rest.own_rows(index)], weights.bone_names), plan.armature,
                          replace_all=plan.settings.replace_all, every_bone=added > 0)
            if added:
                computed = weights.matrix[plan.mesh.object_slice(index)]
                _check_added_vertices(obj, plan.armature, computed, weights.bone_names, plan.rest.own_counts[index])
        for binding in plan.rigid:
            give_own_mesh(binding.obj)
            bind_to_bone(binding.obj, binding.armature, binding.bone, binding.rest_world)


def _check_added_vertices(obj, armature, computed: np.ndarray, bone_names, own_count: int) -> None:
    """Refuse (:class:`InputError`) a mesh whose Armature modifier would
    give the vertices the modifiers before it add (a Mirror's copies) other
    bones than ``computed`` (all of its rows, own first), bone by bone: read
    back what the modifier receives, the groups those modifiers gave them."""
    place = list(obj.modifiers).index(kept_armature_modifier(obj, armature))
    received = convert.read_rest_group_weights(obj, place, bone_names)[own_count:]
    if len(received) + own_count != len(computed):
        raise InputError(f"'{obj.name}' changed while it was being weighted: run the skinning again.")
    totals = received.sum(axis=1, keepdims=True)
    received = np.divide(received, totals, out=np.zeros_like(received), where=totals > 0)
    received_sums, computed_sums = received.sum(axis=0), computed[own_count:].sum(axis=0)
    larger = np.maximum(received_sums, computed_sums)
    wrong = (larger > MIN_ADDED_BONE_SHARE * len(received)) \
        & (np.abs(received_sums - computed_sums) > MAX_ADDED_BONE_MISMATCH * larger)
    if not wrong.any():
        return
    adders = vertex_adders(obj, place)
    names = listed_names([modifier.name for modifier in adders], quoted=True)
    bones = listed_names([name for name, off in zip(bone_names, wrong) if off], quoted=True)
    mirrors = [modifier for modifier in adders if modifier.type == "MIRROR"]
    if not all(modifier.use_mirror_vertex_groups for modifier in mirrors):
        fix = f"turn on the Vertex Groups option of {names} (under Data), or apply it first (Ctrl+A)"
    elif mirrors:
        fix = (f"{names} swaps only the vertex groups whose names end in .L/.R or say left/right: apply it first "
               "(Ctrl+A)")
    else:
        fix = f"move the Armature modifier above {names}, or apply {names} first (Ctrl+A)"
    raise InputError(
        f"'{obj.name}': the vertices its modifier {names} adds would follow the wrong bones (their weights "
        f"for {bones} differ from those computed for them): {fix}."
    )


@dataclass
class SkinJob(WorkerJob):
    """A skinning computation (:func:`compute_skin` of ``plan``) run by a
    worker thread for the modal operator; the weights are ``weights``."""

    plan: SkinPlan
    cancelled_message = "Skinning cancelled."

    def compute(self, progress: ProgressCallback) -> Weights:
        return compute_skin(self.plan, progress)

    @property
    def weights(self) -> Weights | None:
        """The computed weights (None until the worker finishes, or when it failed)."""
        return self.result


def run_skin(armature, meshes: list, settings: SkinSettings, depsgraph, progress: ProgressCallback | None = None,
             *, named: bool = True) -> tuple[SkinPlan, Weights]:
    """Plan, compute and write a skinning run on this thread; nothing is
    written on error. ``named``: see :func:`plan_skin`. Returns the plan and
    the weights written."""
    plan = plan_skin(armature, meshes, settings, depsgraph, named=named)
    weights = compute_skin(plan, progress)
    write_skin(plan, weights)
    return plan, weights


def skin_report(plan: SkinPlan, weights: Weights) -> str:
    """What a finished run says: "Skinned 2 mesh(es) to 24 deform bones of 'Rig' with HeterSkinNet ..."."""
    return (f"Skinned {len(plan.meshes)} mesh(es) to {weights.matrix.shape[1]} deform bones of "
            f"'{plan.armature.name}' with {plan.settings.method_label}{plan.summary}.")
