"""Skeleton prediction as a job: an armature predicted from a character's
meshes (``core.rigging.predict``), and the same bound with skin weights
(Auto-Rig), for the Predict Skeleton and Auto-Rig operators and the ``rig``
command.

The work is written as a sequence of steps (:func:`plan_rig_steps`, then
:func:`rig_steps`, chained by :func:`planned_rig_steps`): generators that
yield the slow, ``bpy``-free parts (telling what the hands hold, the joint
network, the skin weights) as tasks and do the Blender parts themselves
between them. The modal operators run each task in a worker thread
(:class:`TaskJob`; progress in the status bar, Esc cancels); background runs
and the ``rig`` command run the same steps on the main thread
(:func:`run_steps`). A failure or a
cancel anywhere removes the armature and restores every mesh, so nothing
is ever left half built.

Live level of detail: the network outputs of each prediction stay in memory
(:data:`_PREDICTIONS`, keyed by a token stored on the armature as the custom
property :data:`PREDICTED_PROPERTY`). While that armature is what the
prediction built (its rest bones unchanged, not in Edit Mode, nothing
bound to or carried by it: ``armature_binding.followers``, no linked
duplicate sharing its bones), changing the Rig panel's *Bandwidth*, *Density Threshold* or
*Symmetry* re-clusters the cached votes and rebuilds its bones in place
(:func:`update_live_prediction`, a fraction of a second); once the artist
edits it, the settings wait for the next *Predict Skeleton*.
"""

from __future__ import annotations

import uuid
from collections import OrderedDict
from dataclasses import dataclass
from typing import Callable, Generator

import bpy
import numpy as np

from ...core.errors import InputError
from ...core.geometry.flatness import flatness
from ...core.geometry.outliers import require_finite_positions
from ...core.messages import listed_names
from ...core.progress import ProgressCallback, labelled_progress, sub_progress
from ...core.rigging.character_parts import CharacterParts, character_parts, left_out_notes, several_characters_message
from ...core.rigging.held_at_hands import BodyReading, props_held_at_hands_reading
from ...core.rigging.predict import (
    DEFAULT_FINGERS,
    DEFAULT_TEMPLATE,
    JointVotes,
    checked_skeleton,
    chosen_template,
    naming_note,
    predict_votes,
    skeleton_from_votes,
    template_notes,
)
from ...core.rigging.props import carried_props, prop_notes, rigid_props
from ...core.rigging.rig_library import KNOWN_RIG
from ...core.rigging.standard_skeleton import FREE_FORM
from ...core.skeleton.checks import skeleton_extent
from ...core.skeleton.name_presets import DEFAULT_PRESET
from ...core.types import Mesh, Skeleton
from .. import convert
from ..armature_binding import (
    armature_bindings,
    bound_armature,
    deforms,
    followers,
    objects_at_rest,
    remove_armature,
    unbind,
)
from ..armature_builder import build_armature
from ..modifier_stack import (
    DEFORM_ONLY_TYPES,
    SHAPELESS_TYPES,
    SURFACE_FINISH_TYPES,
    armature_place,
    binding_place,
    cut_off,
)
from ..object_roles import carried_on_bones
from ..rigify_rig import generate_rigify_rig
from ..snapshot import restored_on_failure
from .input_checks import check_mode
from .skin import SkinSettings, compute_skin, plan_skin, write_skin
from .worker_job import WorkerJob

#: Custom property marking an armature built by a prediction; its value is
#: the key of the prediction's cached network outputs.
PREDICTED_PROPERTY = "autorig_predicted"
#: Predictions whose network outputs stay in memory for live re-clustering;
#: past this many the oldest is forgotten (its armature then keeps its bones).
MAX_CACHED_PREDICTIONS = 8
#: The armature is named after the character: its name plus this suffix.
ARMATURE_SUFFIX = "_rig"
#: Share of the progress bar the skeleton takes in Auto-Rig; the skin weights take the rest.
PREDICTION_SHARE = 0.4
#: Rest bone positions differing by more than this share of the skeleton's
#: extent mean the armature was edited (Blender stores bones in float32).
EDIT_TOLERANCE = 1e-5
#: A side of the bounding box the user sees lying farther than this share of
#: its diagonal from the shape the Armature modifier deforms means the
#: modifiers after it change the character: the skeleton would not fit it.
MAX_UNRIGGED_CHANGE = 0.1
#: An object scale whose largest axis is this many times its smallest is named
#: when the shape is flat (an unapplied scale squashing the character).
UNEVEN_SCALE_RATIO = 1.5


@dataclass(frozen=True)
class RigSettings:
    """Options of the clustering (``core.rigging.predict.skeleton_from_votes``),
    the core's defaults unless given.

    Attributes
    ----------
    bandwidth : float or None, mean-shift bandwidth as a share of the character's largest side
    density_threshold : float or None, share of the strongest mode's vote mass below which a mode is dropped
    symmetry : bool or None, mirror votes and pair joints when the shape is left-right symmetric
    template : str or None, ``auto``, ``biped``, ``quadruped`` or ``free-form``
    names : str or None, a bone-name preset of ``core.skeleton.name_presets.PRESETS``
    fingers : bool or None, give a standard biped fingers when its hands have separable ones
    """

    bandwidth: float | None = None
    density_threshold: float | None = None
    symmetry: bool | None = None
    template: str | None = None
    names: str | None = None
    fingers: bool | None = None

    def keywords(self) -> dict:
        """The keyword arguments of ``skeleton_from_votes`` that were given."""
        return {name: value for name, value in vars(self).items() if value is not None}


@dataclass
class RigPlan:
    """Checked inputs of a prediction.

    Attributes
    ----------
    meshes : list of bpy.types.Object, the character's meshes (those wholly left out dropped)
    mesh : Mesh, their world-space rest shape, concatenated: each as its
        Armature modifier will deform it (``convert.read_rest_shape``), a
        Mirror modifier's mirrored half included
    name : str, the name of the armature to build
    settings : RigSettings
    skin : SkinSettings or None, bind the meshes with these (Auto-Rig) or not
    replace : bool, unbind meshes already bound to an armature before binding them, and remove
        that armature afterwards when nothing else follows it
    named : bool, the user picked the meshes (False: every mesh of a file; see ``plan_skin``)
    rigify : bool, turn the standard skeleton into Rigify's control rig and bind the meshes to its DEF- bones
    keep_poor : bool, build a skeleton the checks find poor (``core.rigging.quality``) instead of refusing it
    left_out : (n,) bool array over ``mesh``'s vertices or None: pieces that are not the character
        (a ground plane, stray specks: ``core.rigging.character_parts``), left out of the prediction and
        left unweighted
    notes : tuple of str, what the report says about what was left out
    held : tuple of (bpy.types.Object, (3,) float array): rigid props the character holds, not among
        ``meshes`` (``core.rigging.props``), and their grip (world space); Auto-Rig binds each wholly to
        the deform bone nearest to its grip
    held_pieces : tuple of ((k,) int array, (3,) float array): held rigid props joined into one of
        ``meshes`` (a sword joined into the body), their rows in ``mesh`` and their grip; left out of
        the prediction, and Auto-Rig weights each wholly to the deform bone nearest to its grip
    body_reading : BodyReading or None, a body the prediction already read while telling what the character
        holds (``core.rigging.held_at_hands``); its votes stand for ``character``'s when it is the same shape
    """

    meshes: list
    mesh: Mesh
    name: str
    settings: RigSettings = RigSettings()
    skin: SkinSettings | None = None
    replace: bool = False
    named: bool = True
    rigify: bool = False
    keep_poor: bool = False
    left_out: np.ndarray | None = None
    notes: tuple = ()
    held: tuple = ()
    held_pieces: tuple = ()
    body_reading: BodyReading | None = None

    @property
    def character(self) -> Mesh:
        """The shape the skeleton is predicted for: ``mesh`` without the ``left_out`` vertices and the
        ``held_pieces``."""
        if self.left_out is None and not self.held_pieces:
            return self.mesh
        left = np.zeros(self.mesh.vertex_count, dtype=bool) if self.left_out is None else self.left_out.copy()
        for rows, _ in self.held_pieces:
            left[rows] = True
        return self.mesh.subset(~left)

    def votes_read_already(self) -> JointVotes | None:
        """The votes of :attr:`body_reading` when its body is :attr:`character`, vertex for vertex; else None."""
        if self.body_reading is None:
            return None
        body, character = self.body_reading.body, self.character
        same = np.array_equal(body.vertices, character.vertices) and np.array_equal(body.triangles,
                                                                                     character.triangles)
        return self.body_reading.votes if same else None


@dataclass
class RigResult:
    """What a run built: the armature, its skeleton, the notes of the
    prediction and, when it bound the meshes, the skin plan and weights;
    ``template`` is the skeleton built (``biped``, ``quadruped``,
    ``free-form`` or ``known rig``), ``body`` and ``confidence`` what the landmark network
    read the body as and how sure it was, ``key_joints_from`` the known rig
    whose key joints a standard skeleton took (``core.rigging.rig_library``;
    empty when the landmark network's), ``kind_from`` the known body whose
    kind the skeleton took when the network read none surely (empty
    otherwise), ``rig_from`` the known body whose whole rig was fitted
    (``known rig``; empty otherwise), ``rigify`` whether Rigify's control
    rig was generated, ``problems`` what the checks found in a poor skeleton
    kept on request, ``meshes`` the character's meshes the run took (those
    wholly left out, such as a ground plane, dropped)."""

    armature: object
    skeleton: Skeleton
    notes: tuple = ()
    skin_plan: object = None
    weights: object = None
    template: str = ""
    body: str = ""
    confidence: float = 0.0
    key_joints_from: str = ""
    kind_from: str = ""
    rig_from: str = ""
    rigify: bool = False
    problems: tuple = ()
    meshes: tuple = ()


@dataclass
class _Prediction:
    """A cached prediction: the network outputs, the skeleton the armature
    had when last built from them (world space, as read back), and whether
    *Auto* may give a known body's rig there (not when the checks found it
    poor on the body; engine names, a setting, turn it off while chosen)."""

    votes: JointVotes
    built: Skeleton
    known_rig: bool = True


_PREDICTIONS: OrderedDict[str, _Prediction] = OrderedDict()

#: A step's task, run by a worker (the operators) or on this thread (:func:`run_steps`).
Task = Callable[[ProgressCallback | None], object]
#: What the progress says while the body is read to tell what its hands hold ...
HANDS_READING_LABEL = "Telling what the hands hold"
#: ... and the share of the progress bar that reading takes in a whole run (:func:`planned_rig_steps`):
#: one pass of the prediction, as the rig's own, which it often spares.
HANDS_READING_SHARE = 0.3


def plan_rig(meshes: list, depsgraph, name: str, settings: RigSettings = RigSettings(), *,
             skin: SkinSettings | None = None, replace: bool = False, named: bool = True,
             rigify: bool = False, keep_poor: bool = False, carried: dict | None = None) -> RigPlan:
    """:func:`plan_rig_steps` run on this thread: the plan. Raises :class:`InputError` on bad input."""
    return run_steps(plan_rig_steps(meshes, depsgraph, name, settings, skin=skin, replace=replace, named=named,
                                    rigify=rigify, keep_poor=keep_poor, carried=carried))


def plan_rig_steps(meshes: list, depsgraph, name: str, settings: RigSettings = RigSettings(), *,
                   skin: SkinSettings | None = None, replace: bool = False, named: bool = True,
                   rigify: bool = False, keep_poor: bool = False,
                   carried: dict | None = None) -> Generator[Task, object, RigPlan]:
    """Read and check the character's meshes, as steps (see :func:`rig_steps`) that return the
    plan; raises :class:`InputError` on bad input.

    The steps yield one task at most, for a character of several objects:
    telling the objects it holds at its hands (``core.rigging.held_at_hands``:
    the candidates, then the landmark network reading the body when there is
    one). The operators run it in the worker like the prediction (progress,
    Esc), not while the operator starts; the rest reads Blender's objects and
    is quick, and its refusals (a mesh already bound, several characters)
    come before it; the flat-shape refusal comes after, measuring the
    character without what its hands hold.

    What is not the character (``core.rigging.character_parts``) is told
    apart here: a ground plane and stray specks are left out (a mesh wholly
    left out is dropped from the plan, so it is not bound; the plan's notes
    say so), and meshes holding several characters are refused, naming them.
    Rigid props (``core.rigging.props``) are dropped from the meshes too:
    those the character holds are the plan's ``held``, the others are not bound.

    Parameters
    ----------
    meshes : list of bpy.types.Object, one character
    depsgraph : bpy.types.Depsgraph (the meshes are read evaluated, armatures at rest)
    name : str, the character's name (the armature is called ``name + ARMATURE_SUFFIX``); a
        mesh left out gives its name to the first mesh kept instead
    settings : RigSettings
    skin : SkinSettings or None; given, the meshes are bound, and a mesh
        already bound to an armature is refused unless ``replace``
    replace : bool
    named, rigify, keep_poor : bool, see :class:`RigPlan`
    carried : dict or None, mapping meshes a replaced armature carried on one bone each (KayKit's
        weapons on their hand slots) to that bone's middle at rest (world space): those sticking out of the
        rest are held props (``core.rigging.props.carried_props``), a mirrored pair too. The ``rig``
        command's ``--replace`` reads it before removing the armatures; with ``replace`` and ``skin``
        (Auto-Rig's Replace Binding) and none given, it is read from ``meshes``
        (``object_roles.carried_on_bones``)
    """
    meshes = list(dict.fromkeys(meshes))
    if not meshes:
        raise InputError("Select the mesh(es) of the character to rig.")
    for obj in meshes:
        convert.require_mesh_object(obj, "mesh to rig")
        check_mode(obj, "rig")
    if carried is None and replace and skin is not None:
        carried = carried_on_bones(meshes)  # Replace Binding: the rig being replaced says what it carried
    # The old Armature modifiers go with Replace Binding, and Predict Skeleton binds nothing: the new one's place.
    places = [armature_place(obj) if skin is None or replace else binding_place(obj) for obj in meshes]
    rest = convert.read_rest_shape(meshes, places, depsgraph)
    mesh = rest.mesh
    require_finite_positions(mesh.vertices, mesh.object_names, mesh.object_offsets)
    _require_rigged_shape_is_seen(meshes, places, rest, depsgraph)
    if rigify and settings.template == FREE_FORM:
        raise InputError("Rigify needs a standard skeleton: choose the Auto, Biped or Quadruped template.")
    chosen = meshes
    parts, props = _told_apart(chosen, mesh, named=named, carried=carried)
    if skin is not None and not replace:
        # What the hands hold moves from the meshes to the held objects, so these are the objects bound either way.
        _require_unbound([obj for index, obj in enumerate(chosen) if index not in _dropped(parts, props)]
                         + [chosen[prop.object_index] for prop in props if prop.held and prop.piece is None])
    told_objects = [prop.object_index for prop in props if prop.piece is None]
    at_hands, reading = (yield lambda progress: props_held_at_hands_reading(
        mesh, parts.left_out, told_objects, progress=labelled_progress(progress, HANDS_READING_LABEL))
    ) if len(mesh.object_names) > 1 else ((), None)
    meshes, mesh, left_out, notes, held, held_pieces = _settled(chosen, mesh, parts, props + at_hands,
                                                                bound=skin is not None)
    if name in {obj.name for obj in chosen} - {obj.name for obj in meshes}:
        name = meshes[0].name  # a mesh left out (a ground plane active in the selection) does not name the armature
    plan = RigPlan(meshes, mesh, name + ARMATURE_SUFFIX, settings, skin, replace, named, rigify, keep_poor,
                   left_out, notes, held, held_pieces, reading)
    _require_not_flat(meshes, plan.character)
    return plan


def _require_unbound(objects) -> None:
    """Refuse when one of ``objects`` is already bound to an armature (without Replace Binding)."""
    bound = [(obj, bound_armature(obj)) for obj in objects if bound_armature(obj) is not None]
    if bound:
        obj, armature = bound[0]
        raise InputError(
            f"'{obj.name}' is already bound to the armature '{armature.name}': turn on Replace Binding to bind "
            "it to the new skeleton instead, or remove its Armature modifier first."
        )


def _told_apart(meshes: list, mesh: Mesh, *, named: bool, carried: dict | None = None) -> tuple:
    """Tell the character from what is not (``core.rigging.character_parts``, ``core.rigging.props``):
    refuse several characters, naming them; find a ground plane, stray specks and the rigid props told
    by their lacking a twin or by the rig being replaced. Quick: no network runs. What the hands hold
    is told after (:func:`props_held_at_hands_reading`).

    Parameters
    ----------
    meshes : list of bpy.types.Object
    mesh : Mesh, their rest shape (objects in the order of ``meshes``)
    named : bool, see :class:`RigPlan`
    carried : dict or None, see :func:`plan_rig_steps`

    Returns
    -------
    parts : CharacterParts
    props : tuple of Prop
    """
    parts = character_parts(mesh)
    if parts.several:
        raise InputError(several_characters_message(mesh, parts, _one_at_a_time(mesh, parts, named)))
    on_bones = {index: carried[obj] for index, obj in enumerate(meshes) if carried and obj in carried}
    told = carried_props(mesh, on_bones) if on_bones else ()
    props = tuple(prop for prop in rigid_props(mesh, parts.left_out)
                  if prop.object_index not in {known.object_index for known in told}) + told
    return parts, props


def _dropped(parts: CharacterParts, props: tuple) -> set:
    """The objects not bound with the character: those wholly left out and the props of their own."""
    return set(parts.whole_objects()) | {prop.object_index for prop in props if prop.piece is None}


def _settled(meshes: list, mesh: Mesh, parts: CharacterParts, props: tuple, *, bound: bool) -> tuple:
    """The character without what is not, once every prop is told (:func:`_told_apart`, then those
    held at the hands).

    Parameters
    ----------
    meshes : list of bpy.types.Object
    mesh : Mesh, their rest shape (objects in the order of ``meshes``)
    parts : CharacterParts
    props : tuple of Prop, all of them
    bound : bool, the run binds the meshes (the notes say what is left unbound)

    Returns
    -------
    meshes : list of bpy.types.Object, without those wholly left out
    mesh : Mesh of those meshes
    left_out : (n',) bool array over its vertices, or None when nothing is left out of them
    notes : tuple of str
    held : tuple of (bpy.types.Object, (3,) array), the props held and their grip (see :class:`RigPlan`)
    held_pieces : tuple of ((k,) int array, (3,) array), the props joined into a mesh: their rows in the
        returned mesh and their grip (see :class:`RigPlan`)
    """
    dropped = _dropped(parts, props)
    kept_rows = np.ones(mesh.vertex_count, dtype=bool)
    for index in dropped:
        kept_rows[mesh.object_slice(index)] = False
    left_out = parts.left_out[kept_rows]
    notes = (*left_out_notes(mesh, parts, bound=bound), *prop_notes(mesh, props, bound=bound))
    held = tuple((meshes[prop.object_index], prop.grip) for prop in props if prop.held and prop.piece is None)
    new_row = np.cumsum(kept_rows) - 1
    held_pieces = tuple((new_row[prop.piece], prop.grip) for prop in props if prop.piece is not None)
    return ([obj for index, obj in enumerate(meshes) if index not in dropped], mesh.subset(kept_rows),
            left_out if left_out.any() else None, notes, held, held_pieces)


def _one_at_a_time(mesh: Mesh, parts: CharacterParts, named: bool) -> str:
    """How to rig several characters one at a time, as the run was started
    (``named``: the user picked the meshes; else the command took every mesh
    of the file), after separating those joined into one mesh."""
    pick = ("select one character's meshes and rig it, then the next" if named else
            "name one character's meshes with --mesh")
    joined = [name for index, name in enumerate(mesh.object_names)
              if sum(character[mesh.object_slice(index)].any() for character in parts.characters) > 1]
    if joined:
        return (f"first separate the characters joined in {listed_names(joined, quoted=True)} into objects of their "
                f"own (Edit Mode: Mesh > Separate > By Loose Parts), then {pick}")
    return pick


def _require_rigged_shape_is_seen(meshes, places, rest: convert.RestShape, depsgraph) -> None:
    """Refuse meshes whose modifiers after the Armature modifier's place
    change the shape the user sees a lot (an Array, a Boolean, a Simple
    Deform below a Subdivision Surface): the skeleton would be fitted to the
    shape before them. Modifiers that only refine the surface are left out
    of the comparison (``modifier_stack.SURFACE_FINISH_TYPES``)."""
    for index, (obj, place) in enumerate(zip(meshes, places)):
        later = cut_off(obj, place)
        changing = [modifier for modifier in later if modifier.type not in SURFACE_FINISH_TYPES | SHAPELESS_TYPES]
        if not changing:
            continue
        seen = convert.evaluated_bounds(obj, depsgraph)
        rigged = rest.mesh.vertices[rest.mesh.object_slice(index)]
        if seen is not None:
            low, high = seen
            size = max(float(np.linalg.norm(high - low)), 1e-12)
            change = max(np.abs(rigged.min(axis=0) - low).max(), np.abs(rigged.max(axis=0) - high).max()) / size
            if change <= MAX_UNRIGGED_CHANGE:
                continue
        names = listed_names([modifier.name for modifier in changing], quoted=True)
        fix = f"apply {names} first (Ctrl+A)"
        if all(modifier.type in DEFORM_ONLY_TYPES | {"MIRROR"} for modifier in changing):
            fix = f"move {names} above '{later[0].name}' in the modifier stack, or {fix}"
        raise InputError(
            f"'{obj.name}': its modifier {names} changes the shape a lot after the place where the Armature modifier "
            f"deforms it (before '{later[0].name}'), so the skeleton would be fitted to another shape than the one "
            f"shown: {fix}."
        )


def _require_not_flat(meshes, mesh: Mesh) -> None:
    """Refuse a flat shape (``core.geometry.flatness``): not a body a
    skeleton can be predicted for; name an uneven object scale that may
    have squashed it."""
    shape = flatness(mesh.vertices, mesh.triangles)
    if not shape.is_flat:
        return
    names = listed_names([obj.name for obj in meshes], quoted=True)
    what = f"{names} is" if len(meshes) == 1 else f"Together, {names} are"
    message = (f"{what} flat: {shape.thickness:.3g} thick and {shape.width:.3g} by {shape.length:.3g} across "
               f"(its thickness is {shape.thickness_ratio:.0%} of its width): a skeleton is predicted for a body with "
               "some depth.")
    for obj in meshes:
        scale = np.abs(np.array(obj.matrix_world.to_scale()))
        if scale.max() > UNEVEN_SCALE_RATIO * max(scale.min(), 1e-12):
            shown = ", ".join(f"{value:.3g}" for value in obj.scale)
            message += (f" '{obj.name}' has the object scale ({shown}), which squashes it: give it the scale the "
                        "character should have (Object properties > Transform), then rig it.")
            break
    raise InputError(message + " Nothing was built.")


def _remember(armature, votes: JointVotes, known_rig: bool = True) -> None:
    """Cache ``votes`` for live re-clustering of ``armature`` (marked with a
    new token), and whether *Auto* may give it a known body's rig there."""
    token = uuid.uuid4().hex
    armature[PREDICTED_PROPERTY] = token
    _PREDICTIONS[token] = _Prediction(votes, convert.read_skeleton(armature), known_rig)
    while len(_PREDICTIONS) > MAX_CACHED_PREDICTIONS:
        _PREDICTIONS.popitem(last=False)


def rig_steps(context, plan: RigPlan, *, remember: bool = True) -> Generator[Task, object, RigResult]:
    """The steps of a prediction (and, with ``plan.skin``, the binding).
    ``remember``: cache the votes for live re-clustering (the operators; not
    the command line, whose session ends).

    Yields the ``bpy``-free tasks, ``task(progress) -> result``, and
    receives their results; does the Blender work itself in between. Drive
    it with :func:`run_steps` or the modal operators. Whatever raises
    (including :class:`Cancelled` thrown in at a yield, or the generator
    being closed), the armature is removed and the meshes restored.
    """
    share = PREDICTION_SHARE if plan.skin is not None else 1.0
    read = plan.votes_read_already()  # telling the props held at the hands read this very body: not twice
    votes = yield (lambda progress: read) if read is not None else (
        lambda progress: predict_votes(plan.character, sub_progress(progress, 0.0, share)))
    # Rigify's control rig is built on a standard skeleton, never on a known body's rig.
    checked = checked_skeleton(votes, known_rig=not plan.rigify, **plan.settings.keywords())
    skeleton, problems = checked.skeleton, checked.problems
    # Engine names are given to a standard skeleton only (skeleton_from_votes reads them so).
    known_rig = checked.known_rig and (plan.settings.names or DEFAULT_PRESET) == DEFAULT_PRESET
    template = plan.settings.template or DEFAULT_TEMPLATE
    if problems and not plan.keep_poor:
        raise InputError(" ".join((*checked.notes,
                                   f"The predicted skeleton looks poor: {'; '.join(problems)}. Nothing was built: try "
                                   "another Template, or keep it anyway with Keep Poor Result (--keep-poor).")))
    bound = plan.meshes + [obj for obj, _ in plan.held]
    replaced = _followed_armatures(bound) if plan.skin is not None and plan.replace else []
    armature = build_armature(skeleton, plan.name, context)
    created = [armature]
    try:
        armature.show_in_front = True  # the bones are inside the body
        fingers = DEFAULT_FINGERS if plan.settings.fingers is None else plan.settings.fingers
        naming = naming_note(skeleton, plan.settings.names or DEFAULT_PRESET)
        notes = (*plan.notes, *votes.notes, *template_notes(votes, template, skeleton, fingers, known_rig),
                 *checked.notes, *((naming,) if naming else ()),
                 *(f"poor result kept: {problem}" for problem in problems))
        target = armature
        rig = None
        if plan.rigify:
            try:
                rig, metarig, rigify_notes = generate_rigify_rig(armature, plan.name, context)
            except InputError as error:
                # The standard skeleton is still a usable rig: keep it, and say why there is no control rig.
                notes = (*notes, f"no Rigify control rig: {error}")
            else:
                created += [rig, metarig]
                target, notes = rig, (*notes, *rigify_notes)
        result = RigResult(target, convert.read_skeleton(target) if rig is not None else skeleton, notes,
                           template=chosen_template(votes, template, known_rig)[0], rigify=rig is not None,
                           problems=problems, meshes=tuple(plan.meshes))
        if votes.landmarks is not None:
            result.body, result.confidence = votes.landmarks.kind, votes.landmarks.confidence
            copied = votes.landmarks.copied_for(result.template)
            result.key_joints_from = copied.name if copied is not None else ""
            relative = votes.landmarks.relative
            result.kind_from = relative.name if relative is not None and result.template == relative.kind else ""
        if result.template == KNOWN_RIG:
            result.rig_from = votes.known_rig.name
        if plan.skin is not None:
            with restored_on_failure(bound):
                if plan.replace:
                    # At rest, as the rest shape was read: what the old rig's pose moved (a sword on a posed
                    # hand's bone) stays where it is at rest, not where the pose held it.
                    with objects_at_rest(bound):
                        for obj in bound:
                            unbind(obj)
                skin_plan = plan_skin(target, plan.meshes, plan.skin, context.evaluated_depsgraph_get(),
                                      named=plan.named, left_out=plan.left_out, held=plan.held,
                                      held_pieces=plan.held_pieces)
                weights = yield lambda progress: compute_skin(skin_plan, sub_progress(progress, share, 1.0))
                write_skin(skin_plan, weights)
            result.skin_plan, result.weights = skin_plan, weights
        if remember and rig is None:
            _remember(armature, votes, checked.known_rig)
    except BaseException:
        for obj in reversed(created):
            if obj.name in bpy.data.objects:
                remove_armature(obj)
        raise
    if rig is not None:
        # The predicted skeleton lives on as the metarig: keep one armature by the character's name.
        remove_armature(armature)
        rig.name = rig.data.name = plan.name
    # Last, once nothing can fail: a removed armature cannot be restored.
    result.notes = (*result.notes, *_remove_unused(replaced))
    return result


def planned_rig_steps(context, plan_steps: Generator[Task, object, RigPlan], *,
                      remember: bool = True) -> Generator[Task, object, RigResult]:
    """``plan_steps`` (:func:`plan_rig_steps`) then :func:`rig_steps` on the plan they
    return, as one run of steps: an operator started on them runs every slow
    part in its worker, the reading that tells what the hands hold too.

    One progress bar for the whole run: when the planning reads the body (a
    character of several objects), its task fills the first
    :data:`HANDS_READING_SHARE` of the bar and the rig's steps the rest, so
    the bar never starts again from empty."""
    read = []
    plan = yield from _progress_within(plan_steps, 0.0, HANDS_READING_SHARE, read)
    return (yield from _progress_within(rig_steps(context, plan, remember=remember),
                                        HANDS_READING_SHARE if read else 0.0, 1.0, []))


def _progress_within(steps: Generator[Task, object, object], start: float, end: float, yielded: list):
    """``steps`` with each task's progress mapped onto [``start``, ``end``] of the
    bar (:func:`...core.progress.sub_progress`); results and exceptions (Esc,
    the generator closed) pass through to ``steps`` as :func:`run_steps` and the
    operators give them. Appends to ``yielded`` for each task yielded."""
    try:
        task = steps.send(None)
        while True:
            yielded.append(task)
            try:
                result = yield _within(task, start, end)
            except BaseException as error:  # the steps clean up and re-raise (GeneratorExit on close too)
                task = steps.throw(error)
            else:
                task = steps.send(result)
    except StopIteration as stop:
        return stop.value


def _within(task: Task, start: float, end: float) -> Task:
    return lambda progress: task(sub_progress(progress, start, end))


def _followed_armatures(meshes) -> list:
    """The armatures ``meshes`` follow (deformed or carried), each once."""
    return list(dict.fromkeys(binding.armature for obj in meshes for binding in armature_bindings(obj)))


def _remove_unused(armatures) -> list[str]:
    """Remove the armatures Replace Binding took the meshes from where
    nothing follows them any more (a leftover armature would still look like
    the character's rig); keep the others. Returns a note for each."""
    notes = []
    for armature in armatures:
        users = [obj.name for obj in followers(armature)]
        name = armature.name
        if users:
            notes.append(f"the old armature '{name}' stays: {listed_names(users, quoted=True)} still follow it")
        else:
            remove_armature(armature)
            notes.append(f"the old armature '{name}' was removed (no other object follows it)")
    return notes


def run_steps(steps: Generator, progress: ProgressCallback | None = None):
    """Run ``steps`` (:func:`rig_steps`) on this thread; returns its result.
    A task's exception is thrown into the steps, so they clean up."""
    try:
        task = steps.send(None)
        while True:
            try:
                result = task(progress)
            except BaseException as error:  # the steps clean up and re-raise
                task = steps.throw(error)
            else:
                task = steps.send(result)
    except StopIteration as stop:
        return stop.value


# --------------------------------------------------------------------------- live re-clustering


def _prediction_of(obj) -> _Prediction | None:
    if obj is None or obj.type != "ARMATURE":
        return None
    return _PREDICTIONS.get(obj.get(PREDICTED_PROPERTY, ""))


def live_armature(context) -> tuple[object, str]:
    """The predicted armature the Rig settings update, and what the panel
    says about it.

    The active object if it is a predicted armature, else the most recently
    predicted one in the scene. Returns ``(armature, "")`` when it can be
    updated, ``(None, note)`` when it cannot (edited, in Edit Mode, anything
    bound to or carried by it, a linked duplicate sharing its bones),
    ``(None, "")`` when there is none.
    """
    scene_objects = set(context.scene.objects)
    candidates = [obj for obj in scene_objects if _prediction_of(obj) is not None]
    if not candidates:
        return None, ""
    active = context.active_object
    if active in candidates:
        armature = active
    else:
        order = list(_PREDICTIONS)
        armature = max(candidates, key=lambda obj: order.index(obj[PREDICTED_PROPERTY]))
    if armature.mode == "EDIT":
        return None, f"'{armature.name}' is in Edit Mode: the settings wait for the next Predict Skeleton"
    if not _unedited(armature, _prediction_of(armature).built):
        return None, f"'{armature.name}' was edited: the settings apply at the next Predict Skeleton"
    # Rebuilding replaces the bones (and their datablock): whatever hangs on them would move or lose them.
    waiting = "the settings apply at the next Predict Skeleton"
    carried = followers(armature)
    if any(deforms(armature, obj) for obj in carried):
        return None, f"'{armature.name}' is bound to meshes: {waiting}"
    if carried:
        names = listed_names([obj.name for obj in carried], quoted=True)
        return None, f"'{armature.name}' carries {names} on its bones: {waiting}"
    duplicates = [obj.name for obj in bpy.data.objects if obj.data == armature.data and obj != armature]
    if duplicates:
        names = listed_names(duplicates, quoted=True)
        return None, f"'{armature.name}' shares its bones with {names} (a linked duplicate): {waiting}"
    return armature, ""


def _unedited(armature, built: Skeleton) -> bool:
    """Whether ``armature`` still holds the bones it was built with (names,
    parents, deform flags, world-space heads and tails within
    :data:`EDIT_TOLERANCE` of the extent)."""
    try:
        now = convert.read_skeleton(armature)
    except InputError:  # every bone deleted
        return False
    if now.names != built.names or not np.array_equal(now.parents, built.parents) \
            or not np.array_equal(now.deform, built.deform):
        return False
    tolerance = EDIT_TOLERANCE * max(skeleton_extent(built), 1e-9)
    return bool(np.abs(now.joints - built.joints).max() <= tolerance
                and np.abs(now.tails - built.tails).max() <= tolerance)


def rebuild_armature(armature, skeleton: Skeleton, context) -> None:
    """Replace the bones of ``armature`` with ``skeleton`` (world space; the
    object, its name and its transform stay): a new armature datablock
    built whole by ``build_armature`` takes the old one's place."""
    fresh = build_armature(skeleton, armature.data.name, context)
    old, name = armature.data, armature.data.name
    armature.data = fresh.data
    bpy.data.objects.remove(fresh)
    bpy.data.armatures.remove(old)
    armature.data.name = name


def update_live_prediction(context, settings: RigSettings) -> object:
    """Re-cluster the live predicted armature (:func:`live_armature`) with
    ``settings``; returns it, or None when there is none to update.
    Raises :class:`InputError` when the new skeleton cannot be built (the
    armature is unchanged then)."""
    armature, _ = live_armature(context)
    if armature is None:
        return None
    prediction = _prediction_of(armature)
    skeleton = skeleton_from_votes(prediction.votes, **settings.keywords(), known_rig=prediction.known_rig)
    rebuild_armature(armature, skeleton, context)
    prediction.built = convert.read_skeleton(armature)
    _PREDICTIONS.move_to_end(armature[PREDICTED_PROPERTY])
    return armature


#: Why the last live update left the armature as it was ("" when it succeeded), for the panel.
_LIVE_FAILURE = {"message": ""}


def on_rig_setting_changed(context, settings: RigSettings) -> None:
    """A Rig setting of the scene changed to ``settings``: re-cluster the live
    armature. A skeleton that cannot be built (no joint at that density)
    leaves the armature unchanged; the panel shows why (:func:`live_note`)."""
    try:
        update_live_prediction(context, settings)
    except InputError as error:
        _LIVE_FAILURE["message"] = str(error)
    else:
        _LIVE_FAILURE["message"] = ""


def live_note(context) -> tuple[str, str]:
    """What the Rig panel says about live updates: ``(text, icon)``; the
    text is "" when there is no predicted armature."""
    armature, note = live_armature(context)
    if armature is None:
        return note, "INFO"
    if _LIVE_FAILURE["message"]:
        return _LIVE_FAILURE["message"], "ERROR"
    return f"Live: the settings update '{armature.name}'", "ARMATURE_DATA"


@dataclass
class TaskJob(WorkerJob):
    """One task of the steps, run by a worker thread for a modal operator;
    its outcome is handed to the steps on the main thread."""

    task: Task
    cancelled_message = "Rigging cancelled."

    def compute(self, progress: ProgressCallback):
        return self.task(progress)
