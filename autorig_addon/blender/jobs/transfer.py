"""Weight transfer as a job: settings, and the plain functions the operator
and the command line run.

The work is split so nothing is written before everything is computed:

1. :func:`plan_transfer` checks the objects and reads the source once,
2. :func:`compute_transfer` runs the core transfer for every target,
3. :func:`write_transfer` writes all targets, restoring every one of them
   if any write fails.

Props parented to a bone, helper objects, linked duplicates and stray
vertices: :mod:`..object_roles` and :mod:`autorig_addon.core.geometry.outliers`;
each target's line of the report says what happened to it. Which objects a
transfer runs on: :mod:`..selection`. What each exception means:
:mod:`autorig_addon.core.errors`.
"""

from dataclasses import dataclass, field

import numpy as np

from ...core.errors import InputError
from ...core.geometry.outliers import require_finite_positions, rows_for_strays
from ...core.messages import listed_names
from ...core.progress import ProgressCallback, report, sub_progress
from ...core.transfer.combine import (
    DEFAULT_MIX_FACTOR,
    DEFAULT_REPLACE_MODE,
    REPLACE_ALL,
    check_write_mode,
    combine_with_existing,
    keep_existing_where_empty,
    needs_existing_weights,
)
from ...core.transfer.options import GROUP_MEMBER_THRESHOLD, TransferOptions
from ...core.transfer.source import TransferSource
from ...core.transfer.transfer import VertexStatus, transfer_weights
from ...core.types import Mesh, Weights
from ...core.weights import normalize_rows
from .. import convert
from ..armature_binding import bone_parent, find_armature
from ..object_roles import (
    RigidBinding,
    give_own_mesh,
    left_rigid_note,
    shared_mesh_notes,
    split_bone_parented,
    without_helpers,
)
from ..snapshot import restored_on_failure
from ..status_attribute import write_status_attribute
from ..weight_writer import bind_to_bone, write_weights
from .input_checks import check_mode, split_strays, stray_notes


@dataclass(frozen=True)
class TransferSettings:
    """Everything a transfer needs besides the objects: the core's options
    and what only the Blender layer knows (vertex groups, bones, write mode).

    Attributes
    ----------
    options : core.transfer.options.TransferOptions
    mask_group : str, target vertex group forcing inpainting ("" = none)
    protect_group : str, target vertex group keeping its weights ("" = none)
    bones : tuple of str or None, bones to transfer (None = every deform bone)
    replace_mode : one of ``core.transfer.combine.REPLACE_MODES``
    mix_factor : float in [0, 1], used by ``MIX``
    """

    options: TransferOptions = TransferOptions()
    mask_group: str = ""
    protect_group: str = ""
    bones: tuple | None = None
    replace_mode: str = DEFAULT_REPLACE_MODE
    mix_factor: float = DEFAULT_MIX_FACTOR


@dataclass
class TransferPlan:
    """Checked inputs of a transfer: the objects and the source data.

    Attributes
    ----------
    source : bpy.types.Object (mesh)
    targets : list of bpy.types.Object (meshes)
    armature : bpy.types.Object (armature deforming the source)
    bone_names : tuple of b str, the source's deform bones, column order
    transferred_bones : tuple of str, the subset whose weights are written
    source_data : TransferSource, the source's mesh without far stray vertices
        (``core.geometry.outliers``) and its weights raw as stored (the core
        skips unusable rows), checked and indexed once for every target
    settings : TransferSettings
    rigid : list of RigidBinding, props on a bone bound wholly to it instead
    left_rigid : list of bpy.types.Object, props on a bone left as they are
    notes : dict object -> list of str, what each target's report line adds
        (its own mesh for a linked duplicate, strays of the source)
    """

    source: object
    targets: list
    armature: object
    bone_names: tuple
    transferred_bones: tuple
    source_data: TransferSource
    settings: TransferSettings
    rigid: list = field(default_factory=list)
    left_rigid: list = field(default_factory=list)
    notes: dict = field(default_factory=dict)


@dataclass
class TargetOutcome:
    """Computed result for one target, not yet written.

    Attributes
    ----------
    target : bpy.types.Object
    weights : Weights (n_target, b), the final weights to write, or None
        for a prop left rigid on its bone (nothing is written)
    status : (n_target,) int8 array of ``VertexStatus``, or None (no status colours)
    summary : str
    rigid : RigidBinding or None, for a prop bound wholly to its bone
    """

    target: object
    weights: Weights | None
    status: np.ndarray | None
    summary: str
    timings: dict = field(default_factory=dict)
    rigid: RigidBinding | None = None


def _transferred_bones(settings: TransferSettings, bone_names: tuple, armature) -> tuple:
    if settings.bones is None:
        return bone_names
    requested = tuple(dict.fromkeys(settings.bones))
    if not requested:
        raise InputError(f"No bones chosen: select pose bones of '{armature.name}' or transfer all deform bones.")
    unknown = [name for name in requested if name not in bone_names]
    if unknown:
        raise InputError(
            f"{', '.join(unknown)}: not deform bones of '{armature.name}'. "
            f"Deform bones: {', '.join(bone_names[:20])}{' ...' if len(bone_names) > 20 else ''}."
        )
    return requested


def plan_transfer(source, targets: list, settings: TransferSettings, depsgraph, *, named: bool = True) -> TransferPlan:
    """Check the objects and read the source.

    Parameters
    ----------
    source : bpy.types.Object, skinned mesh
    targets : list of bpy.types.Object, meshes to weight
    settings : TransferSettings
    depsgraph : bpy.types.Depsgraph
    named : bool
        True when the user named or selected ``targets``; False when the run
        picked them itself (``selection.unbound_meshes``): helper objects are then
        left out and props on a bone left rigid.

    Raises
    ------
    InputError for: a non-mesh source or target, the source among the
    targets, objects in Edit or Sculpt Mode, a source with no armature or
    no weights on its deform bones, vertices at infinite positions, a prop
    parented to a bone of another armature, unknown bones, bad settings.
    """
    check_write_mode(settings.replace_mode, settings.mix_factor)
    convert.require_mesh_object(source, "source")
    check_mode(source, "transfer")
    targets = list(dict.fromkeys(targets))
    if not named:
        targets = without_helpers(targets)
    for target in targets:
        convert.require_mesh_object(target, "target")
        if target == source:
            raise InputError(f"'{source.name}' is both the source and a target: pick a different mesh to weight.")
        check_mode(target, "transfer")
    armature = find_armature(source)
    bone_names = convert.deform_bone_names(armature)
    if not bone_names:
        raise InputError(f"The armature '{armature.name}' has no bones with Deform enabled.")
    targets, rigid, left_rigid = split_bone_parented(targets, armature, named)
    if not targets and not rigid:
        if not left_rigid:
            raise InputError("Nothing to weight: the other meshes are helpers (bone shapes, hidden from render). "
                             "Name the meshes to weight them.")
        props = listed_names([f"'{obj.name}' (bone '{bone_parent(obj)}')" for obj in left_rigid])
        one = len(left_rigid) == 1
        raise InputError(f"Nothing to weight: {props} {'is' if one else 'are'} left rigid on "
                         f"{'its bone' if one else 'their bones'}. Name the meshes to weight them.")
    source_weights = convert.read_weights(source, bone_names)
    # NaN weights (which vertex groups can hold) are not a naming problem:
    # the core's TransferSource.prepare says what is wrong with them.
    if not np.any(source_weights.matrix > 0) and not np.isnan(source_weights.matrix).any():
        raise InputError(
            f"'{source.name}' has no weights for the deform bones of '{armature.name}': "
            "its vertex groups must be named after the bones. Skin it first."
        )
    source_mesh = convert.read_mesh([source], depsgraph)
    require_finite_positions(source_mesh.vertices, source_mesh.object_names, source_mesh.object_offsets)
    kept_source, source_strays = split_strays(source_mesh)
    notes = {obj: [note] for obj, note in shared_mesh_notes(targets + [b.obj for b in rigid]).items()}
    if source_strays is not None:
        (source_note,) = stray_notes(source_mesh, source_strays, "the matching", reweighted=False).values()
        for target in targets:
            notes.setdefault(target, []).append(f"source '{source.name}': {source_note}")
        source_weights = Weights(source_weights.matrix[~source_strays], bone_names)
        source_mesh = kept_source
    return TransferPlan(
        source=source,
        targets=targets,
        armature=armature,
        bone_names=bone_names,
        transferred_bones=_transferred_bones(settings, bone_names, armature),
        # Raw weights: the core never copies rows without usable weights (none, NaN) and reports them.
        source_data=TransferSource.prepare(source_mesh, source_weights),
        settings=settings,
        rigid=rigid,
        left_rigid=left_rigid,
        notes=notes,
    )


def _transfer_without_strays(plan: TransferPlan, target_mesh: Mesh, inpaint_mask, protected, existing: Weights,
                             progress: ProgressCallback | None):
    """The core transfer onto ``target_mesh`` with its far strays left out:
    (weights (n, b) in ``plan.bone_names`` order, status (n,), summary, timings,
    stray mask or None). Strays take the weights of their nearest kept vertex
    (protected strays keep theirs) and the status of a part with no match."""
    kept_mesh, strays = split_strays(target_mesh)
    keep = slice(None) if strays is None else ~strays

    def subset(mask):
        return None if mask is None else mask[keep]

    result = transfer_weights(
        plan.source_data.mesh,
        plan.source_data.weights,
        kept_mesh,
        plan.settings.options,
        inpaint_mask=subset(inpaint_mask),
        protected=subset(protected),
        protected_weights=Weights(existing.matrix[keep], existing.bone_names) if protected is not None else None,
        progress=progress,
        prepared=plan.source_data,
    )
    same_order = result.weights.bone_names == plan.bone_names
    incoming = result.weights.matrix if same_order else result.weights.select_bones(plan.bone_names).matrix
    status = np.asarray(result.status)
    if strays is not None:
        incoming = rows_for_strays(incoming, target_mesh.vertices, target_mesh.triangles, strays)
        if protected is not None:
            kept_rows = strays & protected
            incoming[kept_rows] = normalize_rows(existing.matrix[kept_rows])
        full_status = np.full(len(strays), VertexStatus.UNMATCHED_PART, dtype=status.dtype)
        full_status[~strays] = status
        status = full_status
    return incoming, status, result.summary(), dict(result.timings), strays


def _compute_one(plan: TransferPlan, target, depsgraph, progress: ProgressCallback | None) -> TargetOutcome:
    settings = plan.settings
    target_mesh = convert.read_mesh([target], depsgraph)
    require_finite_positions(target_mesh.vertices, target_mesh.object_names, target_mesh.object_offsets)
    inpaint_mask = convert.vertex_group_mask(target, settings.mask_group, GROUP_MEMBER_THRESHOLD)
    protected = convert.vertex_group_mask(target, settings.protect_group, GROUP_MEMBER_THRESHOLD)
    reads_existing = protected is not None or needs_existing_weights(
        settings.replace_mode, len(plan.transferred_bones), len(plan.bone_names))
    if reads_existing:
        existing = convert.read_weights(target, plan.bone_names)
    else:
        existing = Weights(np.zeros((len(target.data.vertices), len(plan.bone_names))), plan.bone_names)
    incoming, status, summary, timings, strays = _transfer_without_strays(
        plan, target_mesh, inpaint_mask, protected, existing, progress)
    column_of = {name: k for k, name in enumerate(plan.bone_names)}
    columns = np.array([column_of[name] for name in plan.transferred_bones], dtype=np.int64)
    final = combine_with_existing(existing.matrix, incoming, columns, settings.replace_mode, settings.mix_factor,
                                  settings.options.max_influences)
    final, unweighted = keep_existing_where_empty(final, existing.matrix)
    if unweighted.any():
        raise InputError(
            f"{int(np.count_nonzero(unweighted))} vertices of '{target.name}' get no weight from the chosen bones: "
            "transfer all bones or select the bones that cover them."
        )
    notes = list(plan.notes.get(target, []))
    if strays is not None:
        notes += list(stray_notes(target_mesh, strays, "the transfer").values())
    summary += "".join(f"; {note}" for note in notes)
    return TargetOutcome(target, Weights(final, plan.bone_names), status, summary, timings)


def compute_transfer(plan: TransferPlan, depsgraph, progress: ProgressCallback | None = None) -> list[TargetOutcome]:
    """Run the core transfer for every target of ``plan``; writes nothing.
    Props on a bone get an outcome saying what happens to them (bound
    wholly to it, or left rigid) and no transfer."""
    outcomes = []
    count = len(plan.targets)
    for index, target in enumerate(plan.targets):
        report(progress, index / count, f"Weighting '{target.name}'")
        target_progress = sub_progress(progress, index / count, (index + 1) / count)
        outcomes.append(_compute_one(plan, target, depsgraph, target_progress))
    for binding in plan.rigid:
        summary = binding.note + "".join(f"; {note}" for note in plan.notes.get(binding.obj, []))
        outcomes.append(TargetOutcome(binding.obj, None, None, summary, rigid=binding))
    for obj in plan.left_rigid:
        outcomes.append(TargetOutcome(obj, None, None, left_rigid_note(obj)))
    report(progress, 1.0, "Done")
    return outcomes


def write_transfer(plan: TransferPlan, outcomes: list[TargetOutcome]) -> None:
    """Write weights, binding and status colours of every outcome (a prop
    bound to its bone gets that bone's group and no status colours; one left
    rigid is not touched). Linked duplicates get their own mesh first.

    All-or-nothing over all targets: if any write fails, every target is
    restored and the exception re-raised.
    """
    written = [outcome for outcome in outcomes if outcome.weights is not None or outcome.rigid is not None]
    with restored_on_failure([outcome.target for outcome in written]):
        for outcome in written:
            give_own_mesh(outcome.target)
            if outcome.rigid is not None:
                binding = outcome.rigid
                bind_to_bone(binding.obj, binding.armature, binding.bone, binding.rest_world)
                continue
            write_weights(
                outcome.target, outcome.weights, plan.armature,
                replace_all=plan.settings.replace_mode == REPLACE_ALL,
                keep_groups=[name for name in (plan.settings.mask_group, plan.settings.protect_group) if name],
            )
            write_status_attribute(outcome.target, outcome.status)


def outcome_report(outcomes: list[TargetOutcome]) -> str:
    """One line summing up the outcomes, e.g. "Sleeve: 120 copied, 30 inpainted (20%)"."""
    return "; ".join(f"{outcome.target.name}: {outcome.summary}" for outcome in outcomes)


def run_transfer(source, targets: list, settings: TransferSettings, depsgraph, progress: ProgressCallback | None = None,
                 *, named: bool = True) -> list[TargetOutcome]:
    """Plan, compute and write a transfer; nothing is written on error.
    ``named``: see :func:`plan_transfer`."""
    plan = plan_transfer(source, targets, settings, depsgraph, named=named)
    outcomes = compute_transfer(plan, depsgraph, progress)
    write_transfer(plan, outcomes)
    return outcomes
