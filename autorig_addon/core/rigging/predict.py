"""A skeleton for a bare character mesh, RigNet's way (Xu et al. 2020).

1. :func:`predict_votes` (the slow part, about a second): the mesh's
   triangles, wound outward (:mod:`..geometry.outward_faces`), are
   simplified to a proxy of :data:`.joint_features.PROXY_VERTICES`
   vertices, moved into RigNet's normalised frame (feet at z = 0, largest
   side 1), checked for orientation, and the joint network moves every
   vertex toward its joint and weighs its vote (:mod:`.networks.joints`).
2. :func:`skeleton_from_votes` (fast, so the level-of-detail slider answers
   at once): attention-weighted mean shift of the votes at the chosen
   *bandwidth* (:mod:`.mean_shift`), mirrored across the character's plane
   and paired when the shape is symmetric (:mod:`.symmetry`), bones from a
   spanning tree over learned bone probabilities and a learned root
   (:mod:`.connectivity`), names by role (:mod:`.role_names`), tails for
   the leaves, and back to the mesh's own space.

The character is expected upright along +Z, facing -Y, its left at +X
(Blender's front view). One facing +-X is recognised by its mirror plane and
turned for the network; so is one turned by any angle, lying or upside down
(:mod:`.orientation`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ..dataset.normalise import apply_transform, normalisation_transform
from ..errors import InputError
from ..geometry.bounding_box import bounding_box_diagonal
from ..geometry.normals import triangle_double_areas
from ..geometry.outliers import without_vertices
from ..geometry.outward_faces import inward_faces_note, outward_mesh
from ..geometry.proxy import simplified_proxy
from ..nn.numpy_kernels import NUMPY, sigmoid
from ..nn.spec import shipped_weights
from ..progress import ProgressCallback, report
from ..skeleton.name_presets import DEFAULT_PRESET, preset_names, preset_of
from ..skeleton.tails import derived_tails
from ..types import Mesh, Skeleton
from .body_layout import BodyLayout, biped_layout, quadruped_layout
from .connectivity import bone_probabilities, oriented_tree, root_scores, spanning_tree
from .facing import facing, from_behind, front_cue, front_untold_note, half_turned
from .fingers import NOT_SEPARABLE_NOTE, has_fingers
from .joint_features import PROXY_VERTICES, JointGraph, SolidDepth, joint_graph, solid_depth
from .mean_shift import mean_shift_modes
from .networks import joints as joint_network
from .orientation import STANDING_MIDLINE, axis_name, feet_across, stand_upright
from .quality import enclosed_by, skeleton_problems
from .rig_library import KNOWN_RIG, KnownRelative, KnownRig, closest_rig, fitted_rig, nearest_known_body
from .role_names import role_names
from .standard_skeleton import (
    AUTO,
    BIPED,
    FREE_FORM,
    NEAR_SYMMETRIC_ERROR,
    QUADRUPED,
    TEMPLATES,
    Landmarks,
    landmark_disorder,
    landmark_warnings,
    predict_landmarks,
    standard_confidence,
    standard_skeleton,
)
from .symmetry import SYMMETRY_TOLERANCE, mirror_error, mirror_points, symmetric_joints
from .tree_features import candidate_pairs, pair_features, root_features
from .typical_proportions import (
    TYPICAL_CROTCH_SHARE,
    TYPICAL_NECK_SHARE,
    hip_joints_raised_to_crotch,
    points_back,
    stretched,
    typical_proportions,
)

#: Kinds a body's nearest known body (:func:`.rig_library.nearest_known_body`)
#: may give it when the landmark network reads none surely: bipeds only (a
#: velociraptor lies 0.044 from a quadruped; see :data:`.rig_library.RELATIVE_KIND_DISTANCE`).
RELATIVE_KINDS = (BIPED,)

#: Mean-shift bandwidth, share of the character's largest side: the level
#: of detail (smaller: more joints). On the held-out training characters of
#: the 419-character split (``scripts/tune_rig_clustering.py``,
#: docs/models.md) CD-J2J falls with the bandwidth only by finding ever more
#: joints (0.0559 at 0.01 with 17 times the artists' joints, 0.0589 at
#: 0.0175 with 4 times), while joint IoU peaks from 0.0225 to 0.035 (0.095
#: to 0.096); the default is the finest bandwidth within 0.001 of the best
#: IoU (0.0225: IoU 0.095, CD-J2J 0.0614, 2.5 times the artists' joints).
DEFAULT_BANDWIDTH = 0.0225
MIN_BANDWIDTH = 0.01
MAX_BANDWIDTH = 0.2
#: Modes with less vote density than this share of the strongest are not
#: joints. Off by default: every threshold tried (0.01 to 0.05) raised the
#: held-out CD-J2J at the default bandwidth, by dropping real leaf joints.
DEFAULT_DENSITY_THRESHOLD = 0.0
MIN_DENSITY_THRESHOLD = 0.0
MAX_DENSITY_THRESHOLD = 1.0
#: Mirror votes and pair joints when the shape is left-right symmetric.
DEFAULT_SYMMETRY = True
#: The skeleton's template: the landmark network's guess of the body
#: (:func:`chosen_template`).
DEFAULT_TEMPLATE = AUTO
#: Give a standard biped fingers when its hands have separable ones (:mod:`.fingers`).
DEFAULT_FINGERS = True
#: Joints this close to the mirror plane, or to their twin's mirror image,
#: are snapped (share of the bandwidth).
SNAP_SHARE = 0.5
#: Half a turn about the vertical axis.
HALF_TURN = np.diag([-1.0, -1.0, 1.0])
#: A landmark reading this sure of a biped or quadruped is not read again
#: from behind to find the surer of the two (it could gain under 0.001).
SURE_READING = 0.999
#: Fewest faces with an area a mesh needs: below this there is no shape to read.
MIN_FACES = 16
#: A face whose area is below this share of the squared diagonal of the
#: mesh's bounding box has none (collapsed, or its corners on a line): it
#: does not count toward :data:`MIN_FACES`.
FLAT_FACE_AREA_SHARE = 1e-12
#: Length of a bone the tree gives no direction (a lone joint), share of
#: the largest side, pointing up; also the shortest a leaf is cut to.
LONE_BONE_LENGTH = 0.02
#: A leaf bone ends at this share of the way to where its line leaves the
#: solid, so its tail stays inside the body.
LEAF_INSIDE_SHARE = 0.8
#: Points sampled along a leaf bone to find where it leaves the solid.
LEAF_SAMPLES = 16

@dataclass(frozen=True)
class JointVotes:
    """The joint network's output for one character, kept so that clustering
    again at another bandwidth needs no network.

    Attributes
    ----------
    points : (n, 3) float64, votes (moved proxy vertices), normalised frame
    attention : (n,) float64 in (0, 1)
    solid : SolidDepth of the normalised proxy (None: votes only clustered, never connected)
    transform : (4, 4) float64, from the mesh's space to the normalised frame
    symmetric : bool, whether the shape is left-right symmetric
    notes : tuple of str, what was detected or decided
    landmarks : Landmarks of the standard skeleton (:mod:`.standard_skeleton`),
        with the kind of body; None when only the free-form skeleton was asked for
    proxy_vertices : (n, 3) float64, the normalised proxy's vertices (None with ``landmarks``)
    proxy_triangles : (m, 3) int, the proxy's triangles, outward wound (None with ``proxy_vertices``)
    surface : Mesh, the full-resolution surface in the normalised frame, where
        a standard biped's fingers are looked for (None: no fingers)
    known_rig : KnownRig, the rig of a known body near this one, fitted to it
        (:func:`.rig_library.fitted_rig`), which the Auto template gives; None when none is near
    """

    points: np.ndarray
    attention: np.ndarray
    solid: SolidDepth
    transform: np.ndarray
    symmetric: bool
    notes: tuple = ()
    landmarks: Landmarks | None = None
    proxy_vertices: np.ndarray | None = None
    proxy_triangles: np.ndarray | None = None
    surface: Mesh | None = None
    known_rig: KnownRig | None = None


def require_enough_faces(mesh: Mesh) -> None:
    """Refuse a mesh with fewer than :data:`MIN_FACES` faces with an area
    (:data:`FLAT_FACE_AREA_SHARE`): faces without one (a triangle with
    its corners on a line) add no shape, only a count.

    Raises
    ------
    InputError naming the faces with and without an area.
    """
    floor = FLAT_FACE_AREA_SHARE * bounding_box_diagonal(mesh.vertices) ** 2
    has_area = 0.5 * triangle_double_areas(mesh.vertices, mesh.triangles) > floor
    count = int(np.count_nonzero(has_area))
    if count >= MIN_FACES:
        return
    flat = len(has_area) - count
    without = (f" with an area ({flat} more have none: remove them with Mesh > Clean Up > Degenerate Dissolve)"
               if flat else "")
    raise InputError(f"The mesh has {count} faces{without}; predicting a skeleton needs a character surface of at "
                     f"least {MIN_FACES}.")


def predict_votes(mesh: Mesh, progress: ProgressCallback | None = None) -> JointVotes:
    """Run the joint network on ``mesh`` (see the module docstring).

    Parameters
    ----------
    mesh : Mesh, one or more objects forming one character, any space
    progress : optional ProgressCallback (may raise Cancelled)

    Raises
    ------
    InputError for a mesh with too few faces with an area, or a lying character whose up cannot be told.
    """
    # Vertices in no face have no surface to read; the proxy would keep them.
    faceless = np.ones(mesh.vertex_count, dtype=bool)
    faceless[mesh.triangles] = False
    surface = Mesh(*without_vertices(mesh.vertices, mesh.triangles, faceless)[1:])
    if not np.all(np.isfinite(surface.vertices)):
        raise InputError("The mesh has vertices at NaN or infinite positions; fix them before predicting a skeleton.")
    # The proxy's clusters and the networks' normals follow the winding: read it outward whatever the file's.
    surface, inward = outward_mesh(surface)
    require_enough_faces(surface)
    weights = shipped_weights(joint_network.SPEC).weights
    report(progress, 0.0, "Simplifying the mesh")
    proxy = simplified_proxy(surface, PROXY_VERTICES).mesh
    readings, turned_readings = {}, {}

    def read(rotation: np.ndarray) -> tuple:
        """The transform, graph, solid and landmarks of the proxy turned by ``rotation``, each read once."""
        key = np.round(rotation, 9).tobytes()
        if key not in readings:
            transform = framed_transform(proxy.vertices, rotation, proxy.triangles)
            readings[key] = (transform, *_read_shape(proxy, transform, progress))
        return readings[key]

    def read_turned(rotation: np.ndarray) -> Landmarks:
        """The landmarks of the proxy turned by ``rotation``, then half a turn, read once."""
        key = np.round(rotation, 9).tobytes()
        if key not in turned_readings:
            turned_readings[key] = predict_landmarks(half_turned(read(rotation)[1]))
        return turned_readings[key]

    def standing_reading(rotation: np.ndarray) -> Landmarks:
        """The landmarks of the proxy turned by ``rotation``, facing -Y or +Y,
        whichever reads more surely as a biped or quadruped (the kind head
        reads a character from behind less surely); a reading already sure
        (:data:`SURE_READING`) is not read the other way."""
        landmarks = read(rotation)[3]
        if standard_confidence(landmarks) >= SURE_READING:
            return landmarks
        turned = read_turned(rotation)
        return landmarks if standard_confidence(landmarks) >= standard_confidence(turned) else turned

    notes = [inward_faces_note(int(inward.sum()), "the skeleton prediction")] if inward.any() else []
    stance = stand_upright(proxy.vertices, proxy.triangles, standing_reading)
    notes += stance.notes
    rotation = stance.rotation
    transform, graph, solid, landmarks = read(rotation)
    turned = read_turned(rotation)
    way = facing(landmarks, turned, Mesh(graph.vertices, proxy.triangles))
    if way.turn:
        # Turned half a turn the character faces -y as the networks expect, its left at +x; seen from behind, it is
        # now as it was given.
        turned = landmarks
        rotation = HALF_TURN @ rotation
        transform, graph, solid, landmarks = read(rotation)
        notes.append(_turned_note(way.reason))
    if way.untold_kind is not None:
        notes.append(front_untold_note(axis_name(-rotation[1]), read_as=way.untold_kind))
    if way.read_from_behind:
        landmarks = from_behind(turned)
        facing_note = "Turned, it" if way.turn else f"The character faces -Y ({way.reason}) but"
        notes.append(f"{facing_note} reads more surely as a {landmarks.kind} from behind: its landmarks were read "
                     "from behind and turned back.")
    normalised_surface = Mesh(apply_transform(surface.vertices, transform), surface.triangles)
    nearest = None if sure_standard_kind(landmarks) else nearest_known_body(normalised_surface)
    relative = _of_relative_kind(nearest)
    layout = _layout_of_untold_kind(landmarks, relative, solid)
    if way.front_untold:
        # Read as neither kind either way round. A body a biped or a quadruped by its nearest known body or its layout
        # has its front told by its shape (a biped's toes, a quadruped's head end); so has one whose landmarks make a
        # quadruped only read the other way round, its head end toward +Y.
        told = relative or layout
        told_kind = told.kind if told is not None else QUADRUPED
        cue = front_cue(Mesh(graph.vertices, proxy.triangles), told_kind)
        faces_plus_y = cue.tells and cue.reach < 0.0
        turned_nearest = None
        if faces_plus_y and told_kind == QUADRUPED:
            # A quadruped's layout depends on the way it is read (its neck toward -y): read turned, it must make one
            # too, and no known biped may lie near it.
            turned_transform, _, turned_solid, turned_landmarks = read(HALF_TURN @ rotation)
            turned_nearest = nearest_known_body(Mesh(apply_transform(surface.vertices, turned_transform),
                                                     surface.triangles))
            turned_layout = _layout_of_untold_kind(turned_landmarks, None, turned_solid)
            faces_plus_y = _of_relative_kind(turned_nearest) is None and QUADRUPED in (
                turned_landmarks.standard_kind, turned_layout.kind if turned_layout is not None else None)
            if not faces_plus_y:
                # Laid out facing -y with its head end toward +Y, it makes a quadruped neither way round.
                told = layout = None
        if faces_plus_y:
            rotation = HALF_TURN @ rotation
            transform, graph, solid, landmarks = read(rotation)
            normalised_surface = Mesh(apply_transform(surface.vertices, transform), surface.triangles)
            # A quadruped's turned reading already looked for its nearest known body.
            nearest = turned_nearest if told_kind == QUADRUPED else nearest_known_body(normalised_surface)
            relative = _of_relative_kind(nearest)
            layout = _layout_of_untold_kind(landmarks, relative, solid)
            notes.append(_turned_note(f"{cue.toward} +Y"))
        elif told is None:
            notes.append(front_untold_note(axis_name(-rotation[1])))  # the mesh-space direction the frame's -y is
        elif not cue.tells:
            notes.append(front_untold_note(axis_name(-rotation[1]), told_kind))
    landmarks = replace(landmarks, relative=relative, layout=layout)
    landmarks, proportion_notes = _read_again_at_typical_proportions(Mesh(graph.vertices, proxy.triangles), solid,
                                                                     landmarks, way.read_from_behind)
    notes += proportion_notes
    landmarks = _raise_hip_joints_to_crotch(Mesh(graph.vertices, proxy.triangles), solid, landmarks)
    if sure_standard_kind(landmarks):
        landmarks = replace(landmarks, closest_rig=closest_rig(normalised_surface, sure_standard_kind(landmarks)))
    near = landmarks.closest_rig or nearest
    # The closest rig's map is the fitted rig's too: the same entry onto the same surface.
    axis_map = landmarks.closest_rig.axis_map if landmarks.closest_rig is not None else None
    known = fitted_rig(near.name, near.distance, normalised_surface, axis_map=axis_map) if near is not None else None
    report(progress, 0.7, "Running the joint network")
    votes = graph_votes(weights, graph, solid, transform)
    if not votes.symmetric:
        notes.append("The shape is not left-right symmetric, so the skeleton is not mirrored.")
    report(progress, 1.0, "Joint votes done")
    return replace(votes, notes=tuple(notes), landmarks=landmarks, proxy_vertices=graph.vertices,
                   proxy_triangles=proxy.triangles, surface=normalised_surface, known_rig=known)


def _turned_note(reason: str) -> str:
    """The report's note for a character turned half a turn to face -Y, and why."""
    return (f"The character faces away from -Y ({reason}); it was turned half a turn for the prediction, so its .L "
            "bones lie on its own left.")


def _of_relative_kind(nearest: KnownRelative | None) -> KnownRelative | None:
    """The nearest known body of a body the landmark network does not read
    surely (:func:`.rig_library.nearest_known_body`), when it is of a kind of
    :data:`RELATIVE_KINDS`; else None."""
    return nearest if nearest is not None and nearest.kind in RELATIVE_KINDS else None


def _layout_of_untold_kind(landmarks: Landmarks, relative: KnownRelative | None,
                           solid: SolidDepth) -> BodyLayout | None:
    """The layout of a body's landmarks as a biped's (:func:`.body_layout.biped_layout`), else as a
    quadruped's (:func:`.body_layout.quadruped_layout`), when neither the landmark network (reading no kind
    surely) nor a known ``relative`` (a biped near it, :func:`_of_relative_kind`) tells its kind; else None.
    The two exclude each other: a biped's trunk rises, a quadruped's runs along its length."""
    if landmarks.read_surely or relative is not None:
        return None
    return biped_layout(landmarks.points, solid) or quadruped_layout(landmarks.points, solid)


def _read_again_at_typical_proportions(normalised: Mesh, solid: SolidDepth, landmarks: Landmarks,
                                       read_from_behind: bool = False) -> tuple[Landmarks, tuple]:
    """A biped's landmarks read again on its body (``normalised``: the proxy
    in the normalised frame, ``solid`` its solid) mapped to typical
    proportions when they put its hip joints far above its crotch or its
    neck far above its neck's pinch (:mod:`.typical_proportions`), mapped back;
    else ``landmarks`` as they are. Also the note saying so. Landmarks that
    were ``read_from_behind`` (:func:`.facing.from_behind`) are read again
    from behind too: read as given, the body may read as another kind, or
    with its sides swapped."""
    if sure_standard_kind(landmarks) != BIPED:
        return landmarks, ()
    top = float(normalised.vertices[:, 2].max())
    enclosed = enclosed_by(normalised)
    found = typical_proportions(landmarks.points, solid, top, enclosed)
    if found is None:
        return landmarks, ()
    body, stretch = stretched(normalised, found.height_map)
    graph = joint_graph(body)
    reread = from_behind(predict_landmarks(half_turned(graph))) if read_from_behind else predict_landmarks(graph)
    points = points_back(reread.points, stretch, found.height_map)
    # A layout tells the kind of the points it was found on: the points read again must make one too.
    layout = biped_layout(points, solid) if landmarks.layout is not None else None
    reread = replace(reread, points=points, relative=landmarks.relative, layout=layout)
    if reread.standard_kind != BIPED:
        return landmarks, ()  # read again, the body is no sure biped: the first reading stands
    if found.big_head:
        note = (f"The head is big (neck at {found.neck / top:.0%} of the height, crotch at {found.crotch / top:.0%}) "
                f"and the neck was first read higher: the landmarks were read again on the body mapped to a neck at "
                f"{TYPICAL_NECK_SHARE:.0%} and a crotch at {TYPICAL_CROTCH_SHARE:.0%} or higher.")
    else:
        note = (f"The legs are short (crotch at {found.crotch / top:.0%} of the height) and were first read as "
                f"longer: the landmarks were read again on the body stretched to a crotch at "
                f"{TYPICAL_CROTCH_SHARE:.0%}.")
    return reread, (note,)


def _raise_hip_joints_to_crotch(normalised: Mesh, solid: SolidDepth, landmarks: Landmarks) -> Landmarks:
    """A biped's landmarks with the middle of its hip joints (and the hips
    with them) raised to the crotch of its body when read below it
    (:func:`.typical_proportions.hip_joints_raised_to_crotch`; ``normalised``
    and ``solid`` as :func:`_read_again_at_typical_proportions` takes them);
    other landmarks as they are."""
    if sure_standard_kind(landmarks) != BIPED:
        return landmarks
    top = float(normalised.vertices[:, 2].max())
    points, lift = hip_joints_raised_to_crotch(landmarks.points, solid, top, enclosed_by(normalised))
    return replace(landmarks, points=points) if lift > 0.0 else landmarks


def sure_standard_kind(landmarks: Landmarks) -> str | None:
    """The kind of standard skeleton a body gets by default
    (:attr:`.standard_skeleton.Landmarks.standard_kind`): the kind the landmark
    network reads, when it is one with a standard skeleton read with at least
    :data:`.standard_skeleton.KIND_CONFIDENCE`, else its nearest known body's
    (:data:`RELATIVE_KINDS`), else a biped or a quadruped when its landmarks
    are laid out as one (:mod:`.body_layout`); else None."""
    return landmarks.standard_kind


#: A shift of the midline (:func:`framed_transform`) smaller than this share
#: of the largest side is rounding, not a pose.
CENTRE_SHIFT_NOISE = 1e-6


def framed_transform(vertices: np.ndarray, rotation: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(4, 4) from the mesh's space to the normalised frame of ``vertices``
    turned by ``rotation`` (3, 3) first (:func:`.orientation.stand_upright`).

    The networks put the midline at x = 0, the box centre. A body
    (``vertices`` and ``triangles``) standing on feet apart (:func:`.orientation.feet_across`:
    under :data:`.orientation.STANDING_MIDLINE` of its lowest band between
    them) is centred between its feet instead: an arm turned on one side
    moves the box centre, not the feet. The procedural biped with its left
    arm turned 20 degrees in its frontal plane: spine 0.033 off its midline
    and the thighs at 0.022 and -0.088 (0.056 and -0.056 unposed) with the
    box centre; 0.000, 0.054 and -0.054 between the feet. On the validation
    characters (``eval rig``, 2026-11-26) the mean Chamfer distances move by
    0.0003 at most, IoU 0.1010 to 0.1008, key joints 46.3 to 46.4 % (one
    more on a Quaternius zombie); centring on the median of the vertices
    instead cost the humanoids 3.4 points of key joints (Quaternius'
    monsters, whose weapons pull the median): not taken.
    """
    turn = np.eye(4)
    turn[:3, :3] = rotation
    turned = vertices @ rotation.T
    transform = normalisation_transform(turned)
    if len(triangles):
        between, centre = feet_across(turned, triangles)
        shift = centre - 0.5 * (turned[:, 0].min() + turned[:, 0].max())
        # Rounding noise is no shift: a symmetric body's midline vertices must stay at exactly x = 0, where
        # pairing left and right decides by sign (the same body wound the other way must give the same skeleton).
        if between < STANDING_MIDLINE and abs(shift) * transform[0, 0] > CENTRE_SHIFT_NOISE:
            transform[:3, 3] -= transform[:3, :3] @ np.array([shift, 0.0, 0.0])
    return transform @ turn


def _read_shape(proxy: Mesh, transform: np.ndarray, progress) -> tuple:
    """The normalised proxy's joint graph, solid and landmarks."""
    normalised = Mesh(apply_transform(proxy.vertices, transform), proxy.triangles)
    report(progress, 0.3, "Measuring the shape")
    solid = solid_depth(normalised)
    graph = joint_graph(normalised, solid)
    report(progress, 0.5, "Running the landmark network")
    return graph, solid, predict_landmarks(graph)


def skeleton_quality(votes: JointVotes, skeleton: Skeleton) -> tuple:
    """What an animator would reject in ``skeleton`` (the mesh's space), as
    sentences (:func:`.quality.skeleton_problems`); empty when nothing, or
    when the votes kept no solid to check against."""
    if votes.solid is None or votes.proxy_vertices is None:
        return ()
    normalised = Skeleton(apply_transform(skeleton.joints, votes.transform), skeleton.parents, skeleton.names,
                          apply_transform(skeleton.tails, votes.transform))
    # The proxy (2,000 vertices, the solid's own mesh) keeps the winding numbers' and the closest points' cost
    # small on any mesh.
    proxy = Mesh(votes.proxy_vertices, np.zeros((0, 3)) if votes.proxy_triangles is None else votes.proxy_triangles)
    enclosed = enclosed_by(proxy) if len(proxy.triangles) else None
    return skeleton_problems(normalised, votes.solid.at, proxy, enclosed)


class CheckedSkeleton(NamedTuple):
    """A skeleton (:func:`checked_skeleton`), what the checks found wrong in
    it, whether a known rig may be used for this body, and a note when a
    poor known rig gave way."""

    skeleton: Skeleton
    problems: tuple
    known_rig: bool
    notes: tuple


def checked_skeleton(votes: JointVotes, known_rig: bool = True, **settings) -> CheckedSkeleton:
    """:func:`skeleton_from_votes` with ``settings`` (its keywords) and
    ``known_rig``, and what :func:`skeleton_quality` finds wrong in it.

    A known body's rig (:attr:`JointVotes.known_rig`) is checked first,
    whether these settings choose it or not: one the checks find poor on this
    body (a bone far outside it) is not used, and ``known_rig`` is False in
    the result, so that building again with other settings (the live panel)
    does not bring it back; when these settings would have chosen it, a note
    says why it was not used.
    """
    template, names = settings.get("template", DEFAULT_TEMPLATE), settings.get("names", DEFAULT_PRESET)
    notes = ()
    if known_rig and votes.known_rig is not None:
        fitted = skeleton_from_votes(votes, template=AUTO, known_rig=True)  # the known rig, whatever the settings
        poor = skeleton_quality(votes, fitted)
        if poor:
            if chosen_template(votes, template, names == DEFAULT_PRESET)[0] == KNOWN_RIG:
                notes = (f"The rig of the closest known character, {votes.known_rig.name}, looks poor on this body "
                         f"({'; '.join(poor)}): it was not used.",)
            known_rig = False
    skeleton = skeleton_from_votes(votes, **settings, known_rig=known_rig)
    return CheckedSkeleton(skeleton, skeleton_quality(votes, skeleton), known_rig, notes)


def template_notes(votes: JointVotes, template: str = DEFAULT_TEMPLATE, skeleton: Skeleton | None = None,
                   fingers: bool = DEFAULT_FINGERS, known_rig: bool = True) -> tuple:
    """The report's notes on the template: which one and why
    (:func:`chosen_template`), then what looks wrong with a standard
    skeleton (:func:`.standard_skeleton.landmark_warnings`), and, for a
    standard biped ``skeleton`` asked with ``fingers`` that has none, that
    its hands' fingers are not separable. ``known_rig``: as for :func:`chosen_template`."""
    kind, note = chosen_template(votes, template, known_rig)
    if kind in (FREE_FORM, KNOWN_RIG) or votes.solid is None:
        return (note,)
    fingerless = (kind == BIPED and fingers and skeleton is not None and votes.surface is not None
                  and not has_fingers(skeleton.names))
    copied = votes.landmarks.copied_for(kind)
    copy_notes = (copied.note,) if copied is not None else ()
    return (note, *copy_notes, *landmark_warnings(votes.landmarks, kind, votes.solid.at),
            *((NOT_SEPARABLE_NOTE,) if fingerless else ()))


def chosen_template(votes: JointVotes, template: str = DEFAULT_TEMPLATE, known_rig: bool = True) -> tuple[str, str]:
    """The skeleton ``template`` gives on these votes, and a note saying why.

    Returns
    -------
    (kind, note): ``kind`` is ``"biped"``, ``"quadruped"``, ``"free-form"``
    or ``"known rig"``. ``auto`` gives the rig of a known body near this one
    when there is one (:attr:`JointVotes.known_rig`) and ``known_rig`` allows
    it (Rigify's control rig and engine names need a standard skeleton);
    else the landmark network's kind when it is a biped or a quadruped with
    probability at least :data:`.standard_skeleton.KIND_CONFIDENCE`, else
    the kind of the body's nearest known body when it gave one
    (:data:`RELATIVE_KINDS`), else a biped or a quadruped when its landmarks
    are laid out as one (:attr:`.standard_skeleton.Landmarks.layout`); but the free-form
    skeleton when that kind's landmarks are out of the order a standing body
    has them (:func:`.standard_skeleton.landmark_disorder`).
    """
    if template not in TEMPLATES:
        raise InputError(f"Unknown template '{template}': use one of {', '.join(TEMPLATES)}.")
    if template == FREE_FORM or votes.landmarks is None:
        return FREE_FORM, "Template: free-form skeleton, as asked."
    guess, confidence = votes.landmarks.kind, votes.landmarks.confidence
    seen = f"the landmark network reads the body as {guess} ({confidence:.0%} sure)"
    if template != AUTO:
        return template, f"Template: standard {template} skeleton, as asked; {seen}."
    if known_rig and votes.known_rig is not None:
        return KNOWN_RIG, (f"{votes.known_rig.note}; {seen}. Choose the Biped or Quadruped template for a standard "
                           "skeleton (and Rigify's control rig).")
    kind = sure_standard_kind(votes.landmarks)
    if kind is None:
        return FREE_FORM, (f"Template: free-form skeleton, because {seen}; choose a biped or quadruped template to "
                           "force one.")
    told = "" if votes.landmarks.read_surely else (f", not surely a biped or quadruped; "
                                                   f"{votes.landmarks.kind_told_by.note}")
    disorder = landmark_disorder(votes.landmarks, kind)
    if disorder:
        # A standard skeleton hung on these would be wrong at first sight; the free-form one follows the mesh.
        return FREE_FORM, (f"Template: free-form skeleton, because the {kind} landmarks are out of order ("
                           f"{'; '.join(disorder)}); {seen}{told}; choose a biped or quadruped template to force one.")
    return kind, f"Template: standard {kind} skeleton; {seen}{told}."


def graph_votes(weights: dict, graph: JointGraph, solid: SolidDepth | None = None,
                transform: np.ndarray | None = None) -> JointVotes:
    """The joint network's votes on a graph in the normalised frame.

    Parameters
    ----------
    weights : dict, the joint network's weights (shipped, or a training run's)
    graph : JointGraph of the normalised proxy (:func:`.joint_features.joint_graph`)
    solid : its SolidDepth, when the votes will be connected into a skeleton
    transform : (4, 4) float64 from the mesh's space to the normalised frame; default identity

    Returns
    -------
    JointVotes, symmetric when the graph's vertices are left-right symmetric
    (:data:`.symmetry.SYMMETRY_TOLERANCE`), without notes.
    """
    offsets, logits = joint_network.SPEC.forward(NUMPY, weights, graph)
    attention = sigmoid(logits)
    symmetric = mirror_error(graph.vertices, 0) <= SYMMETRY_TOLERANCE
    return JointVotes(graph.vertices + offsets, attention, solid, np.eye(4) if transform is None else transform,
                      symmetric)


def cluster_joints(votes: JointVotes, bandwidth: float, density_threshold: float,
                   symmetry: bool) -> tuple[np.ndarray, np.ndarray]:
    """Joints of the votes in the normalised frame and each one's twin (-1: none)."""
    points, weights = votes.points, votes.attention
    mirrored = symmetry and votes.symmetric
    if mirrored:
        points = np.concatenate([points, mirror_points(points)])
        weights = np.concatenate([weights, weights])
    joints, _ = mean_shift_modes(points, weights, bandwidth, density_threshold)
    if mirrored and len(joints):
        return symmetric_joints(joints, SNAP_SHARE * bandwidth)
    return joints, np.full(len(joints), -1, dtype=np.int64)


def connect_joints(joints: np.ndarray, mirror: np.ndarray, solid: SolidDepth) -> tuple[np.ndarray, np.ndarray]:
    """A parents-first order of the joints and the parents in that order."""
    count = len(joints)
    pairs = candidate_pairs(joints)
    features = pair_features(joints, pairs, solid, mirror)
    probabilities = bone_probabilities(features) if len(pairs) else np.zeros(0)
    edges = spanning_tree(count, pairs, probabilities, mirror, joints)
    scores = root_scores(root_features(joints, solid))
    midline = mirror < 0
    if np.any(mirror >= 0) and midline.any():
        scores = np.where(midline, scores, -np.inf)
    return oriented_tree(count, edges, int(np.argmax(scores)))


def skeleton_from_votes(votes: JointVotes, *, bandwidth: float = DEFAULT_BANDWIDTH,
                        density_threshold: float = DEFAULT_DENSITY_THRESHOLD,
                        symmetry: bool = DEFAULT_SYMMETRY, template: str = DEFAULT_TEMPLATE,
                        names: str = DEFAULT_PRESET, fingers: bool = DEFAULT_FINGERS,
                        known_rig: bool = True) -> Skeleton:
    """The skeleton of the votes at a level of detail, in the mesh's space.

    Parameters
    ----------
    votes : JointVotes of :func:`predict_votes`
    bandwidth : float in [MIN_BANDWIDTH, MAX_BANDWIDTH], share of the largest side
    density_threshold : float in [0, 1]
    symmetry : bool, mirror and pair when the shape is symmetric
    template : one of :data:`.standard_skeleton.TEMPLATES` (:func:`chosen_template`);
        a standard skeleton does not depend on the bandwidth and the density threshold
    names : a preset of :data:`...skeleton.name_presets.PRESETS`; a skeleton
        that is not a standard biped keeps Rigify's names (:func:`naming_note` says so)
    fingers : bool, give a standard biped fingers when both hands have
        separable ones in ``votes.surface`` (:mod:`.fingers`)
    known_rig : bool, let ``auto`` give a known body's rig (:func:`chosen_template`);
        names other than Rigify's need the standard skeleton, so they do not

    Returns
    -------
    Skeleton, parents first, names unique; every bone deforming but those of a
    known rig that only join its deform bones into one tree.
    """
    kind, _ = chosen_template(votes, template, known_rig and names == DEFAULT_PRESET)
    to_mesh = np.linalg.inv(votes.transform)
    if kind == KNOWN_RIG:
        rig = votes.known_rig.skeleton
        return Skeleton(apply_transform(rig.joints, to_mesh), rig.parents, rig.names,
                        apply_transform(rig.tails, to_mesh), rig.deform)
    if kind != FREE_FORM:
        nearly_symmetric = symmetry and mirror_error(votes.proxy_vertices, 0) <= NEAR_SYMMETRIC_ERROR
        skeleton = standard_skeleton(votes.landmarks, kind, votes.proxy_vertices, nearly_symmetric, votes.surface,
                                     fingers, votes.solid)
        return Skeleton(apply_transform(skeleton.joints, to_mesh), skeleton.parents,
                        preset_names(skeleton.names, names)[0], apply_transform(skeleton.tails, to_mesh))
    if not MIN_BANDWIDTH <= bandwidth <= MAX_BANDWIDTH:
        raise InputError(f"The bandwidth must be between {MIN_BANDWIDTH} and {MAX_BANDWIDTH}, got {bandwidth}.")
    if not MIN_DENSITY_THRESHOLD <= density_threshold <= MAX_DENSITY_THRESHOLD:
        raise InputError(f"The density threshold must be between {MIN_DENSITY_THRESHOLD} and "
                         f"{MAX_DENSITY_THRESHOLD}, got {density_threshold}.")
    joints, mirror = cluster_joints(votes, bandwidth, density_threshold, symmetry)
    if not len(joints):
        hint = "lower the density threshold" if density_threshold > 0 else "the network found no joint in this shape"
        raise InputError(f"No joint was found: {hint}.")
    order, parents = connect_joints(joints, mirror, votes.solid)
    joints = joints[order]
    position = np.empty_like(order)
    position[order] = np.arange(len(order))
    mirror = np.where(mirror[order] >= 0, position[np.maximum(mirror[order], 0)], -1)
    bone_names = preset_names(role_names(joints, parents, mirror), names)[0]
    tails = leaf_tails_inside(joints, parents, derived_tails(joints, parents), votes.solid)
    return Skeleton(apply_transform(joints, to_mesh), parents, bone_names, apply_transform(tails, to_mesh))


def naming_note(skeleton: Skeleton, names: str = DEFAULT_PRESET) -> str:
    """Why a skeleton kept Rigify's names instead of ``names`` ("" when it did not)."""
    if names == DEFAULT_PRESET or preset_of(skeleton.names) == names:
        return ""
    return f"the bones keep Rigify's names: {names} names exist for a standard biped skeleton only"


def leaf_tails_inside(joints: np.ndarray, parents: np.ndarray, tails: np.ndarray, solid: SolidDepth) -> np.ndarray:
    """Tails with each leaf cut where its line would leave the body.

    A leaf continues its parent's direction for the parent's length
    (:func:`...skeleton.tails.derived_tails`), which pokes out of a head or
    a fingertip; it is cut to :data:`LEAF_INSIDE_SHARE` of the way to the
    first point of the line outside the solid, and no shorter than
    :data:`LONE_BONE_LENGTH`. A bone without a direction points up.
    """
    tails = np.array(tails, dtype=np.float64)
    lone = ~np.isfinite(tails).all(axis=1)
    tails[lone] = joints[lone] + np.array([0.0, 0.0, LONE_BONE_LENGTH])
    leaves = np.flatnonzero(np.bincount(parents[parents >= 0], minlength=len(joints)) == 0)
    if not len(leaves):
        return tails
    offsets = tails[leaves] - joints[leaves]
    steps = np.linspace(1.0 / LEAF_SAMPLES, 1.0, LEAF_SAMPLES)
    along = joints[leaves, None, :] + steps[None, :, None] * offsets[:, None, :]
    outside = solid.at(along.reshape(-1, 3)).reshape(len(leaves), LEAF_SAMPLES) <= 0.0
    first_outside = np.where(outside.any(axis=1), steps[outside.argmax(axis=1)], np.inf)
    length = np.linalg.norm(offsets, axis=1)
    share = np.minimum(1.0, LEAF_INSIDE_SHARE * first_outside)
    share = np.maximum(share, np.minimum(1.0, LONE_BONE_LENGTH / np.maximum(length, 1e-12)))
    tails[leaves] = joints[leaves] + share[:, None] * offsets
    return tails


def predict_skeleton(mesh: Mesh, *, bandwidth: float = DEFAULT_BANDWIDTH,
                     density_threshold: float = DEFAULT_DENSITY_THRESHOLD, symmetry: bool = DEFAULT_SYMMETRY,
                     template: str = DEFAULT_TEMPLATE, names: str = DEFAULT_PRESET,
                     fingers: bool = DEFAULT_FINGERS, known_rig: bool = True,
                     progress: ProgressCallback | None = None) -> Skeleton:
    """:func:`predict_votes` then :func:`skeleton_from_votes`."""
    votes = predict_votes(mesh, progress)
    return skeleton_from_votes(votes, bandwidth=bandwidth, density_threshold=density_threshold, symmetry=symmetry,
                               template=template, names=names, fingers=fingers, known_rig=known_rig)
