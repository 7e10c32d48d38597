"""Rigid props: separate objects the character holds or carries (a sword,
an axe, a shield, a mug, a quiver), told from its body.

A prop rigged with the character (selected with it, or every mesh of a file)
was read by the skeleton prediction as part of the body: a sword's tip got a
bone floating far from the hand, its blade was split over two bones, and
KayKit's knight with its swords and shields got 106 bones instead of 25.
Its place is one bone: the one that holds it. This module tells props from
the body from the shapes alone (world space), object by object, after
:mod:`.character_parts` has left out a ground plane and stray specks. An
object is a prop when:

1. **it is small**: under :data:`PROP_AREA_SHARE` of the area of the
   character's other objects;
2. **it has no twin**: under :data:`TWIN_SHARE` of its surface, mirrored
   across the body's left-right mirror plane, lies on the character's
   surface (within :data:`NEAR_SHARE` of the body's largest side). A body
   part that is an object of its own (KayKit's arms, legs, head), boots,
   gloves, eyes, a helmet or a cape lies across the plane or has a twin:
   96-100 % of it on KayKit's knight, barbarian, rogue and ranger at rest;
   their shields, two-handed axe, crossbows, mug and quiver 19-63 %;
3. **it sticks out of the body**: over :data:`OUT_SHARE` of its area lies
   farther than :data:`NEAR_SHARE` of the body's largest side from the
   body's surface (the objects that are not small and twinless). Clothes,
   armour, a pouch or an eye patch lie on the body and stay.

The mirror plane runs across x or across y, through the body's bounding-box
centre or the median of its surface, whichever mirrors it best; for each,
the twinless objects are told and the body is told again without them, until
they settle (at most :data:`PASSES` times: a prop widens the body's box on
one side). The plane leaving the body most symmetric is taken, and the body
must be symmetric across it (:data:`.symmetry.SYMMETRY_TOLERANCE`), or no
prop is told: a posed character's own parts lack twins, and leaving an arm
out of the skeleton would be worse than giving a sword bones. Where the
other plane mirrors the body about as well (a round body; not
:data:`.symmetry.CLEARLY_BETTER`), a prop must lack a twin across both. A
prop on the mirror plane (a staff held centred in both hands) or a pair of
them (a sword in each hand, mirrored) has a twin and is not told here:
:mod:`.held_at_hands` tells the thin ones by where they touch the body.

A loose piece joined into a larger object (a sword joined into the body's
mesh, Ctrl+J) is told the same way, piece by piece, but only when it is
held, and only when at most :data:`MAX_TWINLESS_PIECES` pieces lack a twin,
together small (:data:`PROP_AREA_SHARE` of the rest): a piece far from the
body is a part of something held (a weapon's spikes) or of the body, and a
character of many loose parts the mirror plane does not pair (a mech of
plates, a mannequin turned in its file, a body twisted by a Simple Deform)
would lose its limbs. On the 416
cached development characters, pieces are told on 11 (15 pieces): the
weapons of Quaternius' monsters and cyberpunk character, SuperTuxKart's hats
and pendants, blob monsters' horns, a sunfish's fin; their artists weighted
14 of them wholly (95 % or more) to one bone.

A prop is **held** when it comes within :data:`NEAR_SHARE` of the body's
largest side of the body's surface. Its **grip** is the mean of its surface
points that near the body (the handle in the fist, a shield's straps on the
forearm): the rig job binds it wholly to the deform bone whose segment lies
nearest to the grip (:func:`holding_bone`). A prop farther away (set down
beside the character) is left out and not bound.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from ..geometry.bounding_box import largest_side
from ..geometry.closest_point import TriangleMeshQuery
from ..geometry.normals import triangle_double_areas
from ..geometry.segments import point_segment_distances
from ..geometry.topology import connected_component_labels
from ..geometry.weld import seam_tolerance, weld_vertices
from ..types import Mesh, Skeleton
from .character_parts import distance_text
from .nearest_character import surface_points
from .symmetry import CLEARLY_BETTER, SYMMETRY_TOLERANCE

#: A prop holds under this share of the area of the character's other objects (KayKit's two-handed axe: 11 %).
PROP_AREA_SHARE = 0.15
#: An object with at least this share of its surface mirrored onto the character's has a twin (or is its own).
TWIN_SHARE = 0.8
#: Near the body's surface: within this share of the body's largest side (5 cm on a 1.8 m human).
NEAR_SHARE = 0.03
#: A prop has over this share of its area farther than :data:`NEAR_SHARE` from the body.
OUT_SHARE = 0.5
#: Points drawn on the character's surface to tell whether a mirrored point lies on it, the nearest one looked up
#: (on a human about 0.3 % of its largest side apart, a tenth of :data:`NEAR_SHARE`; exact closest points on the
#: triangles made 300 hair cards cost 7 s instead of 2).
SURFACE_SAMPLES = 65536
#: Points drawn on each object's surface, uniformly by area (a share within about 2 %) ...
SAMPLES_PER_OBJECT = 512
#: ... fewer when there are many objects (hundreds of hair cards), these many on them all ...
SAMPLE_BUDGET = 16384
#: ... but at least these many on each (a share within about 6 %).
FEWEST_SAMPLES = 64
#: Points drawn on the body's surface to measure its symmetry, pairs of them voting for where its mirror
#: plane lies (memory grows as the square of their count) ...
BODY_SAMPLES = 2048
#: ... for this many places, each tried with the plane through the body's box centre and its median ...
VOTED_PLANES = 4
#: ... on the first this many of them.
CHOOSING_SAMPLES = 512
#: Most times the body and its mirror plane are told, each time without the objects found twinless the time before.
PASSES = 8
#: A character with more twinless loose pieces than this in its meshes (or pieces holding together
#: :data:`PROP_AREA_SHARE` of the rest's area) has none told (see the module docstring).
MAX_TWINLESS_PIECES = 3
#: Mirror errors (share of the largest side) below this are equal: a symmetric mesh's mirror lands on itself.
MIRROR_NOISE = 1e-3


@dataclass(frozen=True, eq=False)
class Prop:
    """An object of the character that is a rigid prop (:func:`rigid_props`).

    Attributes
    ----------
    object_index : int, the object in the mesh's ``object_names``
    grip : (3,) float array, world space: where it holds on to the body (held), or its point nearest the body
    gap : float, the smallest distance from its vertices and surface points to the body's surface (about 0
        where they meet), scene units
    held : bool, it comes within :data:`NEAR_SHARE` of the body's largest side of the body
    piece : (k,) int array of the mesh's vertex rows when the prop is a loose piece joined into a larger
        object (a sword joined into the body's mesh); None when it is the whole object
    """

    object_index: int
    grip: np.ndarray
    gap: float
    held: bool
    piece: np.ndarray | None = None


def rigid_props(mesh: Mesh, left_out: np.ndarray | None = None) -> tuple[Prop, ...]:
    """The objects of ``mesh`` that are rigid props (see the module docstring),
    in the objects' order.

    Parameters
    ----------
    mesh : Mesh, world space, one or more objects
    left_out : (n,) bool array or None, vertices that are not the character
        (``character_parts``): triangles touching them are neither a prop nor the body

    Returns
    -------
    tuple of Prop, empty when the body is not left-right symmetric or there is one object
    """
    vertices = mesh.vertices
    kept = np.ones(mesh.vertex_count, dtype=bool) if left_out is None else ~np.asarray(left_out, dtype=bool)
    triangles = mesh.triangles[kept[mesh.triangles].all(axis=1)] if len(mesh.triangles) else mesh.triangles
    triangles = triangles[triangle_double_areas(vertices, triangles) > 0]
    # Pieces first; where more of them lack a twin than a character holds, they are no props and the
    # plane their absence let through is not trusted: told again with whole objects only, as before pieces.
    told = _told(mesh, triangles, kept, *_groups(mesh, triangles, pieces=True))
    if told is None:
        told = _told(mesh, triangles, kept, *_groups(mesh, triangles, pieces=False))
    return told or ()


def _told(mesh: Mesh, triangles: np.ndarray, kept: np.ndarray, group_of_vertex: np.ndarray,
          group_object: np.ndarray) -> tuple[Prop, ...] | None:
    """The props among the groups (:func:`_groups`) of ``mesh``'s ``triangles``;
    None when more than :data:`MAX_TWINLESS_PIECES` pieces lack a twin (or
    together hold :data:`PROP_AREA_SHARE` of the rest's area)."""
    vertices = mesh.vertices
    owner = group_of_vertex[triangles[:, 0]]
    if len(np.unique(owner)) < 2:
        return ()
    whole_groups = sum(1 for index in np.unique(owner) if group_object[index] >= 0)
    objects = _Objects(vertices, {int(index): triangles[owner == index] for index in np.unique(owner)},
                       cKDTree(surface_points(vertices, triangles, SURFACE_SAMPLES)), whole_groups)
    area = {index: 0.5 * float(triangle_double_areas(vertices, own).sum()) for index, own in objects.own.items()}
    total_area = sum(area.values())
    # An object with pieces left out (a stray speck in it) is not bound whole: it is never a prop.
    whole = {index for index in objects.own
             if group_object[index] < 0 or kept[mesh.object_slice(int(group_object[index]))].all()}
    small = {index for index in whole if area[index] < PROP_AREA_SHARE * (total_area - area[index])}
    if not small:
        return ()
    # Only a symmetric body tells twins from twinless parts (the objects told with it may have made it lopsided).
    tellings = {}
    for axis in (0, 1):
        telling = _twinless(objects, small, axis)
        if telling is not None and telling[0] <= SYMMETRY_TOLERANCE:
            tellings[axis] = telling[1]
    if len(tellings) == 2:
        tellings = _mirror_planes(objects, tellings)
    candidates = set.intersection(*tellings.values()) if tellings else set()
    pieces = {index for index in candidates if group_object[index] < 0}
    piece_area = sum(area[index] for index in pieces)
    if len(pieces) > MAX_TWINLESS_PIECES or (pieces and piece_area >= PROP_AREA_SHARE * (total_area - piece_area)):
        return None  # many loose parts without twins: the plane does not pair them (a mech, a twisted body)
    if not candidates:
        return ()
    body = objects.triangles_without(candidates)
    near = NEAR_SHARE * largest_side(vertices[np.unique(body)])
    body_query = TriangleMeshQuery(vertices, body)
    props = []
    for index in sorted(candidates):
        points = objects.samples[index]
        distances = body_query.closest(points).distances
        if np.mean(distances > near) <= OUT_SHARE:
            continue  # it lies on the body: clothing, armour
        own_vertices = vertices[np.unique(objects.own[index])]
        gap = min(float(distances.min()), float(body_query.closest(own_vertices).distances.min()))
        touching = distances <= near
        grip = points[touching].mean(axis=0) if touching.any() else points[np.argmin(distances)]
        if group_object[index] >= 0:
            props.append(Prop(int(group_object[index]), grip, gap, gap <= near))
        elif gap <= near:
            # A piece far from the body is part of something held (a weapon's spikes) or of the body: it stays.
            rows = np.flatnonzero(group_of_vertex == index)
            object_index = int(np.searchsorted(mesh.object_offsets, rows[0], side="right") - 1)
            props.append(Prop(object_index, grip, gap, True, rows))
    return tuple(sorted(props, key=lambda prop: prop.object_index))


def carried_props(mesh: Mesh, carried: dict) -> tuple[Prop, ...]:
    """The objects a replaced rig carried on one bone each that stick out of
    the rest (the artist's own word that they are props, twin or not: a
    sword in each hand, a shield), as held props gripped at that bone.

    Parameters
    ----------
    mesh : Mesh, world space, one or more objects
    carried : dict mapping an object index to the (3,) world point of the bone
        that carried it (its middle at rest)

    Returns
    -------
    tuple of Prop (``held`` set, ``grip`` the bone's point), in the objects' order:
    those over :data:`OUT_SHARE` of whose area lies farther than
    :data:`NEAR_SHARE` of the rest's largest side from the rest's surface. A
    helmet or a cape lying on the body stays part of it; nothing is told when
    every object was carried (a robot of parts on bones is its parts).
    """
    vertices = mesh.vertices
    triangles = mesh.triangles[triangle_double_areas(vertices, mesh.triangles) > 0]
    owner = np.searchsorted(mesh.object_offsets, triangles[:, 0], side="right") - 1
    rest = triangles[~np.isin(owner, list(carried))]
    if not len(rest):
        return ()
    near = NEAR_SHARE * largest_side(vertices[np.unique(rest)])
    query = TriangleMeshQuery(vertices, rest)
    props = []
    for index in sorted(carried):
        own = triangles[owner == index]
        if not len(own):
            continue
        distances = query.closest(surface_points(vertices, own, SAMPLES_PER_OBJECT)).distances
        if np.mean(distances > near) > OUT_SHARE:
            props.append(Prop(int(index), np.asarray(carried[index], dtype=np.float64), float(distances.min()), True))
    return tuple(props)


def _groups(mesh: Mesh, triangles: np.ndarray, pieces: bool) -> tuple[np.ndarray, np.ndarray]:
    """What may be a prop: each object small enough to be one (:data:`PROP_AREA_SHARE`
    of the others) as a whole, and with ``pieces`` each loose piece (faces
    joined by edges, seams welded) of the larger objects (a sword joined into
    the body's mesh); without, every object whole.

    Returns
    -------
    group_of_vertex : (n,) int array, each vertex's group (-1 for none: in no triangle of ``triangles``)
    group_object : (g,) int array, the object of each whole-object group, -1 for a piece's
    """
    vertex_object = np.searchsorted(mesh.object_offsets, np.arange(mesh.vertex_count), side="right") - 1
    double_areas = triangle_double_areas(mesh.vertices, triangles)
    object_area = np.bincount(vertex_object[triangles[:, 0]], weights=double_areas,
                              minlength=len(mesh.object_names))
    small_object = object_area < PROP_AREA_SHARE * (object_area.sum() - object_area) if pieces else \
        np.ones(len(mesh.object_names), dtype=bool)
    welded, _, to_welded = weld_vertices(mesh.vertices, triangles, seam_tolerance(mesh))
    piece = connected_component_labels(to_welded[triangles], len(welded))[to_welded]
    objects = len(mesh.object_names)
    # A whole small object is group k < objects; a piece of a larger one is objects + its piece label.
    key = np.where(small_object[vertex_object], vertex_object, objects + piece)
    used = np.zeros(mesh.vertex_count, dtype=bool)
    used[triangles.reshape(-1)] = True
    keys, group = np.unique(key[used], return_inverse=True)
    group_of_vertex = np.full(mesh.vertex_count, -1, dtype=np.int64)
    group_of_vertex[used] = group
    return group_of_vertex, np.where(keys < objects, keys, -1)


@dataclass
class _Objects:
    """The objects of a mesh with an area (or its groups, :func:`_groups`:
    whole objects first, ``whole_objects`` of them, then pieces): (m_i, 3)
    triangles of each (``own``, by group index), points drawn on each
    (``samples``: :data:`SAMPLES_PER_OBJECT`, fewer when there are many
    objects, down to :data:`FEWEST_SAMPLES`) and a tree of
    :data:`SURFACE_SAMPLES` points drawn on them all (``surface``)."""

    vertices: np.ndarray
    own: dict
    surface: cKDTree
    whole_objects: int | None = None
    samples: dict = field(init=False)

    def __post_init__(self):
        # Whole objects share the budget among themselves, so many small pieces of a big one (hair cards joined
        # into the body) do not thin the points of a separate sword; the first ``whole_objects`` groups are whole.
        whole = len(self.own) if self.whole_objects is None else self.whole_objects
        for_whole = max(FEWEST_SAMPLES, min(SAMPLES_PER_OBJECT, SAMPLE_BUDGET // max(whole, 1)))
        for_piece = max(FEWEST_SAMPLES, min(SAMPLES_PER_OBJECT, SAMPLE_BUDGET // max(len(self.own) - whole, 1)))
        self.samples = {index: surface_points(self.vertices, own, for_whole if rank < whole else for_piece)
                        for rank, (index, own) in enumerate(sorted(self.own.items()))}

    def triangles_without(self, left: set) -> np.ndarray:
        """(m, 3) the triangles of the objects not in ``left`` (empty for none)."""
        rest = [own for index, own in self.own.items() if index not in left]
        return np.concatenate(rest) if rest else np.zeros((0, 3), dtype=np.int64)


def _twinless(objects: _Objects, small: set, axis: int) -> tuple[float, set] | None:
    """The ``small`` objects without a twin across the body's mirror plane
    perpendicular to ``axis`` (module docstring), told again without those
    found the time before until they settle: ``(error, twinless)``, the
    error of the body's plane (:func:`_mirror_plane`); None when they never
    settle or nothing is left of the body."""
    chosen = sorted(small)
    # All of their points are queried at once: one query per object costs more than the query itself.
    points = np.concatenate([objects.samples[index] for index in chosen])
    counts = np.array([len(objects.samples[index]) for index in chosen])
    owner = np.repeat(np.arange(len(chosen)), counts)
    twinless: set = set()
    for _ in range(PASSES):
        body = objects.triangles_without(twinless)
        if not len(body):
            return None
        centre, size, error = _mirror_plane(objects.vertices, body, axis)
        near = NEAR_SHARE * size
        on_surface = objects.surface.query(_mirrored(points, axis, centre), distance_upper_bound=near)[0] <= near
        twin_share = np.bincount(owner, weights=on_surface, minlength=len(chosen)) / counts
        found = {index for index, share in zip(chosen, twin_share) if share < TWIN_SHARE}
        if found == twinless:
            return error, twinless
        twinless = found
    return None


def _mirror_planes(objects: _Objects, tellings: dict) -> dict:
    """Of two tellings ``{axis: twinless}``, each leaving the body symmetric
    across its plane, the one whose plane mirrors the body clearly better
    (:data:`.symmetry.CLEARLY_BETTER`), both when neither does (a round
    body). They are compared on the same body, without the objects either
    found twinless: a plane that found more of them twinless must not win
    by what it left out (a cape, twinless front to back)."""
    body = objects.triangles_without(set.union(*tellings.values()))
    if not len(body):
        return {}
    errors = {axis: max(_mirror_plane(objects.vertices, body, axis)[2], MIRROR_NOISE) for axis in tellings}
    best = min(errors, key=errors.get)
    clearly = all(errors[best] < CLEARLY_BETTER * error for axis, error in errors.items() if axis != best)
    return {best: tellings[best]} if clearly else tellings


def _mirror_plane(vertices: np.ndarray, triangles: np.ndarray, axis: int) -> tuple[float, float, float]:
    """The body's mirror plane perpendicular to ``axis``, ``x[axis] =
    centre``: of the planes through its bounding-box centre, the median of
    its surface and the centres its surface votes for
    (:func:`_voted_centres`; a prop the body was told with widens its box
    and moves its median), the one that mirrors its surface best. Returns
    ``(centre, largest side, error)``, the error being the mean distance
    from the mirrored surface to the surface, as a share of the largest side
    (inf for a body of no size)."""
    corners = vertices[np.unique(triangles)]
    size = largest_side(corners)
    if size <= 0:
        return 0.0, 0.0, np.inf
    query = TriangleMeshQuery(vertices, triangles)
    points = surface_points(vertices, triangles, BODY_SAMPLES)
    centres = (0.5 * float(corners[:, axis].min() + corners[:, axis].max()), float(np.median(points[:, axis])),
               *_voted_centres(points, axis, NEAR_SHARE * size))
    # The planes are told apart on a few of the points, the error of the one chosen measured on all.
    _, centre = min((float(query.closest(_mirrored(points[:CHOOSING_SAMPLES], axis, centre)).distances.mean()),
                     centre) for centre in centres)
    return centre, size, float(query.closest(_mirrored(points, axis, centre)).distances.mean()) / size


def _voted_centres(points: np.ndarray, axis: int, near: float) -> list[float]:
    """Where the mirror plane perpendicular to ``axis`` may lie: pairs of
    ``points`` (k, 3) level with each other across it (their other two
    coordinates within a third of ``near``) and farther apart than ``near``
    along it vote for their midpoint, in bins a third of ``near`` wide; the
    mean midpoint of each of the :data:`VOTED_PLANES` fullest bins, none
    next to another (a mirror's pairs all vote for one bin)."""
    width = near / 3.0
    if width <= 0:
        return []
    level = [other for other in range(3) if other != axis]
    pairs = cKDTree(points[:, level]).query_pairs(width, output_type="ndarray")
    first, second = points[pairs[:, 0], axis], points[pairs[:, 1], axis]
    midpoints = (0.5 * (first + second))[np.abs(first - second) > near]
    if not len(midpoints):
        return []
    bins = np.floor(midpoints / width).astype(np.int64)
    values, counts = np.unique(bins, return_counts=True)
    chosen: list = []
    for value in values[np.argsort(-counts, kind="stable")]:
        if all(abs(value - other) > 1 for other in chosen):
            chosen.append(value)
        if len(chosen) == VOTED_PLANES:
            break
    return [float(midpoints[np.abs(bins - value) <= 1].mean()) for value in chosen]


def _mirrored(points: np.ndarray, axis: int, centre: float) -> np.ndarray:
    """(k, 3) ``points`` mirrored across the plane ``x[axis] = centre``."""
    mirrored = points.copy()
    mirrored[:, axis] = 2.0 * centre - mirrored[:, axis]
    return mirrored


#: Bone segments at most this much farther from a prop's grip than the nearest (share of the skeleton's largest
#: side) hold it as well as the nearest (:func:`holding_bone`).
GRIP_TIE = 0.01


def holding_bone(grip: np.ndarray, skeleton: Skeleton) -> str:
    """The deform bone holding a prop: the one whose segment (head to tail)
    lies nearest to its ``grip`` (3,) (a sword's grip in the fist: the hand;
    with Rigify's rig, its DEF- bone). Of segments as near within
    :data:`GRIP_TIE`, the one the grip lies nearest the head of: a grip
    where the forearm ends and the hand begins is in the hand, which turns it
    with the wrist (a wrist read a centimetre nearer the fingers, as a
    longer-trained landmark network reads the procedural biped's, left its
    sword on the forearm). ``skeleton`` needs a deform bone."""
    deform = np.flatnonzero(skeleton.deform)
    grip = np.asarray(grip, dtype=np.float64)
    heads, tails = skeleton.joints[deform], skeleton.tails[deform]
    distances = point_segment_distances(grip[None], heads, tails)[0]
    extent = np.ptp(np.concatenate([skeleton.joints, skeleton.tails]), axis=0).max()
    near = np.flatnonzero(distances <= distances.min() + GRIP_TIE * extent)
    along = np.einsum("ij,ij->i", grip - heads[near], tails[near] - heads[near])
    lengths = np.einsum("ij,ij->i", tails[near] - heads[near], tails[near] - heads[near])
    shares = np.where(lengths > 0.0, along / np.where(lengths > 0.0, lengths, 1.0), 0.0)
    return skeleton.names[deform[int(near[np.argmin(np.clip(shares, 0.0, 1.0))])]]


# --------------------------------------------------------------------------- wording


def piece_text(vertices: int) -> str:
    """How a report names a prop joined into a mesh: "a loose piece of 232 vertices"."""
    return f"a loose piece of {vertices} vertices"


def held_note(bone: str) -> str:
    """What the report says, after a held prop's name, once it is bound."""
    return f"held: bound wholly to bone '{bone}' (a rigid prop, left out of the skeleton)"


def prop_notes(mesh: Mesh, props, *, bound: bool) -> list[str]:
    """What the report says about each prop before the skeleton exists
    (``bound``: the run binds the meshes; a held prop's note then comes
    with its bone, :func:`held_note`)."""
    notes = []
    for prop in props:
        name = mesh.object_names[prop.object_index]
        if prop.piece is not None:
            if not bound:
                notes.append(f"'{name}': {piece_text(len(prop.piece))} is held: a rigid prop, left out of the skeleton")
            continue
        if not prop.held:
            notes.append(f"'{name}' lies {distance_text(prop.gap)} from the character and nothing holds it: left out "
                         "of the skeleton" + (" and not bound" if bound else "") + " (a prop set down?)")
        elif not bound:
            notes.append(f"'{name}' is held: a rigid prop, left out of the skeleton")
    return notes
