"""Procedural rigged characters: a skeleton, a surface and skin weights from one seed.

:func:`generate_character` draws a skeleton morphology (biped, quadruped,
many-legged, winged, tailed, long chain, fish or prop), grows a body around
it and derives the weights from how each piece was built:

* **Body shells** are generalised cylinders (elliptical rings of varying
  radius, rounded end caps) around chains of bones, plus ellipsoids for heads.
  A ring's vertices take the bone the ring lies on, blended
  linearly with the neighbouring bone inside a joint region. Shells overlap
  and intersect where limbs meet the torso, as many game characters are
  built; each shell on its own is closed, watertight and outward facing.
* **Rigid accessories** (eyes, helmets, swords, buttons, horns, feathers,
  prop pieces) follow exactly one bone.
* **Clothing shells** (skirt, cape, blanket) are open surfaces offset from the
  body. Either they take the body's weights at the closest body point, or
  they get their own bones placed outside the body and weights that follow
  those bones.
* **Parts driven by bones outside the body**: skirt and cape bones, hair
  chains, an anglerfish lure, a sword on a floating weapon bone.

Everything is drawn from ``numpy.random.default_rng(seed)`` in a fixed order,
so a seed always gives the same arrays. No bpy: the Blender layer converts
the result to objects.

Conventions: metres, z up, characters face -y, left side (``.L``) at +x.
Symmetric kinds are built on the left and mirrored across x = 0, so ``.L``
and ``.R`` joints mirror each other exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.spatial import cKDTree

from . import templates
from ..geometry.closest_point import closest_points_on_triangles
from ..geometry.segments import polyline_arc_lengths
from ..errors import InputError
from ..types import Mesh, Skeleton, Weights

#: Character kinds :func:`generate_character` can make.
KINDS = ("biped", "quadruped", "multileg", "winged", "tailed", "long_chain", "fish", "prop")

#: Part types (``ProceduralCharacter.part_types``).
PART_BODY = "body"  # shell grown around bones; weights blend along the bones
PART_RIGID = "rigid"  # closed accessory moved by exactly one bone
PART_CLOTH = "cloth"  # open shell offset from the body; body weights at the closest body point
PART_DRIVEN = "driven"  # surface moved by its own bones, placed outside the body
PART_TYPES = (PART_BODY, PART_RIGID, PART_CLOTH, PART_DRIVEN)

#: Spacing of tube rings, as a fraction of the skeleton's bounding-box diagonal.
RING_SPACING_FRACTION = 1.0 / 55.0
#: Fewest and most vertices around one ring of a tube or ellipsoid.
MIN_RING_SEGMENTS = 6
MAX_RING_SEGMENTS = 16
#: Rings in each rounded end cap of a tube, besides the pole.
CAP_RINGS = 2
#: Length of a rounded end cap as a fraction of the end ring's smaller radius.
CAP_LENGTH_FACTOR = 0.9
#: A chain bending more than this (degrees) at a joint becomes two
#: overlapping shells there, so rings do not fold through each other.
TUBE_SPLIT_ANGLE_DEG = 55.0
#: Half-width of the zone where a tube vertex blends two bones, as a fraction
#: of the shorter bone; each character draws one value from this range.
JOINT_BLEND_RANGE = (0.15, 0.45)
#: Gap between a clothing shell and the body, as a fraction of the skeleton's
#: bounding-box diagonal; each garment draws one value from this range.
CLOTH_GAP_RANGE = (0.006, 0.02)
#: Body triangles examined per cloth vertex when looking for the closest body point.
CLOSEST_POINT_CANDIDATES = 8
#: Distances equal within this (relative to 1 + the distance) count as ties.
TIE_TOLERANCE = 1e-9
#: Body vertices consulted per point when draping a sheet over the body.
DRAPE_NEIGHBOURS = 12
#: Probability that a character gets a non-deforming ``root`` bone at the floor.
ROOT_BONE_PROBABILITY = 0.5

#: Probability of each optional piece, per character of a kind that can have it.
ACCESSORY_PROBABILITY = {
    "eyes": 0.8,
    "fingers": 0.5,
    "breasts": 0.2,
    "helmet": 0.2,
    "hat": 0.2,
    "sword": 0.3,
    "shield": 0.2,
    "belt": 0.35,
    "buttons": 0.35,
    "backpack": 0.2,
    "skirt": 0.3,
    "cape": 0.25,
    "ponytail": 0.25,
    "garment_bones": 0.5,  # skirt or cape driven by its own bones rather than by the body
    "ears": 0.6,
    "horns": 0.3,
    "collar": 0.3,
    "blanket": 0.3,
    "saddle": 0.2,
    "spikes": 0.35,
    "antennae": 0.7,
    "insect_wings": 0.5,
    "stinger": 0.3,
    "lure": 0.3,
    "door_frame": 0.6,
    "door_handle": 0.7,
    "lamp_upper_arm": 0.6,
    "chest_lock": 0.5,
}

#: Overall size of each kind, metres: the height of bipeds (tailed humanoids
#: too) and birds, the largest extent of many-legged creatures and long
#: chains, the length front to back of the others.
SIZE_RANGE = {
    "biped": (0.4, 2.4),
    "quadruped": (0.3, 3.0),
    "multileg": (0.05, 2.0),
    "bird": (0.15, 1.6),
    "dragon": (1.0, 8.0),
    "tailed": (0.3, 6.0),
    "long_chain": (0.5, 6.0),
    "fish": (0.15, 8.0),
}


@dataclass(frozen=True)
class ProceduralCharacter:
    """A generated character with the weights it was built with.

    Attributes
    ----------
    mesh : Mesh
        The surface (one object), all parts concatenated.
    skeleton : Skeleton
        Bones, parents first; control bones have ``deform`` False.
    weights : Weights
        (n, j) ground-truth weights, one column per skeleton bone in skeleton
        order; rows non-negative and summing to one; control bone columns zero.
    kind : str
        One of :data:`KINDS`.
    variant : str
        Sub-kind, e.g. ``"spider"``, ``"dragon"``, ``"door"``.
    parts : (n,) int64 array
        Index into ``part_names`` of the piece each vertex belongs to.
    part_names : tuple of str
        Name of each piece (``"arm.L"``, ``"helmet"``...).
    part_types : tuple of str
        One of :data:`PART_TYPES` per piece.
    part_closed : (p,) bool array
        Whether each piece is a closed surface (every edge in two triangles).
    seed : int
    """

    mesh: Mesh
    skeleton: Skeleton
    weights: Weights
    kind: str
    variant: str
    parts: np.ndarray
    part_names: tuple
    part_types: tuple
    part_closed: np.ndarray
    seed: int


def generate_character(seed: int, kind: str | None = None) -> ProceduralCharacter:
    """Build one rigged character from ``seed``.

    Parameters
    ----------
    seed : int
        Non-negative; the same seed (and kind) always gives identical arrays.
    kind : str or None
        One of :data:`KINDS`; None draws the kind from the seed.

    Returns
    -------
    ProceduralCharacter
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError(f"The seed must be a non-negative integer, got {seed!r}.")
    if kind is not None and kind not in KINDS:
        raise InputError(f"Unknown character kind {kind!r}; use one of {', '.join(KINDS)} or None.")
    rng = np.random.default_rng(int(seed))
    chosen = KINDS[int(rng.integers(len(KINDS)))] if kind is None else kind
    builder = _Character(rng)
    variant = _BUILDERS[chosen](builder)
    return builder.finish(chosen, variant, int(seed))


def generate_characters(seeds: Sequence[int], kind: str | None = None):
    """Yield :func:`generate_character` for each seed (a lazy data set)."""
    for seed in seeds:
        yield generate_character(seed, kind)


# ---------------------------------------------------------------------------
# Small geometry helpers
# ---------------------------------------------------------------------------

_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])


def _unit(vectors: np.ndarray) -> np.ndarray:
    """Vectors scaled to unit length along the last axis (zero stays zero)."""
    vectors = np.asarray(vectors, dtype=np.float64)
    norms = np.linalg.norm(vectors, axis=-1, keepdims=True)
    return vectors / np.maximum(norms, 1e-300)


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """(3, 3) rotation by ``angle`` radians about ``axis`` (right hand rule)."""
    x, y, z = _unit(axis)
    skew = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * skew + (1.0 - np.cos(angle)) * (skew @ skew)


def _frame(axis: np.ndarray, hint: np.ndarray) -> np.ndarray:
    """(3, 3) right-handed frame with columns (x, y, z): z along ``axis``,
    x along the part of ``hint`` perpendicular to it."""
    z = _unit(axis)
    x = hint - np.dot(hint, z) * z
    if np.linalg.norm(x) < 1e-6 * max(np.linalg.norm(hint), 1e-300):
        other = _X if abs(z[0]) < 0.9 else _Y
        x = other - np.dot(other, z) * z
    x = _unit(x)
    return np.column_stack([x, np.cross(z, x), z])


def _mirror_name(name: str) -> str:
    """Blender's left/right name flip for a ``.L`` / ``.R`` suffix."""
    if name.endswith(".L"):
        return name[:-2] + ".R"
    if name.endswith(".R"):
        return name[:-2] + ".L"
    return name


def _chain_names(base: str, count: int, suffix: str = "") -> list:
    """``base``, ``base.001``, ... with an optional side ``suffix`` (``.L``)."""
    return [base + suffix] + [f"{base}.{i:03d}{suffix}" for i in range(1, count)]


def _ring_segments(radius: float, spacing: float) -> int:
    """Even vertex count around a ring of ``radius`` for edges near ``spacing``."""
    count = int(np.clip(np.ceil(2.0 * np.pi * radius / spacing), MIN_RING_SEGMENTS, MAX_RING_SEGMENTS))
    return count + (count % 2)


def _projected_normals(tangents: np.ndarray, up: np.ndarray) -> np.ndarray:
    """(r, 3) unit normals: ``up`` made perpendicular to each tangent.

    When ``up`` comes close to a tangent, the coordinate axis most
    perpendicular to every tangent replaces it, so no ring degenerates.
    """
    candidates = np.vstack([_unit(up), np.eye(3)])
    sines = np.linalg.norm(np.cross(tangents[None, :, :], candidates[:, None, :]), axis=2).min(axis=1)
    reference = candidates[0] if sines[0] > 0.3 else candidates[int(np.argmax(sines))]
    normals = reference[None, :] - (tangents @ reference)[:, None] * tangents
    return _unit(normals)


def _lathe(centres, tangents, normals, radii, segments, start_pole=None, end_pole=None, phase=0.0):
    """Rings swept along a curve, optionally closed by a pole at each end.

    Parameters
    ----------
    centres, tangents, normals : (k, 3) float64 arrays
        Ring centres, unit ring axes and unit in-plane reference directions.
    radii : (k, 2) float64 array
        Ring semi-axes along ``normals`` and along ``tangents x normals``.
    segments : int
        Vertices per ring.
    start_pole, end_pole : (3,) float64 array or None
        Extra vertex closing the first / last ring with a fan.

    Returns
    -------
    vertices : (k * segments [+ 2], 3) float64 array
    triangles : (t, 3) int64 array
        Counter-clockwise seen from outside (outside = away from the axis,
        or beyond the poles).
    ring : (v,) int64 array
        Ring index of each vertex (poles belong to the ring they close).
    """
    count = len(centres)
    binormals = np.cross(tangents, normals)
    angles = phase + 2.0 * np.pi * np.arange(segments) / segments
    rings = (
        centres[:, None, :]
        + (radii[:, 0, None] * np.cos(angles)[None, :])[:, :, None] * normals[:, None, :]
        + (radii[:, 1, None] * np.sin(angles)[None, :])[:, :, None] * binormals[:, None, :]
    )
    vertices = [rings.reshape(-1, 3)]
    ring = [np.repeat(np.arange(count), segments)]
    j = np.arange(segments)
    j_next = (j + 1) % segments
    i = np.arange(count - 1)[:, None]
    a, b = i * segments + j, i * segments + j_next
    c, d = (i + 1) * segments + j_next, (i + 1) * segments + j
    triangles = [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    next_index = count * segments
    if start_pole is not None:
        vertices.append(np.asarray(start_pole, dtype=np.float64)[None, :])
        ring.append(np.zeros(1, dtype=np.int64))
        triangles.append(np.stack([np.full(segments, next_index), j_next, j], -1))
        next_index += 1
    if end_pole is not None:
        last = (count - 1) * segments
        vertices.append(np.asarray(end_pole, dtype=np.float64)[None, :])
        ring.append(np.full(1, count - 1, dtype=np.int64))
        triangles.append(np.stack([last + j, last + j_next, np.full(segments, next_index)], -1))
    return np.concatenate(vertices), np.concatenate(triangles).astype(np.int64), np.concatenate(ring)


def _ellipsoid_geometry(centre, radii, frame, spacing, cut_angle=0.0):
    """Closed ellipsoid (or a dome cut flat at polar angle ``cut_angle``).

    ``radii`` (3,) are the semi-axes along the columns of ``frame``; the poles
    lie on the third axis. ``cut_angle`` in [0, pi/2] removes the cap below
    it and closes the cut with a flat disc (a helmet shape).
    """
    radii = np.asarray(radii, dtype=np.float64)
    segments = _ring_segments(max(radii[0], radii[1]), spacing)
    ring_count = max(3, segments // 2 - 1)
    if cut_angle > 0.0:
        theta = np.linspace(cut_angle, np.pi, ring_count + 1, endpoint=False)
    else:
        theta = np.pi * np.arange(1, ring_count + 1) / (ring_count + 1)
    local_z = -radii[2] * np.cos(theta)
    centres = centre + local_z[:, None] * frame[:, 2][None, :]
    ring_radii = np.column_stack([radii[0] * np.sin(theta), radii[1] * np.sin(theta)])
    tangents = np.repeat(frame[:, 2][None, :], len(theta), axis=0)
    normals = np.repeat(frame[:, 0][None, :], len(theta), axis=0)
    start = centres[0] if cut_angle > 0.0 else centre - radii[2] * frame[:, 2]
    vertices, triangles, _ = _lathe(centres, tangents, normals, ring_radii, segments, start, centre + radii[2] * frame[:, 2])
    return vertices, triangles


def _prism_geometry(centre, half_length, radii, frame, segments, phase=0.0):
    """Closed prism along the frame's third axis with flat capped ends;
    ``radii`` (2,) are the ring semi-axes. Four segments with phase pi/4
    give a box whose half extents are ``radii / sqrt(2)``."""
    axis = frame[:, 2]
    centres = np.stack([centre - half_length * axis, centre + half_length * axis])
    tangents = np.stack([axis, axis])
    normals = np.stack([frame[:, 0], frame[:, 0]])
    ring_radii = np.array([radii, radii], dtype=np.float64)
    vertices, triangles, _ = _lathe(centres, tangents, normals, ring_radii, segments, centres[0], centres[1], phase)
    return vertices, triangles


def _box_geometry(centre, half_extents, frame):
    """Closed box: ``half_extents`` (3,) along the columns of ``frame``."""
    half_extents = np.asarray(half_extents, dtype=np.float64)
    radii = np.sqrt(2.0) * half_extents[:2]
    return _prism_geometry(np.asarray(centre, dtype=np.float64), half_extents[2], radii, frame, 4, np.pi / 4)


def _cone_geometry(base_centre, radius, height, frame, spacing):
    """Closed cone from a base disc of ``radius`` to an apex ``height`` along
    the frame's third axis."""
    segments = _ring_segments(radius, spacing)
    axis = frame[:, 2]
    centres = np.asarray(base_centre, dtype=np.float64)[None, :]
    vertices, triangles, _ = _lathe(
        centres, axis[None, :], frame[:, 0][None, :], np.array([[radius, radius]]), segments, centres[0], centres[0] + height * axis
    )
    return vertices, triangles


def _torus_geometry(centre, major_radii, minor_radius, frame, spacing):
    """Closed torus around the frame's third axis; the core is an ellipse
    with semi-axes ``major_radii`` (2,) along the first two frame axes."""
    major_radii = np.asarray(major_radii, dtype=np.float64)
    around = int(np.clip(np.ceil(2 * np.pi * major_radii.max() / spacing), 12, 40))
    tube = _ring_segments(minor_radius, spacing)
    u = 2.0 * np.pi * np.arange(around) / around
    v = 2.0 * np.pi * np.arange(tube) / tube
    core = major_radii[0] * np.cos(u)[:, None] * frame[:, 0] + major_radii[1] * np.sin(u)[:, None] * frame[:, 1]
    outward = _unit(np.cos(u)[:, None] / major_radii[0] * frame[:, 0] + np.sin(u)[:, None] / major_radii[1] * frame[:, 1])
    points = (
        centre
        + core[:, None, :]
        + minor_radius * np.cos(v)[None, :, None] * outward[:, None, :]
        + minor_radius * np.sin(v)[None, :, None] * frame[:, 2][None, None, :]
    )
    i = np.arange(around)[:, None]
    j = np.arange(tube)[None, :]
    a, b = i * tube + j, ((i + 1) % around) * tube + j
    c, d = ((i + 1) % around) * tube + (j + 1) % tube, i * tube + (j + 1) % tube
    triangles = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    vertices = points.reshape(-1, 3)
    if _signed_volume(vertices, triangles) < 0:
        triangles = triangles[:, ::-1]
    return vertices, np.ascontiguousarray(triangles)


def _grid_triangles(rows: int, columns: int) -> np.ndarray:
    """(2 (rows-1) (columns-1), 3) triangles of an open rows x columns grid."""
    i = np.arange(rows - 1)[:, None]
    j = np.arange(columns - 1)[None, :]
    a, b = i * columns + j, i * columns + j + 1
    c, d = (i + 1) * columns + j + 1, (i + 1) * columns + j
    return np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]).astype(np.int64)


def _face_towards(vertices, triangles, direction) -> np.ndarray:
    """``triangles`` flipped if their summed normal points against ``direction``."""
    corners = vertices[triangles]
    normal_sum = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]).sum(axis=0)
    return np.ascontiguousarray(triangles[:, ::-1]) if np.dot(normal_sum, direction) < 0 else triangles


def _signed_volume(vertices, triangles) -> float:
    """Volume enclosed by a closed surface; positive when it faces outward."""
    corners = vertices[triangles]
    return float(np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0)


def _resample_polyline(points: np.ndarray, count: int) -> np.ndarray:
    """(count, 3) points evenly spaced by arc length along a polyline."""
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(lengths)])
    targets = np.linspace(0.0, arc[-1], count)
    return np.column_stack([np.interp(targets, arc, points[:, k]) for k in range(3)])


def _closest_point_weights(points, body_vertices, body_triangles, body_weights):
    """Body weights interpolated at the closest body point of each point.

    The closest point is searched among the :data:`CLOSEST_POINT_CANDIDATES`
    triangles whose centroids are nearest, which finds the true closest
    point on the smooth, evenly meshed shells built here. A point at the
    same distance from several distinct places takes their mean.

    Parameters
    ----------
    points : (m, 3) float64 array
    body_vertices : (n, 3) float64 array
    body_triangles : (t, 3) int64 array
    body_weights : (n, b) float64 array

    Returns
    -------
    (m, b) float64 array
    """
    corners = body_vertices[body_triangles]
    tree = cKDTree(corners.mean(axis=1))
    count = min(CLOSEST_POINT_CANDIDATES, len(body_triangles))
    _, candidates = tree.query(points, k=count)
    candidates = candidates.reshape(len(points), count)
    flat = candidates.reshape(-1)
    repeated = np.repeat(points, count, axis=0)
    closest, bary = closest_points_on_triangles(repeated, corners[flat, 0], corners[flat, 1], corners[flat, 2])
    distance = np.linalg.norm(closest - repeated, axis=1).reshape(len(points), count)
    closest = closest.reshape(len(points), count, 3)
    # Points equally far from several places (a skirt's midline between the
    # legs) average them, so symmetric bodies give symmetric cloth weights.
    tolerance = TIE_TOLERANCE * (1.0 + distance.min(axis=1, keepdims=True))
    tied = distance <= distance.min(axis=1, keepdims=True) + tolerance
    same_place = np.linalg.norm(closest[:, :, None, :] - closest[:, None, :, :], axis=3) <= tolerance[:, :, None]
    earlier_twin = (np.tril(same_place, k=-1) & tied[:, None, :]).any(axis=2)
    use = tied & ~earlier_twin
    candidate_weights = np.einsum("mkc,mkcb->mkb", bary.reshape(len(points), count, 3), body_weights[body_triangles[candidates]])
    return (use[:, :, None] * candidate_weights).sum(axis=1) / use.sum(axis=1, keepdims=True)


def _joint_blend_weights(arc, joint_arc, blend, with_parent, with_child):
    """Weights along a chain: each bone owns its stretch, blending linearly
    into its neighbour within ``blend`` x (shorter bone) of each joint.

    Parameters
    ----------
    arc : (n,) float64 array
        Arc length of each sample along the chain.
    joint_arc : (k + 1,) float64 array
        Arc length of each joint (0 first, chain length last).
    blend : float
        Half-width of a joint region as a fraction of the shorter bone (< 0.5).
    with_parent, with_child : bool
        Whether the chain blends into a bone before its first joint / after
        its last joint.

    Returns
    -------
    (n, k + with_parent + with_child) float64 array
        Columns: [parent], bones in chain order, [child]; rows sum to one.
    """
    lengths = np.maximum(np.diff(joint_arc), 1e-12)
    count = len(lengths)
    shorter = np.concatenate([[lengths[0]], np.minimum(lengths[:-1], lengths[1:]), [lengths[-1]]])
    half_width = blend * shorter
    rise = np.clip((arc[:, None] - joint_arc[None, :]) / (2.0 * half_width[None, :]) + 0.5, 0.0, 1.0)
    if not with_parent:
        rise[:, 0] = 1.0
    if not with_child:
        rise[:, count] = 0.0
    columns = [rise[:, :count] - rise[:, 1:]]
    if with_parent:
        columns.insert(0, 1.0 - rise[:, :1])
    if with_child:
        columns.append(rise[:, count:])
    return np.concatenate(columns, axis=1)




# ---------------------------------------------------------------------------
# Rig and parts under construction
# ---------------------------------------------------------------------------


class _Rig:
    """Bones under construction (mutable; parents added before children)."""

    def __init__(self):
        self.names: list = []
        self.heads: list = []
        self.tails: list = []
        self.parents: list = []
        self.deform: list = []
        self.index: dict = {}

    def add(self, name, head, tail, parent=None, deform=True):
        if name in self.index:
            raise ValueError(f"bone {name} added twice")
        if parent is not None and parent not in self.index:
            raise ValueError(f"parent {parent} of {name} does not exist yet")
        self.index[name] = len(self.names)
        self.names.append(name)
        self.heads.append(np.array(head, dtype=np.float64))
        self.tails.append(np.array(tail, dtype=np.float64))
        self.parents.append(parent)
        self.deform.append(bool(deform))
        return name

    def add_chain(self, names, start, directions, lengths, parent=None):
        """Connected bones from ``start`` along ``directions`` (k, 3)."""
        position = np.asarray(start, dtype=np.float64)
        for name, direction, length in zip(names, directions, lengths):
            tail = position + length * _unit(direction)
            self.add(name, position, tail, parent)
            parent, position = name, tail
        return list(names)

    def has(self, name) -> bool:
        return name in self.index

    def head(self, name) -> np.ndarray:
        return self.heads[self.index[name]]

    def tail(self, name) -> np.ndarray:
        return self.tails[self.index[name]]

    def direction(self, name) -> np.ndarray:
        return _unit(self.tail(name) - self.head(name))

    def length(self, name) -> float:
        return float(np.linalg.norm(self.tail(name) - self.head(name)))

    def set_tail(self, name, tail):
        self.tails[self.index[name]] = np.array(tail, dtype=np.float64)

    def place(self, name, head, tail):
        """Move bone ``name`` (and its mirrored twin, if any) to ``head``/``tail``."""
        self.heads[self.index[name]] = np.array(head, dtype=np.float64)
        self.tails[self.index[name]] = np.array(tail, dtype=np.float64)
        twin = _mirror_name(name)
        if twin != name and twin in self.index:
            mirror = np.array([-1.0, 1.0, 1.0])
            self.heads[self.index[twin]] = self.heads[self.index[name]] * mirror
            self.tails[self.index[twin]] = self.tails[self.index[name]] * mirror

    def subtree(self, name) -> list:
        """Indices of ``name`` and all its descendants."""
        members = {name}
        for bone, parent in zip(self.names, self.parents):
            if parent in members:
                members.add(bone)
        return [self.index[bone] for bone in self.names if bone in members]

    def transform(self, indices, function):
        for k in indices:
            self.heads[k] = function(self.heads[k])
            self.tails[k] = function(self.tails[k])

    def rotate_subtree(self, name, axis, angle, pivot=None):
        pivot = self.head(name).copy() if pivot is None else np.asarray(pivot, dtype=np.float64)
        rotation = _rotation(axis, angle)
        self.transform(self.subtree(name), lambda p: pivot + rotation @ (p - pivot))

    def raise_subtree(self, name, angle):
        """Swing ``name`` and its children up (towards +z) by ``angle``
        radians about its head; negative angles lower it."""
        axis = np.cross(self.direction(name), _Z)
        if np.linalg.norm(axis) < 1e-9:
            axis = _X
        self.rotate_subtree(name, axis, angle)

    def translate_subtree(self, name, offset):
        self.transform(self.subtree(name), lambda p: p + offset)

    def transform_all(self, function):
        self.transform(range(len(self.names)), function)

    def points(self) -> np.ndarray:
        return np.vstack([np.array(self.heads), np.array(self.tails)])

    def deforming_parent(self, name):
        """Nearest deforming ancestor of ``name`` (None for none)."""
        parent = self.parents[self.index[name]]
        while parent is not None and not self.deform[self.index[parent]]:
            parent = self.parents[self.index[parent]]
        return parent

    def symmetrize(self):
        """Add a ``.R`` twin, mirrored across x = 0, for every ``.L`` bone
        that has none yet."""
        for k in range(len(self.names)):
            name = self.names[k]
            twin = _mirror_name(name)
            if name.endswith(".L") and twin not in self.index:
                parent = self.parents[k]
                mirror = np.array([-1.0, 1.0, 1.0])
                self.add(twin, self.heads[k] * mirror, self.tails[k] * mirror,
                         None if parent is None else _mirror_name(parent), self.deform[k])

    def path_points(self, bones) -> np.ndarray:
        """(k + 1, 3) joints of a path through ``bones`` (consecutive bones
        touch at one end; each may point either way along the path)."""
        ends = [(self.head(b), self.tail(b)) for b in bones]
        if len(bones) == 1:
            return np.stack(ends[0])

        def gap(point, k):
            return min(np.linalg.norm(point - ends[k][0]), np.linalg.norm(point - ends[k][1]))

        start, end = ends[0] if gap(ends[0][1], 1) <= gap(ends[0][0], 1) else ends[0][::-1]
        points = [start]
        for head, tail in ends[1:]:
            near, far = (head, tail) if np.linalg.norm(head - end) <= np.linalg.norm(tail - end) else (tail, head)
            points.append(0.5 * (end + near))
            end = far
        points.append(end)
        return np.array(points)


@dataclass
class _Part:
    name: str
    part_type: str
    closed: bool
    vertices: np.ndarray
    triangles: np.ndarray
    bone_names: tuple
    weights: np.ndarray


def _mirrored_part(part: _Part) -> _Part:
    vertices = part.vertices * np.array([-1.0, 1.0, 1.0])
    return _Part(
        _mirror_name(part.name), part.part_type, part.closed, vertices, np.ascontiguousarray(part.triangles[:, ::-1]),
        tuple(_mirror_name(b) for b in part.bone_names), part.weights.copy(),
    )


def _stack_weight_blocks(blocks):
    """Row blocks of weights with their own column names -> one matrix over
    the union of names (first-seen order); equal names add up."""
    names = []
    for block_names, _ in blocks:
        for name in block_names:
            if name not in names:
                names.append(name)
    column = {name: k for k, name in enumerate(names)}
    matrix = np.zeros((sum(len(w) for _, w in blocks), len(names)))
    row = 0
    for block_names, block in blocks:
        for k, name in enumerate(block_names):
            matrix[row:row + len(block), column[name]] += block[:, k]
        row += len(block)
    return tuple(names), matrix


class _Character:
    """A character under construction: the rig, the parts, the random stream."""

    def __init__(self, rng: np.random.Generator):
        self.rng = rng
        self.rig = _Rig()
        self.parts: list = []
        self.size = 1.0  # bounding-box diagonal of the finished skeleton, metres
        self.spacing = 0.05
        self.blend = float(rng.uniform(*JOINT_BLEND_RANGE))

    # -- random helpers -------------------------------------------------
    def uniform(self, low, high) -> float:
        return float(self.rng.uniform(low, high))

    def chance(self, what: str) -> bool:
        return bool(self.rng.random() < ACCESSORY_PROBABILITY[what])

    # -- skeleton -----------------------------------------------------------
    def maybe_root(self) -> str | None:
        """A non-deforming ``root`` bone at the origin, half of the time."""
        if self.rng.random() < ROOT_BONE_PROBABILITY:
            return self.rig.add("root", [0.0, 0.0, 0.0], [0.0, 0.3, 0.0], None, deform=False)
        return None

    def place_template(self, table, length_factor, lateral_factor=None, keep=None, root_parent=None):
        """Add a baked metarig with each bone's length scaled by
        ``length_factor[name]`` (default 1). Bones connected in the template
        stay connected; other offsets scale with the parent's factor, and
        their x with ``lateral_factor[name]`` (shoulder and hip width)."""
        lateral_factor = lateral_factor or {}
        template_heads, template_tails = {}, {}
        for name, parent, head, tail, deform in table:
            if keep is not None and name not in keep:
                continue
            head, tail = np.array(head), np.array(tail)
            template_heads[name], template_tails[name] = head, tail
            if parent is None:
                new_head = head.copy()
            elif np.allclose(head, template_tails[parent], atol=1e-4):
                new_head = self.rig.tail(parent).copy()
            else:
                offset = (head - template_heads[parent]) * length_factor.get(parent, 1.0)
                offset[0] *= lateral_factor.get(name, 1.0)
                new_head = self.rig.head(parent) + offset
            new_tail = new_head + (tail - head) * length_factor.get(name, 1.0)
            self.rig.add(name, new_head, new_tail, root_parent if parent is None else parent, deform)

    def fit_size(self, size: float, axis: int | None = 2) -> float:
        """Scale the rig so its extent along ``axis`` (None: largest extent)
        equals ``size``, put its lowest point on z = 0 and centre it on x = 0
        and y; returns the scale factor."""
        points = self.rig.points()
        extent = points.max(0) - points.min(0)
        scale = size / (extent.max() if axis is None else extent[axis])
        low = points.min(0) * scale
        high = points.max(0) * scale
        shift = np.array([0.0, -0.5 * (low[1] + high[1]), -low[2]])
        self.rig.transform_all(lambda p: p * scale + shift)
        return scale

    def settle(self):
        """Mirror the left side and fix the mesh resolution from the rig size."""
        self.rig.symmetrize()
        points = self.rig.points()
        self.size = float(np.linalg.norm(points.max(0) - points.min(0)))
        self.spacing = self.size * RING_SPACING_FRACTION

    # -- parts ------------------------------------------------------------
    def add_part(self, part: _Part, mirror: bool = False):
        self.parts.append(part)
        if mirror:
            self.parts.append(_mirrored_part(part))

    def tube(self, name, bones, radii, up=_Z, part_type=PART_BODY, parent="auto", child=None, mirror=False, bulge=None):
        """A closed shell around the path of ``bones``.

        Parameters
        ----------
        radii : (k + 1, 2) float64 array, or callable
            Ring semi-axes at each joint of the path (k bones): along ``up``
            made perpendicular to the path, and across; linear in between.
            A callable maps (r,) fractions of the path length to (r, 2).
        bulge : (k,) float64 array or None
            Extra fractional radius at the middle of each bone (muscle).
        parent : "auto", str or None
            Bone the first bone blends into at the path start ("auto": its
            nearest deforming ancestor).
        child : str or None
            Bone the last bone blends into at the path end.
        """
        points = self.rig.path_points(bones)
        bulge = np.zeros(len(bones)) if bulge is None else np.asarray(bulge, dtype=np.float64)
        lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
        joint_arc = np.concatenate([[0.0], np.cumsum(lengths)])
        profile = radii if callable(radii) else None
        radii = None if profile else np.asarray(radii, dtype=np.float64)

        def radius_at(arc):
            bone = np.clip(np.searchsorted(joint_arc, arc, side="right") - 1, 0, len(bones) - 1)
            fraction = np.clip((arc - joint_arc[bone]) / np.maximum(lengths[bone], 1e-12), 0.0, 1.0)
            if profile is not None:
                base = profile(np.clip(arc / joint_arc[-1], 0.0, 1.0))
            else:
                base = np.column_stack([np.interp(arc, joint_arc, radii[:, 0]), np.interp(arc, joint_arc, radii[:, 1])])
            return base * (1.0 + bulge[bone] * np.sin(np.pi * fraction))[:, None]

        directions = _unit(np.diff(points, axis=0))
        bends = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", directions[:-1], directions[1:]), -1.0, 1.0)))
        cuts = [0] + [k + 1 for k in np.flatnonzero(bends > TUBE_SPLIT_ANGLE_DEG)] + [len(bones)]
        first_parent = self.rig.deforming_parent(bones[0]) if parent == "auto" else parent
        vertex_blocks, triangle_blocks, weight_blocks, offset = [], [], [], 0
        for start, stop in zip(cuts[:-1], cuts[1:]):
            vertices, triangles, arc = self._tube_shell(points[start:stop + 1], joint_arc[start], radius_at, up)
            before = bones[start - 1] if start > 0 else first_parent
            after = bones[stop] if stop < len(bones) else child
            weights = _joint_blend_weights(
                arc - joint_arc[start], joint_arc[start:stop + 1] - joint_arc[start], self.blend, before is not None, after is not None
            )
            names = ([before] if before is not None else []) + list(bones[start:stop]) + ([after] if after is not None else [])
            vertex_blocks.append(vertices)
            triangle_blocks.append(triangles + offset)
            weight_blocks.append((names, weights))
            offset += len(vertices)
        names, weights = _stack_weight_blocks(weight_blocks)
        part = _Part(name, part_type, True, np.concatenate(vertex_blocks), np.concatenate(triangle_blocks), names, weights)
        self.add_part(part, mirror)
        return part

    def _tube_shell(self, points, arc_offset, radius_at, up):
        """One closed tube along ``points`` with rounded caps; returns
        vertices, triangles and each vertex's arc length along the full path."""
        lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
        per_bone = np.maximum(1, np.ceil(lengths / self.spacing).astype(np.int64))
        bone = np.repeat(np.arange(len(lengths)), per_bone)
        fraction = (np.arange(per_bone.sum()) - np.repeat(np.cumsum(per_bone) - per_bone, per_bone)) / np.repeat(per_bone, per_bone)
        bone = np.append(bone, len(lengths) - 1)
        fraction = np.append(fraction, 1.0)
        centres = points[bone] + fraction[:, None] * (points[bone + 1] - points[bone])
        arc = arc_offset + np.concatenate([[0.0], np.cumsum(lengths)])[bone] + fraction * lengths[bone]
        forward = _unit(np.diff(centres, axis=0))
        tangents = np.vstack([forward[:1], _unit(forward[:-1] + forward[1:]), forward[-1:]])
        radii = radius_at(arc)
        normals = _projected_normals(tangents, up)
        theta = 0.5 * np.pi * np.arange(1, CAP_RINGS + 1) / (CAP_RINGS + 1)
        start_length = CAP_LENGTH_FACTOR * radii[0].min()
        end_length = CAP_LENGTH_FACTOR * radii[-1].min()
        start_caps = centres[0] - np.outer(start_length * np.sin(theta[::-1]), tangents[0])
        end_caps = centres[-1] + np.outer(end_length * np.sin(theta), tangents[-1])
        all_centres = np.vstack([start_caps, centres, end_caps])
        all_radii = np.vstack([np.outer(np.cos(theta[::-1]), radii[0]), radii, np.outer(np.cos(theta), radii[-1])])
        all_tangents = np.vstack([np.repeat(tangents[:1], CAP_RINGS, 0), tangents, np.repeat(tangents[-1:], CAP_RINGS, 0)])
        all_normals = np.vstack([np.repeat(normals[:1], CAP_RINGS, 0), normals, np.repeat(normals[-1:], CAP_RINGS, 0)])
        all_arc = np.concatenate([np.full(CAP_RINGS, arc[0]), arc, np.full(CAP_RINGS, arc[-1])])
        segments = _ring_segments(float(radii.max()), self.spacing)
        vertices, triangles, ring = _lathe(
            all_centres, all_tangents, all_normals, all_radii, segments,
            centres[0] - start_length * tangents[0], centres[-1] + end_length * tangents[-1],
        )
        return vertices, triangles, all_arc[ring]

    def rigid(self, name, geometry, bone, part_type=PART_RIGID, mirror=False):
        """A closed piece moved only by ``bone``; ``geometry`` is (vertices, triangles)."""
        vertices, triangles = geometry
        part = _Part(name, part_type, True, vertices, triangles, (bone,), np.ones((len(vertices), 1)))
        self.add_part(part, mirror)
        return part

    def body_surface(self, names=None):
        """Vertices, triangles and (n, bones) weights of the closed body
        shells so far (only those called ``names``, if given)."""
        body = [p for p in self.parts if p.part_type == PART_BODY and p.closed and (names is None or p.name in names)]
        if not body:
            raise ValueError("no body shells yet")
        offsets = np.cumsum([0] + [len(p.vertices) for p in body])
        names, weights = _stack_weight_blocks([(p.bone_names, p.weights) for p in body])
        vertices = np.concatenate([p.vertices for p in body])
        triangles = np.concatenate([p.triangles + o for p, o in zip(body, offsets)])
        return vertices, triangles, names, weights

    def cloth(self, name, vertices, triangles, body=None):
        """An open shell weighted by the body's weights at its closest point
        on the body shells (those called ``body``, if given)."""
        body_vertices, body_triangles, names, body_weights = self.body_surface(body)
        weights = _closest_point_weights(vertices, body_vertices, body_triangles, body_weights)
        used = np.flatnonzero(weights.max(axis=0) > 0)
        self.add_part(_Part(name, PART_CLOTH, False, vertices, triangles, tuple(names[k] for k in used), weights[:, used]))

    def extent_along(self, origin, direction, reach, body=None) -> float:
        """How far the body surface lies from ``origin`` along ``direction``,
        using body vertices within ``reach`` of that ray."""
        vertices = self.body_surface(body)[0]
        direction = _unit(direction)
        relative = vertices - origin
        along = relative @ direction
        across = np.linalg.norm(relative - along[:, None] * direction, axis=1)
        near = (across < reach) & (along > 0)
        return float(along[near].max()) if near.any() else 0.0

    def band_ellipse(self, height, thickness, centre_xy, body=None):
        """(2,) semi-axes (x, y) of the smallest ellipse around ``centre_xy``,
        with the aspect of the band's bounding box, that encloses the body
        vertices whose z lies within ``thickness`` of ``height``."""
        vertices = self.body_surface(body)[0]
        band = vertices[np.abs(vertices[:, 2] - height) < thickness][:, :2] - centre_xy
        if len(band) == 0:
            return np.array([self.spacing, self.spacing])
        half = np.maximum(np.abs(band).max(axis=0), 1e-6)
        scale = np.sqrt(((band / half) ** 2).sum(axis=1).max())
        return half * scale

    def drape(self, grid_2d, plane_axes, normal_axis, gap, body=None):
        """Height over the body of each 2-D grid point: the farthest body
        vertex along ``normal_axis`` among the :data:`DRAPE_NEIGHBOURS`
        nearest in the plane, plus ``gap``."""
        vertices = self.body_surface(body)[0]
        tree = cKDTree(vertices[:, plane_axes])
        _, nearest = tree.query(grid_2d.reshape(-1, 2), k=DRAPE_NEIGHBOURS)
        return vertices[nearest, normal_axis].max(axis=1).reshape(grid_2d.shape[:-1]) + gap

    # -- result -------------------------------------------------------------
    def finish(self, kind, variant, seed) -> ProceduralCharacter:
        skeleton = Skeleton(
            np.array(self.rig.heads), np.array([self.rig.index[p] if p is not None else -1 for p in self.rig.parents]),
            tuple(self.rig.names), np.array(self.rig.tails), np.array(self.rig.deform),
        )
        vertex_counts = [len(p.vertices) for p in self.parts]
        offsets = np.cumsum([0] + vertex_counts)
        weights = np.zeros((offsets[-1], skeleton.bone_count))
        for part, start in zip(self.parts, offsets):
            columns = [self.rig.index[b] for b in part.bone_names]
            weights[start:start + len(part.vertices), columns] += part.weights
        weights /= weights.sum(axis=1, keepdims=True)
        mesh = Mesh(
            np.concatenate([p.vertices for p in self.parts]),
            np.concatenate([p.triangles + o for p, o in zip(self.parts, offsets)]),
            object_names=(f"{kind}_{seed}",),
        )
        return ProceduralCharacter(
            mesh=mesh,
            skeleton=skeleton,
            weights=Weights(weights, skeleton.names),
            kind=kind,
            variant=variant,
            parts=np.repeat(np.arange(len(self.parts)), vertex_counts).astype(np.int64),
            part_names=tuple(p.name for p in self.parts),
            part_types=tuple(p.part_type for p in self.parts),
            part_closed=np.array([p.closed for p in self.parts], dtype=bool),
            seed=seed,
        )


# ---------------------------------------------------------------------------
# Pieces shared by several kinds
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class _Ellipsoid:
    """An ellipsoidal head or body: centre (3,), semi-axes (3,) along the
    columns of frame (3, 3)."""

    centre: np.ndarray
    radii: np.ndarray
    frame: np.ndarray

    def surface_point(self, direction: np.ndarray) -> np.ndarray:
        """Where the ray from the centre along world ``direction`` leaves the surface."""
        local = self.frame.T @ _unit(direction)
        return self.centre + self.frame @ (local / np.sqrt(((local / self.radii) ** 2).sum()))


def _head_ellipsoid(ch, bone, radii_fraction, centre_fraction, unit_scale=1.0) -> _Ellipsoid:
    """Ellipsoid around a head bone: semi-axes ``radii_fraction`` (across,
    up, along) times the bone length (times ``unit_scale``), centred
    ``centre_fraction`` of the way from head to tail."""
    rig = ch.rig
    length = rig.length(bone)
    frame = _frame(rig.direction(bone), _Z if abs(rig.direction(bone)[2]) < 0.9 else -_Y)
    # frame columns: (up-ish, across, along); reorder radii to match.
    across, up, along = np.asarray(radii_fraction) * length * unit_scale
    centre = rig.head(bone) + centre_fraction * (rig.tail(bone) - rig.head(bone))
    return _Ellipsoid(centre, np.array([up, across, along]), frame)


def _vertical_head(ch, bone, radii_fraction, centre_fraction) -> _Ellipsoid:
    """Ellipsoid for an upright head bone; semi-axes (x, y, z) as fractions
    of the bone length, world-aligned."""
    rig = ch.rig
    centre = rig.head(bone) + centre_fraction * (rig.tail(bone) - rig.head(bone))
    return _Ellipsoid(centre, np.asarray(radii_fraction) * rig.length(bone), np.eye(3))


#: Eye radius as a fraction of the head's smallest semi-axis.
EYE_SIZE_RANGE = (0.12, 0.3)
#: How far apart the eyes sit: sideways component of the gaze direction.
EYE_SPREAD_RANGE = (0.25, 0.9)


def _add_eyes(ch, head: _Ellipsoid, bone: str, forward=-_Y):
    """Two spheres on the head surface, one per side, each moved only by
    ``bone`` (mirrored names are used when the bone has a side)."""
    radius = ch.uniform(*EYE_SIZE_RANGE) * head.radii.min()
    direction = _unit(forward + ch.uniform(*EYE_SPREAD_RANGE) * _X + ch.uniform(0.1, 0.5) * _Z)
    surface = head.surface_point(direction)
    centre = surface - 0.4 * radius * direction
    centre[0] = max(centre[0], 1.05 * radius)
    geometry = _ellipsoid_geometry(centre, np.full(3, radius), np.eye(3), ch.spacing)
    if bone.endswith(".L"):
        # An eye bone of its own sits at the eye's centre, looking out.
        ch.rig.place(bone, centre, centre + 2.0 * radius * direction)
    ch.rigid("eye.L", geometry, bone, mirror=True)


def _add_helmet_or_hat(ch, head: _Ellipsoid, bone: str):
    if ch.chance("helmet"):
        radii = head.radii * ch.uniform(1.08, 1.2)
        cut = np.arccos(ch.uniform(-0.1, 0.3))
        frame = np.eye(3)
        ch.rigid("helmet", _ellipsoid_geometry(head.centre, radii, frame, ch.spacing, cut), bone)
    elif ch.chance("hat"):
        top = head.centre + np.array([0.0, 0.0, 0.75 * head.radii[2]])
        crown_height = ch.uniform(0.5, 1.5) * head.radii[2]
        crown_radius = ch.uniform(0.6, 0.9) * head.radii[0]
        segments = _ring_segments(crown_radius, ch.spacing)
        crown = _prism_geometry(top + [0, 0, 0.5 * crown_height], 0.5 * crown_height, (crown_radius, crown_radius), np.eye(3), segments)
        ch.rigid("hat", crown, bone)
        brim_radius = ch.uniform(1.3, 2.0) * head.radii[0]
        brim = _prism_geometry(top, 0.04 * head.radii[2], (brim_radius, brim_radius), np.eye(3), _ring_segments(brim_radius, ch.spacing))
        ch.rigid("hat_brim", brim, bone)


def _add_horns(ch, head: _Ellipsoid, bone: str):
    root = head.surface_point(np.array([ch.uniform(0.3, 0.8), -ch.uniform(0.0, 0.6), 1.0]))
    direction = _unit(np.array([ch.uniform(0.1, 0.8), ch.uniform(-0.6, 0.6), 1.0]))
    length = ch.uniform(0.5, 2.0) * head.radii.max()
    radius = ch.uniform(0.12, 0.3) * head.radii.min()
    base = root - 0.3 * length * direction
    ch.rigid("horn.L", _cone_geometry(base, radius, 1.3 * length, _frame(direction, _X), ch.spacing), bone, mirror=True)


def _add_spikes(ch, bones):
    """A cone on the back over the middle of each bone, moved by that bone."""
    height_scale = ch.uniform(0.5, 1.5)
    for k, bone in enumerate(bones):
        middle = 0.5 * (ch.rig.head(bone) + ch.rig.tail(bone))
        top = ch.extent_along(middle, _Z, 2.0 * ch.spacing)
        if top <= 0.0:
            continue
        height = height_scale * max(top, ch.spacing)
        radius = 0.35 * height
        base = middle + (top - 0.25 * height) * _Z
        direction = _unit(_Z + 0.4 * ch.rig.direction(bone))
        ch.rigid(f"spike.{k:03d}", _cone_geometry(base, radius, height, _frame(direction, _X), ch.spacing), bone)


def _add_collar(ch, bone: str, radii: np.ndarray):
    """A ring around a neck bone's head; ``radii`` (2,) of the neck there."""
    direction = ch.rig.direction(bone)
    minor = 0.25 * radii.min()
    frame = _frame(direction, _Z)
    ch.rigid("collar", _torus_geometry(ch.rig.head(bone) + 0.3 * ch.rig.length(bone) * direction, radii + minor, minor, frame, ch.spacing), bone)


def _sheet_rows(count_low, length, spacing):
    return max(count_low, int(np.ceil(length / spacing)) + 1)


def _add_blanket(ch, front_bone: str, back_bone: str, half_width: float):
    """A cloth sheet draped over the back between two spine bones."""
    y_front = ch.rig.head(front_bone)[1]
    y_back = ch.rig.head(back_bone)[1]
    rows = _sheet_rows(3, abs(y_back - y_front), ch.spacing)
    columns = _sheet_rows(3, 2 * half_width, ch.spacing)
    x, y = np.meshgrid(np.linspace(-half_width, half_width, columns), np.linspace(y_front, y_back, rows))
    grid = np.stack([x, y], axis=-1)
    gap = ch.uniform(*CLOTH_GAP_RANGE) * ch.size
    z = ch.drape(grid, [0, 1], 2, gap, {"torso"})
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    triangles = _face_towards(vertices, _grid_triangles(rows, columns), _Z)
    ch.cloth("blanket", vertices, triangles, {"torso"})


def _add_saddle(ch, bone: str, size: float):
    middle = 0.5 * (ch.rig.head(bone) + ch.rig.tail(bone))
    top = ch.extent_along(middle, _Z, 2.0 * ch.spacing, {"torso"})
    half = np.array([0.6, 0.8, 0.25]) * size
    ch.rigid("saddle", _box_geometry(middle + (top + 0.5 * half[2]) * _Z, half, np.eye(3)), bone)


def _bone_radii(radii, scale):
    return np.asarray(radii, dtype=np.float64) * scale


# ---------------------------------------------------------------------------
# Biped (Rigify basic human)
# ---------------------------------------------------------------------------

#: Random factors of the biped's proportions (1 = Rigify basic human).
BIPED_PROPORTIONS = {
    "leg": (0.65, 1.3), "arm": (0.75, 1.3), "torso": (0.8, 1.25), "neck": (0.5, 1.8), "head": (0.8, 1.8),
    "hand": (0.8, 1.4), "foot": (0.8, 1.3), "shoulder": (0.7, 1.4), "hips": (0.75, 1.35),
    "thickness": (0.65, 1.5), "limb_thickness": (0.7, 1.4),
}
#: How far the arms hang below horizontal in the rest pose (0 = T-pose), degrees.
BIPED_ARM_DROP_DEG = (0.0, 50.0)
#: Largest forward bend of the elbow and outward spread of the legs at rest, degrees.
BIPED_ELBOW_BEND_DEG = 25.0
BIPED_LEG_SPREAD_DEG = 10.0
#: Shell semi-axes in template metres, at the joints of each chain.
BIPED_TORSO_RADII = ((0.115, 0.16), (0.105, 0.15), (0.10, 0.135), (0.115, 0.165), (0.075, 0.10), (0.055, 0.055), (0.055, 0.055))
BIPED_TORSO_BULGE = (0.0, 0.0, 0.05, 0.12, 0.0, 0.0)
BIPED_ARM_RADII = ((0.045, 0.045), (0.052, 0.052), (0.04, 0.04), (0.03, 0.03))
BIPED_ARM_BULGE = (0.0, 0.08, 0.1)
BIPED_HAND_RADII = ((0.02, 0.038), (0.016, 0.036))  # (thickness, width)
BIPED_LEG_RADII = ((0.085, 0.085), (0.055, 0.055), (0.04, 0.04))
BIPED_LEG_BULGE = (0.1, 0.15)
BIPED_FOOT_RADII = ((0.042, 0.045), (0.025, 0.042), (0.016, 0.032))  # (height, width)
BIPED_FINGER_RADIUS = 0.009
#: Head semi-axes (across, front-back, up) as fractions of the head bone.
BIPED_HEAD_RADII = (0.48, 0.55, 0.6)
#: Fingers: name, place across the hand (-1 little finger side .. 1 thumb side), phalanx lengths (template metres).
BIPED_FINGERS = (
    ("f_index", 0.6, (0.032, 0.022, 0.018)),
    ("f_middle", 0.2, (0.035, 0.024, 0.019)),
    ("f_ring", -0.2, (0.033, 0.022, 0.018)),
    ("f_pinky", -0.6, (0.026, 0.018, 0.015)),
)
BIPED_THUMB_LENGTHS = (0.025, 0.02, 0.018)


def _add_finger_bones(ch):
    """Rigify-named finger chains on the left hand (template metres)."""
    rig = ch.rig
    wrist, knuckles = rig.head("hand.L"), rig.tail("hand.L")
    along = _unit(knuckles - wrist)
    palm_normal = _unit(_Z - np.dot(_Z, along) * along)
    thumb_side = _unit(np.cross(along, palm_normal))
    half_width = BIPED_HAND_RADII[1][1]
    names = []
    for base, place, lengths in BIPED_FINGERS:
        direction = _unit(along + 0.2 * place * thumb_side)
        directions = [_unit(direction - 0.15 * k * palm_normal) for k in range(3)]
        chain = [f"{base}.{k + 1:02d}.L" for k in range(3)]
        rig.add_chain(chain, knuckles + place * half_width * thumb_side, directions, lengths, "hand.L")
        names.append(chain)
    thumb_direction = _unit(0.6 * along + 0.8 * thumb_side - 0.3 * palm_normal)
    chain = [f"thumb.{k + 1:02d}.L" for k in range(3)]
    start = wrist + 0.35 * (knuckles - wrist) + 0.7 * half_width * thumb_side
    rig.add_chain(chain, start, [thumb_direction] * 3, BIPED_THUMB_LENGTHS, "hand.L")
    names.append(chain)
    return names


def _build_biped(ch, tail_bones: int = 0) -> str:
    factor = {name: ch.uniform(*limits) for name, limits in BIPED_PROPORTIONS.items()}
    lengths = {
        "spine": factor["torso"], "spine.001": factor["torso"], "spine.002": factor["torso"], "spine.003": factor["torso"],
        "spine.004": factor["neck"], "spine.005": factor["neck"], "spine.006": factor["head"],
        "thigh.L": factor["leg"], "shin.L": factor["leg"], "upper_arm.L": factor["arm"], "forearm.L": factor["arm"],
        "hand.L": factor["hand"], "foot.L": factor["foot"], "toe.L": factor["foot"], "heel.02.L": factor["foot"],
        "shoulder.L": factor["shoulder"],
    }
    lateral = {"thigh.L": factor["hips"], "shoulder.L": factor["shoulder"], "upper_arm.L": factor["shoulder"]}
    keep = {row[0] for row in templates.HUMAN}
    with_breasts = ch.chance("breasts")
    if not with_breasts:
        keep.discard("breast.L")
    root = ch.maybe_root()
    ch.place_template(templates.HUMAN, lengths, lateral, keep, root)
    rig = ch.rig
    rig.set_tail("shoulder.L", rig.head("upper_arm.L"))
    elevation = np.arcsin(np.clip(rig.direction("upper_arm.L")[2], -1, 1))
    rig.raise_subtree("upper_arm.L", -np.radians(ch.uniform(*BIPED_ARM_DROP_DEG)) - elevation)
    rig.rotate_subtree("forearm.L", _Z, -np.radians(ch.uniform(0.0, BIPED_ELBOW_BEND_DEG)))
    rig.rotate_subtree("thigh.L", _Y, -np.radians(ch.uniform(0.0, BIPED_LEG_SPREAD_DEG)))
    fingers = _add_finger_bones(ch) if ch.chance("fingers") else []
    tail = []
    if tail_bones:
        tail = _grow_tail(ch, "tail", "spine", rig.head("spine") + np.array([0.0, 0.08, 0.0]), _unit([0.0, 1.0, -0.6]),
                          ch.uniform(0.5, 1.2), tail_bones, ch.uniform(-12.0, 12.0))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["biped"]))
    thick = factor["thickness"] * unit
    limb = thick * factor["limb_thickness"]
    ch.settle()

    torso = ["spine", "spine.001", "spine.002", "spine.003", "spine.004", "spine.005"]
    ch.tube("torso", torso, _bone_radii(BIPED_TORSO_RADII, thick), up=-_Y, child="spine.006", bulge=BIPED_TORSO_BULGE)
    head = _vertical_head(ch, "spine.006", BIPED_HEAD_RADII, 0.45)
    ch.rigid("head", _ellipsoid_geometry(head.centre, head.radii, head.frame, ch.spacing), "spine.006", PART_BODY)
    ch.tube("arm.L", ["shoulder.L", "upper_arm.L", "forearm.L"], _bone_radii(BIPED_ARM_RADII, limb), up=_Z, mirror=True, bulge=BIPED_ARM_BULGE)
    ch.tube("hand.L", ["hand.L"], _bone_radii(BIPED_HAND_RADII, limb), up=_Z, mirror=True)
    for chain in fingers:
        radius = BIPED_FINGER_RADIUS * limb
        ch.tube(chain[0].split(".")[0] + ".L", chain, [(radius, radius)] * 3 + [(0.75 * radius, 0.75 * radius)], up=_Z, mirror=True)
    ch.tube("leg.L", ["thigh.L", "shin.L"], _bone_radii(BIPED_LEG_RADII, limb), up=-_Y, mirror=True, bulge=BIPED_LEG_BULGE)
    ch.tube("foot.L", ["foot.L", "toe.L"], _bone_radii(BIPED_FOOT_RADII, limb), up=_Z, mirror=True)
    if with_breasts:
        length = rig.length("breast.L")
        centre = rig.head("breast.L") + 0.55 * (rig.tail("breast.L") - rig.head("breast.L"))
        radii = np.array([0.6, 0.45, 0.55]) * length
        ch.rigid("breast.L", _ellipsoid_geometry(centre, radii, np.eye(3), ch.spacing), "breast.L", PART_BODY, mirror=True)
    if tail:
        radius = 0.05 * thick
        ch.tube("tail", tail, np.linspace(1.0, 0.25, len(tail) + 1)[:, None] * [radius, radius], up=_Z)
    _biped_accessories(ch, head)
    return "tailed_humanoid" if tail else "humanoid"


#: Body shells that clothing wraps (arms and tails pass through garments).
_BIPED_TRUNK = frozenset({"torso", "leg.L", "leg.R"})


def _biped_accessories(ch, head: _Ellipsoid):
    rig = ch.rig
    height = rig.points()[:, 2].max()
    if ch.chance("eyes"):
        _add_eyes(ch, head, "spine.006")
    _add_helmet_or_hat(ch, head, "spine.006")
    if ch.chance("belt"):
        waist = rig.head("spine.001")
        radii = ch.band_ellipse(waist[2], ch.spacing, waist[:2], _BIPED_TRUNK)
        minor = ch.uniform(0.008, 0.02) * height
        ch.rigid("belt", _torus_geometry(waist, radii + 0.5 * minor, minor, np.eye(3), ch.spacing), "spine.001")
    if ch.chance("buttons"):
        count = int(ch.rng.integers(2, 6))
        low, high = rig.head("spine.002")[2], rig.tail("spine.003")[2] - 0.3 * rig.length("spine.003")
        radius = ch.uniform(0.008, 0.015) * height
        for k, z in enumerate(np.linspace(low, high, count)):
            bone = "spine.002" if z < rig.head("spine.003")[2] else "spine.003"
            origin = np.array([0.0, rig.head(bone)[1], z])
            front = ch.extent_along(origin, -_Y, 1.5 * ch.spacing, _BIPED_TRUNK)
            centre = origin - (front + 0.2 * radius) * _Y
            ch.rigid(f"button.{k:03d}", _ellipsoid_geometry(centre, np.array([radius, 0.5 * radius, radius]), np.eye(3), ch.spacing), bone)
    if ch.chance("backpack"):
        middle = 0.5 * (rig.head("spine.003") + rig.tail("spine.003"))
        back = ch.extent_along(middle, _Y, 1.5 * ch.spacing, _BIPED_TRUNK)
        half = np.array([ch.uniform(0.08, 0.14), ch.uniform(0.04, 0.08), ch.uniform(0.1, 0.16)]) * height
        ch.rigid("backpack", _box_geometry(middle + (back + 0.8 * half[1]) * _Y, half, np.eye(3)), "spine.003")
    if ch.chance("sword"):
        _add_sword(ch, height)
    if ch.chance("shield"):
        forearm = 0.5 * (rig.head("forearm.L") + rig.tail("forearm.L"))
        radius = ch.uniform(0.1, 0.16) * height
        centre = forearm - (ch.extent_along(forearm, -_Y, ch.spacing, {"arm.L"}) + 0.01 * height) * _Y
        shield = _prism_geometry(centre, 0.006 * height, (radius, radius), _frame(-_Y, _Z), _ring_segments(radius, ch.spacing))
        ch.rigid("shield", shield, "forearm.L")
    if ch.chance("skirt"):
        _add_skirt(ch, driven=ch.chance("garment_bones"))
    if ch.chance("cape"):
        _add_cape(ch, driven=ch.chance("garment_bones"))
    if ch.chance("ponytail"):
        _add_ponytail(ch, head, "spine.006")


def _add_sword(ch, height):
    """A sword on a floating ``weapon`` bone held in the right hand."""
    rig = ch.rig
    grip = rig.tail("hand.R") + 0.3 * (rig.tail("hand.R") - rig.head("hand.R"))
    blade = ch.uniform(0.25, 0.45) * height
    rig.add("weapon", grip, grip - blade * _Y, "hand.R")
    grip_radius, grip_half = 0.012 * height, 0.05 * height
    frame = _frame(-_Y, _Z)
    pieces = [
        _prism_geometry(grip, grip_half, (grip_radius, grip_radius), frame, 6),
        _box_geometry(grip - grip_half * _Y, np.array([0.005, 0.06, 0.01]) * height, frame),
        _box_geometry(grip - (grip_half + 0.5 * blade) * _Y, np.array([0.004, 0.02, 0.5 * blade / height]) * height, frame),
    ]
    for k, piece in enumerate(pieces):
        ch.rigid(f"sword.{k:03d}", piece, "weapon")


#: Skirt bone chains around the waist (even counts keep the rig symmetric).
SKIRT_CHAIN_COUNTS = (4, 6, 8)


def _add_skirt(ch, driven: bool):
    """An open skirt from the waist down, offset from the body. ``driven``:
    give it its own bone chains on its surface; otherwise it takes the body's
    weights at the closest body point."""
    rig = ch.rig
    top, hem = rig.head("spine.001")[2], rig.head("shin.L")[2] + ch.uniform(-0.2, 0.5) * rig.length("thigh.L")
    centre_y = rig.head("spine")[1]
    gap = ch.uniform(*CLOTH_GAP_RANGE) * ch.size
    rows = _sheet_rows(3, top - hem, ch.spacing)
    heights = np.linspace(top, hem, rows)
    radii = np.array([ch.band_ellipse(z, ch.spacing, np.array([0.0, centre_y]), _BIPED_TRUNK) for z in heights]) + gap
    radii = np.maximum.accumulate(radii, axis=0)  # flare out, never in, going down
    centres = np.column_stack([np.zeros(rows), np.full(rows, centre_y), heights])
    tangents = np.repeat(-_Z[None], rows, axis=0)
    normals = np.repeat(-_Y[None], rows, axis=0)
    segments = _ring_segments(float(radii.max()), ch.spacing) + 4
    vertices, triangles, _ = _lathe(centres, tangents, normals, radii[:, ::-1], segments)
    if not driven:
        ch.cloth("skirt", vertices, triangles, _BIPED_TRUNK)
        return
    count = SKIRT_CHAIN_COUNTS[int(ch.rng.integers(len(SKIRT_CHAIN_COUNTS)))]
    chains = []
    middle = rows // 2
    for k in range(count // 2 + 1):
        angle = 2.0 * np.pi * k / count
        on_centre = k == 0 or k == count // 2
        suffix = "" if on_centre else ".L"
        points = centres[[0, middle, rows - 1]] + np.column_stack(
            [radii[[0, middle, rows - 1], 0] * np.sin(angle), -radii[[0, middle, rows - 1], 1] * np.cos(angle), np.zeros(3)]
        )
        if on_centre:
            points[:, 0] = 0.0
        names = _chain_names(f"skirt_{k:02d}", 2, suffix)
        rig.add(names[0], points[0], points[1], "spine")
        rig.add(names[1], points[1], points[2], names[0])
        chains.append((angle, names))
    rig.symmetrize()
    for angle, names in list(chains):
        if names[0].endswith(".L"):
            chains.append((-angle, [_mirror_name(n) for n in names]))
    chains.sort(key=lambda item: item[0])
    chain_angles = np.array([a for a, _ in chains])
    vertex_angles = np.arctan2(vertices[:, 0], -(vertices[:, 1] - centre_y))
    # Periodic linear interpolation between the two chains around each vertex.
    wrapped = np.concatenate([chain_angles, [chain_angles[0] + 2 * np.pi]])
    position = np.interp(np.mod(vertex_angles - chain_angles[0], 2 * np.pi) + chain_angles[0], wrapped, np.arange(len(wrapped)))
    lower = np.floor(position).astype(np.int64)
    upper_share = position - lower
    blocks = []
    for k, (_, names) in enumerate(chains):
        share = np.where(lower % len(chains) == k, 1.0 - upper_share, 0.0) + np.where((lower + 1) % len(chains) == k, upper_share, 0.0)
        polyline = rig.path_points(names)
        arc = polyline_arc_lengths(vertices, polyline)
        joint_arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(polyline, axis=0), axis=1))])
        along = _joint_blend_weights(arc, joint_arc, ch.blend, True, False)
        blocks.append((["spine"] + names, along * share[:, None]))
    names, weights = _sum_weight_columns(blocks)
    ch.add_part(_Part("skirt", PART_DRIVEN, False, vertices, triangles, names, weights))


def _sum_weight_columns(blocks):
    """Several (names, (n, k)) weight blocks over the same rows, summed by name."""
    names = []
    for block_names, _ in blocks:
        names.extend(n for n in block_names if n not in names)
    column = {n: k for k, n in enumerate(names)}
    weights = np.zeros((len(blocks[0][1]), len(names)))
    for block_names, block in blocks:
        for k, name in enumerate(block_names):
            weights[:, column[name]] += block[:, k]
    return tuple(names), weights


def _add_cape(ch, driven: bool):
    """An open cape hanging behind the back from the shoulders."""
    rig = ch.rig
    top = rig.head("spine.004")[2]
    bottom = max(rig.head("shin.L")[2] - ch.uniform(0.0, 0.6) * rig.length("shin.L"), 0.05 * top)
    half_width = ch.uniform(0.9, 1.3) * abs(rig.head("upper_arm.L")[0])
    rows = _sheet_rows(3, top - bottom, ch.spacing)
    columns = 2 * (_sheet_rows(2, half_width, ch.spacing) // 2) + 1
    x, z = np.meshgrid(np.linspace(-half_width, half_width, columns), np.linspace(top, bottom, rows))
    gap = ch.uniform(*CLOTH_GAP_RANGE) * ch.size
    y = ch.drape(np.stack([x, z], axis=-1), [0, 2], 1, gap, _BIPED_TRUNK | {"head"})
    y = np.maximum.accumulate(y, axis=0)  # hang straight down past the buttocks
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    triangles = _face_towards(vertices, _grid_triangles(rows, columns), _Y)
    if not driven:
        ch.cloth("cape", vertices, triangles, _BIPED_TRUNK | {"head"})
        return
    centre_column = vertices.reshape(rows, columns, 3)[:, columns // 2]
    joints = centre_column[np.linspace(0, rows - 1, 4).round().astype(int)]
    names = _chain_names("cape", 3)
    for k, name in enumerate(names):
        rig.add(name, joints[k], joints[k + 1], "spine.003" if k == 0 else names[k - 1])
    arc = polyline_arc_lengths(vertices, joints)
    joint_arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(joints, axis=0), axis=1))])
    weights = _joint_blend_weights(arc, joint_arc, ch.blend, True, False)
    ch.add_part(_Part("cape", PART_DRIVEN, False, vertices, triangles, tuple(["spine.003"] + names), weights))


def _add_ponytail(ch, head: _Ellipsoid, bone: str):
    """A hair chain hanging from the back of the head on its own bones."""
    start = head.centre + np.array([0.0, 0.8 * head.radii[1], 0.3 * head.radii[2]])
    length = ch.uniform(1.0, 3.0) * head.radii[2]
    directions = [_unit([0.0, 0.8, -0.3]), _unit([0.0, 0.35, -1.0]), _unit([0.0, 0.1, -1.0])]
    names = ch.rig.add_chain(_chain_names("hair", 3), start, directions, [0.3 * length, 0.35 * length, 0.35 * length], bone)
    radius = ch.uniform(0.2, 0.4) * head.radii[0]
    radii = np.array([[1.0, 1.0], [0.9, 0.9], [0.7, 0.7], [0.3, 0.3]]) * radius
    ch.tube("ponytail", names, radii, up=_Y, part_type=PART_DRIVEN)


def _grow_tail(ch, base, parent, start, direction, length, count, bend_deg, suffix=""):
    """A connected chain ``base``, ``base.001``... whose bones shorten
    towards the tip and bend by ``bend_deg`` each (positive curls up)."""
    lengths = 0.88 ** np.arange(count)
    lengths *= length / lengths.sum()
    axis = np.cross(direction, _Z)
    if np.linalg.norm(axis) < 1e-9:
        axis = _X
    directions = [_rotation(axis, np.radians(bend_deg) * k) @ direction for k in range(count)]
    return ch.rig.add_chain(_chain_names(base, count, suffix), start, directions, lengths, parent)


# ---------------------------------------------------------------------------
# Quadruped (Rigify basic quadruped) and dragon
# ---------------------------------------------------------------------------

#: Random factors of the quadruped's proportions (1 = Rigify basic quadruped).
QUADRUPED_PROPORTIONS = {
    "body": (0.75, 1.35), "neck": (0.6, 2.5), "head": (0.7, 1.6), "leg": (0.6, 1.6),
    "width": (0.75, 1.3), "thickness": (0.75, 1.5), "tail": (0.3, 2.2),
}
DRAGON_PROPORTIONS = dict(QUADRUPED_PROPORTIONS, neck=(1.2, 2.8), tail=(1.5, 3.0), head=(0.9, 1.5))
#: Bones in the tail chain.
QUADRUPED_TAIL_BONES = (2, 6)
DRAGON_TAIL_BONES = (6, 13)
#: Neck raise and head pitch at rest, degrees.
QUADRUPED_NECK_RAISE_DEG = (-10.0, 35.0)
QUADRUPED_HEAD_PITCH_DEG = (-25.0, 10.0)
#: Shell semi-axes (height, width) in template metres at the joints of each chain.
QUADRUPED_TORSO_RADII = ((0.12, 0.10), (0.14, 0.12), (0.16, 0.13), (0.16, 0.13), (0.15, 0.12), (0.12, 0.10))
QUADRUPED_NECK_RADII = ((0.10, 0.08), (0.075, 0.065), (0.065, 0.06))
QUADRUPED_SNOUT_RADII = ((0.065, 0.055), (0.035, 0.03))
QUADRUPED_HIND_LEG_RADII = ((0.085, 0.085), (0.06, 0.06), (0.035, 0.035), (0.03, 0.03), (0.025, 0.025))
QUADRUPED_FRONT_LEG_RADII = ((0.07, 0.07), (0.065, 0.065), (0.045, 0.045), (0.03, 0.03), (0.028, 0.028), (0.025, 0.025))
QUADRUPED_TAIL_RADII = (0.045, 0.012)
#: Cranium semi-axes (across, up, along) as fractions of the head bone.
QUADRUPED_CRANIUM_RADII = (0.36, 0.38, 0.45)
#: Dragon wings: span as a multiple of the torso length, fingers per wing.
DRAGON_WING_SPAN = (1.0, 2.0)
DRAGON_FINGERS = (2, 5)
#: Membrane vertices across each gap between two fingers.
MEMBRANE_STRIP_SAMPLES = 4
#: The membrane starts this far along each finger, where the fingers have
#: spread apart (they all meet at the wrist).
MEMBRANE_START_FRACTION = 0.1


def _quadruped_skeleton(ch, proportions, tail_bones):
    factor = {name: ch.uniform(*limits) for name, limits in proportions.items()}
    lengths = {name: factor["body"] for name in ("spine.004", "spine.005", "spine.006", "spine.007", "spine.008")}
    lengths.update({"spine.009": factor["neck"], "spine.010": factor["neck"], "spine.011": factor["head"]})
    for name in ("thigh.L", "shin.L", "foot.L", "toe.L", "shoulder.L", "front_thigh.L", "front_shin.L", "front_foot.L", "front_toe.L"):
        lengths[name] = factor["leg"]
    lateral = {"thigh.L": factor["width"], "shoulder.L": factor["width"]}
    root = ch.maybe_root()
    ch.place_template(templates.QUADRUPED, lengths, lateral, None, root)
    rig = ch.rig
    rig.set_tail("shoulder.L", rig.head("front_thigh.L"))
    rig.raise_subtree("spine.009", np.radians(ch.uniform(*QUADRUPED_NECK_RAISE_DEG)))
    rig.raise_subtree("spine.011", np.radians(ch.uniform(*QUADRUPED_HEAD_PITCH_DEG)))
    count = int(ch.rng.integers(tail_bones[0], tail_bones[1] + 1))
    tail = _grow_tail(ch, "tail", "spine.004", rig.head("spine.004"), _unit([0.0, 1.0, -0.34]),
                      0.45 * factor["tail"], count, ch.uniform(-6.0, 10.0))
    ears = []
    if ch.chance("ears"):
        cranium = _head_ellipsoid(ch, "spine.011", QUADRUPED_CRANIUM_RADII, 0.25, np.sqrt(factor["thickness"]))
        root_point = cranium.centre + 0.8 * (cranium.surface_point(np.array([0.6, 0.3, 1.0])) - cranium.centre)
        length = ch.uniform(0.6, 2.0) * cranium.radii.max()
        direction = _unit([ch.uniform(0.2, 1.0), ch.uniform(0.0, 0.6), 1.0])
        ears = rig.add_chain(["ear.L"], root_point, [direction], [length], "spine.011")
    return factor, tail, ears


def _quadruped_body(ch, factor, unit, tail, ears):
    rig = ch.rig
    thick = factor["thickness"] * unit
    torso = ["spine.004", "spine.005", "spine.006", "spine.007", "spine.008"]
    ch.tube("torso", torso, _bone_radii(QUADRUPED_TORSO_RADII, thick), up=_Z, bulge=[0.0, 0.05, 0.05, 0.05, 0.0])
    ch.tube("neck", ["spine.009", "spine.010"], _bone_radii(QUADRUPED_NECK_RADII, thick), up=_Z, child="spine.011")
    ch.tube("snout", ["spine.011"], _bone_radii(QUADRUPED_SNOUT_RADII, thick * np.sqrt(factor["head"])), up=_Z)
    cranium = _head_ellipsoid(ch, "spine.011", QUADRUPED_CRANIUM_RADII, 0.25, np.sqrt(factor["thickness"]))
    ch.rigid("cranium", _ellipsoid_geometry(cranium.centre, cranium.radii, cranium.frame, ch.spacing), "spine.011", PART_BODY)
    radii = np.linspace(*QUADRUPED_TAIL_RADII, len(tail) + 1)[:, None] * np.array([1.0, 1.0]) * thick
    ch.tube("tail", tail, radii, up=_Z)
    ch.tube("hind_leg.L", ["thigh.L", "shin.L", "foot.L", "toe.L"], _bone_radii(QUADRUPED_HIND_LEG_RADII, thick), up=-_Y, mirror=True,
            bulge=[0.15, 0.05, 0.0, 0.0])
    ch.tube("front_leg.L", ["shoulder.L", "front_thigh.L", "front_shin.L", "front_foot.L", "front_toe.L"],
            _bone_radii(QUADRUPED_FRONT_LEG_RADII, thick), up=-_Y, mirror=True)
    for ear in ears:
        width = 0.3 * rig.length(ear)
        ch.tube("ear.L", [ear], [(0.3 * width, width), (0.08 * width, 0.2 * width)], up=-_Y, mirror=True)
    return cranium


def _quadruped_accessories(ch, cranium, factor, unit):
    if ch.chance("eyes"):
        _add_eyes(ch, cranium, "spine.011")
    if ch.chance("horns"):
        _add_horns(ch, cranium, "spine.011")
    if ch.chance("collar"):
        _add_collar(ch, "spine.010", np.array(QUADRUPED_NECK_RADII[1][::-1]) * factor["thickness"] * unit * 1.1)
    if ch.chance("blanket"):
        _add_blanket(ch, "spine.008", "spine.005", 1.4 * QUADRUPED_TORSO_RADII[3][1] * factor["thickness"] * unit)
    elif ch.chance("saddle"):
        _add_saddle(ch, "spine.006", QUADRUPED_TORSO_RADII[3][1] * factor["thickness"] * unit)


def _build_quadruped(ch) -> str:
    factor, tail, ears = _quadruped_skeleton(ch, QUADRUPED_PROPORTIONS, QUADRUPED_TAIL_BONES)
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["quadruped"]), axis=1)
    ch.settle()
    cranium = _quadruped_body(ch, factor, unit, tail, ears)
    _quadruped_accessories(ch, cranium, factor, unit)
    return "quadruped"


def _add_dragon_wing_bones(ch, factor):
    """Arm and finger chains of a membrane wing on the left (template metres)."""
    rig = ch.rig
    height, width = np.array(QUADRUPED_TORSO_RADII[4]) * factor["thickness"]
    middle = 0.5 * (rig.head("spine.008") + rig.tail("spine.008"))
    attach = middle + np.array([0.5 * width, 0.0, 0.7 * height])
    torso_length = np.linalg.norm(rig.tail("spine.008") - rig.head("spine.004"))
    span = ch.uniform(*DRAGON_WING_SPAN) * torso_length
    arm = rig.add_chain(_chain_names("wing", 2, ".L"), attach, [_unit([1.0, 0.15, 0.5]), _unit([1.0, -0.25, -0.1])],
                        [0.3 * span, 0.35 * span], "spine.008")
    count = int(ch.rng.integers(DRAGON_FINGERS[0], DRAGON_FINGERS[1]))
    fingers = []
    for k in range(count):
        angle = np.radians(15.0 + 70.0 * k / max(count - 1, 1))
        direction = _unit([np.cos(angle), np.sin(angle), -0.15 - 0.1 * k])
        length = (0.55 - 0.08 * k) * span
        names = _chain_names(f"wing_finger_{k + 1}", 2, ".L")
        fingers.append(rig.add_chain(names, rig.tail(arm[-1]), [direction, _unit(direction + 0.2 * _Y)],
                                     [0.55 * length, 0.45 * length], arm[-1]))
    return arm, fingers, attach


def _points_at_fractions(polyline, fractions):
    """(m, 3) points at arc-length ``fractions`` (m,) in [0, 1] along a polyline."""
    lengths = np.linalg.norm(np.diff(polyline, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(lengths)])
    return np.column_stack([np.interp(fractions * arc[-1], arc, polyline[:, k]) for k in range(3)])


def _add_membrane(ch, fingers, flank_polyline, torso_bones):
    """An open wing membrane spanning the finger chains and the body flank;
    each vertex blends the weights of the two columns it lies between."""
    rig = ch.rig
    columns = [rig.path_points(chain) for chain in fingers] + [flank_polyline]
    longest = max(np.linalg.norm(np.diff(c, axis=0), axis=1).sum() for c in columns)
    rows = _sheet_rows(4, longest, ch.spacing)
    fractions = np.linspace(MEMBRANE_START_FRACTION, 1.0, rows)
    column_points, column_weights = [], []
    for chain, polyline in zip(fingers, columns[:-1]):
        joint_arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(polyline, axis=0), axis=1))])
        weights = _joint_blend_weights(fractions * joint_arc[-1], joint_arc, ch.blend, True, False)
        column_points.append(_points_at_fractions(polyline, fractions))
        column_weights.append(([rig.deforming_parent(chain[0])] + list(chain), weights))
    flank = _points_at_fractions(flank_polyline, fractions)
    torso_path = rig.path_points(torso_bones)
    torso_arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(torso_path, axis=0), axis=1))])
    column_points.append(flank)
    column_weights.append((list(torso_bones), _joint_blend_weights(polyline_arc_lengths(flank, torso_path), torso_arc, ch.blend, False, False)))
    grid_points, grid_weights = [], []
    for c in range(len(column_points) - 1):
        shares = np.linspace(0.0, 1.0, MEMBRANE_STRIP_SAMPLES + 1)
        shares = shares if c == len(column_points) - 2 else shares[:-1]
        for share in shares:
            grid_points.append((1.0 - share) * column_points[c] + share * column_points[c + 1])
            (names_a, weights_a), (names_b, weights_b) = column_weights[c], column_weights[c + 1]
            grid_weights.append(_sum_weight_columns([(names_a, (1.0 - share) * weights_a), (names_b, share * weights_b)]))
    vertices = np.stack(grid_points, axis=1).reshape(-1, 3)
    names = []
    for block_names, _ in grid_weights:
        names.extend(n for n in block_names if n not in names)
    # Grid rows are fractions along the columns; lay the weights out the same way.
    stacked = np.zeros((rows, len(grid_points), len(names)))
    column_of = {n: k for k, n in enumerate(names)}
    for g, (block_names, block) in enumerate(grid_weights):
        for k, name in enumerate(block_names):
            stacked[:, g, column_of[name]] += block[:, k]
    triangles = _face_towards(vertices, _grid_triangles(rows, len(grid_points)), _Z)
    ch.add_part(_Part("wing_membrane.L", PART_BODY, False, vertices, triangles, names, stacked.reshape(-1, len(names))), mirror=True)


def _build_dragon(ch) -> str:
    factor, tail, ears = _quadruped_skeleton(ch, DRAGON_PROPORTIONS, DRAGON_TAIL_BONES)
    arm, fingers, _ = _add_dragon_wing_bones(ch, factor)
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["dragon"]), axis=1)
    ch.settle()
    cranium = _quadruped_body(ch, factor, unit, tail, ears)
    rig = ch.rig
    height, width = np.array(QUADRUPED_TORSO_RADII[4]) * factor["thickness"] * unit
    ch.tube("wing_arm.L", arm, [(0.12 * height, 0.12 * height), (0.09 * height, 0.09 * height), (0.06 * height, 0.06 * height)], up=_Y, mirror=True)
    for chain in fingers:
        radius = 0.04 * height
        ch.tube(chain[0].replace(".L", "") + ".L", chain, [(radius, radius), (0.8 * radius, 0.8 * radius), (0.4 * radius, 0.4 * radius)], up=_Z, mirror=True)
    hips = rig.head("spine.005") + np.array([0.5 * width, 0.0, 0.5 * height])
    flank = np.stack([rig.head(arm[0]), hips])
    _add_membrane(ch, fingers, flank, ["spine.004", "spine.005", "spine.006", "spine.007", "spine.008"])
    _quadruped_accessories(ch, cranium, factor, unit)
    if ch.chance("spikes"):
        _add_spikes(ch, ["spine.005", "spine.006", "spine.007"] + tail[: len(tail) // 2])
    return "dragon"


# ---------------------------------------------------------------------------
# Bird (Rigify bird)
# ---------------------------------------------------------------------------

BIRD_PROPORTIONS = {
    "wing": (0.8, 1.8), "neck": (0.7, 2.5), "leg": (0.6, 2.2), "beak": (0.6, 2.5),
    "tail": (0.6, 1.8), "head": (0.8, 1.4), "thickness": (0.8, 1.4),
}
#: Wing raise at rest, degrees.
BIRD_WING_RAISE_DEG = (-20.0, 25.0)
#: Shell semi-axes in template metres (the Rigify bird is 0.2 m tall).
BIRD_TORSO_RADII = ((0.022, 0.02), (0.03, 0.026), (0.03, 0.026), (0.02, 0.018))  # (height, width)
BIRD_TAIL_RADII = ((0.016, 0.014), (0.01, 0.009), (0.006, 0.006), (0.004, 0.004))
BIRD_NECK_RADII = ((0.016, 0.015), (0.012, 0.012), (0.011, 0.011), (0.011, 0.011))
BIRD_UPPER_BEAK_RADII = ((0.006, 0.007), (0.004, 0.005), (0.001, 0.0012))
BIRD_LOWER_BEAK_RADII = ((0.004, 0.006), (0.003, 0.004), (0.001, 0.001))
BIRD_LEG_RADII = ((0.008, 0.008), (0.005, 0.005), (0.003, 0.003), (0.0025, 0.0025), (0.0015, 0.0015))
BIRD_WING_RADII = ((0.008, 0.008), (0.006, 0.012), (0.005, 0.016), (0.004, 0.014), (0.002, 0.006))  # (thickness, chord)
#: Head semi-axes (across, up, along) as fractions of the head bone.
BIRD_HEAD_RADII = (0.3, 0.32, 0.35)
#: Feather chord and thickness as fractions of the feather's length.
BIRD_FEATHER_SHAPE = (0.28, 0.04)


def _build_bird(ch) -> str:
    factor = {name: ch.uniform(*limits) for name, limits in BIRD_PROPORTIONS.items()}
    groups = {
        "wing": ("Wing.L", "Wing.001.L", "Wing.002.L", "w_feather.001.L", "w_feather.002.L", "w_feather.003.L", "w_feather.004.L"),
        "neck": ("spine.006", "neck.001", "neck.002"), "leg": ("thigh.L", "shin.L", "foot.L", "toe.L"),
        "beak": ("beak.001.T", "beak.002.T", "beak.001.B", "beak.002.B"), "tail": ("spine.002", "spine.001", "spine", "t_feather.L"),
        "head": ("head",),
    }
    lengths = {bone: factor[group] for group, bones in groups.items() for bone in bones}
    root = ch.maybe_root()
    ch.place_template(templates.BIRD, lengths, None, None, root)
    rig = ch.rig
    rig.set_tail("shoulder.L", rig.head("Wing.L"))
    rig.raise_subtree("Wing.L", np.radians(ch.uniform(*BIRD_WING_RAISE_DEG)))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["bird"]))
    thick = factor["thickness"] * unit
    ch.settle()
    ch.tube("torso", ["spine.003", "spine.004", "spine.005"], _bone_radii(BIRD_TORSO_RADII, thick), up=_Z, bulge=[0.15, 0.15, 0.1])
    ch.tube("tail", ["spine.002", "spine.001", "spine"], _bone_radii(BIRD_TAIL_RADII, thick), up=_Z)
    ch.tube("neck", ["spine.006", "neck.001", "neck.002"], _bone_radii(BIRD_NECK_RADII, thick), up=-_Y, child="head")
    head = _head_ellipsoid(ch, "head", BIRD_HEAD_RADII, 0.25, factor["thickness"] / np.sqrt(factor["head"]))
    ch.rigid("head", _ellipsoid_geometry(head.centre, head.radii, head.frame, ch.spacing), "head", PART_BODY)
    beak = thick * np.sqrt(factor["beak"])
    ch.tube("beak_upper", ["beak.001.T", "beak.002.T"], _bone_radii(BIRD_UPPER_BEAK_RADII, beak), up=_Z)
    ch.tube("beak_lower", ["beak.001.B", "beak.002.B"], _bone_radii(BIRD_LOWER_BEAK_RADII, beak), up=_Z)
    ch.tube("leg.L", ["thigh.L", "shin.L", "foot.L", "toe.L"], _bone_radii(BIRD_LEG_RADII, thick), up=-_Y, mirror=True)
    ch.tube("wing.L", ["shoulder.L", "Wing.L", "Wing.001.L", "Wing.002.L"], _bone_radii(BIRD_WING_RADII, thick), up=_Z, mirror=True)
    for feather in ("w_feather.001.L", "w_feather.002.L", "w_feather.003.L", "w_feather.004.L", "t_feather.L"):
        length = rig.length(feather)
        chord, thickness = BIRD_FEATHER_SHAPE
        frame = _frame(rig.direction(feather), _Z)
        middle = 0.5 * (rig.head(feather) + rig.tail(feather))
        box = _box_geometry(middle, np.array([thickness, chord, 0.5]) * length, frame)
        ch.rigid(feather, box, feather, mirror=True)
    _add_eyes(ch, head, "eye.L", forward=-0.4 * _Y)
    return "bird"


def _build_winged(ch) -> str:
    return _build_bird(ch) if ch.rng.random() < 0.5 else _build_dragon(ch)


# ---------------------------------------------------------------------------
# Many legs: insect, spider, centipede
# ---------------------------------------------------------------------------

MULTILEG_VARIANTS = ("insect", "spider", "centipede")
#: Leg segment elevations (degrees above horizontal) and shares of the leg length.
MULTILEG_LEG_ELEVATIONS_DEG = (-10.0, 40.0, -60.0, -80.0)
MULTILEG_LEG_SHARES = (0.1, 0.35, 0.38, 0.17)
CENTIPEDE_LEG_ELEVATIONS_DEG = (20.0, -50.0, -80.0)
CENTIPEDE_LEG_SHARES = (0.35, 0.4, 0.25)
#: Front legs point this far forward, back legs as far backward (degrees).
MULTILEG_LEG_YAW_DEG = 45.0
#: Leg pairs of a centipede.
CENTIPEDE_PAIRS = (6, 13)


def _build_multileg(ch) -> str:
    rig = ch.rig
    variant = MULTILEG_VARIANTS[int(ch.rng.integers(len(MULTILEG_VARIANTS)))]
    root = ch.maybe_root()
    if variant == "centipede":
        pairs = int(ch.rng.integers(*CENTIPEDE_PAIRS))
        body_radius = ch.uniform(0.025, 0.05)
        segment = 1.0 / pairs
        body = rig.add_chain(_chain_names("spine", pairs), [0.0, -0.5, 0.0], [_Y] * pairs, [segment] * pairs, root)
        rig.add("head", [0.0, -0.5, 0.0], [0.0, -0.5 - 1.5 * segment, 0.01], body[0])
        attach = [(name, 0.5 * (rig.head(name) + rig.tail(name))) for name in body]
        leg_length, elevations, shares = ch.uniform(0.12, 0.3), CENTIPEDE_LEG_ELEVATIONS_DEG, CENTIPEDE_LEG_SHARES
        abdomen = []
        head_radii = (0.9, 0.6, 0.6)
    else:
        pairs = 3 if variant == "insect" else 4
        thorax = ch.uniform(0.22, 0.35) if variant == "insect" else ch.uniform(0.25, 0.35)
        body_radius = ch.uniform(0.07, 0.1) if variant == "insect" else ch.uniform(0.1, 0.15)
        rig.add("thorax", [0.0, -0.5 * thorax, 0.0], [0.0, 0.5 * thorax, 0.0], root)
        head_length = ch.uniform(0.12, 0.2) if variant == "insect" else ch.uniform(0.06, 0.1)
        rig.add("head", [0.0, -0.5 * thorax, 0.01], [0.0, -0.5 * thorax - head_length, 0.02], "thorax")
        count = int(ch.rng.integers(2, 4)) if variant == "insect" else 1
        abdomen_length = ch.uniform(0.35, 0.7)
        abdomen = rig.add_chain(_chain_names("abdomen", count), rig.tail("thorax"), [_unit([0.0, 1.0, ch.uniform(-0.3, 0.3)])] * count,
                                [abdomen_length / count] * count, "thorax")
        spots = np.linspace(-0.3, 0.3, pairs) * thorax
        attach = [("thorax", np.array([0.0, y, 0.0])) for y in spots]
        leg_length = ch.uniform(0.5, 1.1) if variant == "insect" else ch.uniform(0.9, 1.6)
        elevations, shares = MULTILEG_LEG_ELEVATIONS_DEG, MULTILEG_LEG_SHARES
        head_radii = (0.6, 0.5, 0.6) if variant == "insect" else (0.9, 0.7, 0.8)
    legs = []
    yaws = np.radians(np.linspace(MULTILEG_LEG_YAW_DEG, -MULTILEG_LEG_YAW_DEG, pairs))
    for k, ((parent, centre), yaw) in enumerate(zip(attach, yaws)):
        start = centre + np.array([0.6 * body_radius, 0.0, -0.2 * body_radius])
        directions = [np.array([np.cos(e) * np.cos(yaw), -np.cos(e) * np.sin(yaw), np.sin(e)]) for e in np.radians(elevations)]
        legs.append(rig.add_chain(_chain_names(f"leg_{k + 1:02d}", len(shares), ".L"), start, directions, leg_length * np.array(shares), parent))
    antennae = []
    if variant != "spider" and ch.chance("antennae"):
        start = rig.tail("head") + np.array([0.3 * body_radius, 0.0, 0.3 * body_radius])
        length = ch.uniform(0.2, 0.6)
        antennae = rig.add_chain(_chain_names("antenna", 2, ".L"), start, [_unit([0.4, -1.0, 0.7]), _unit([0.6, -1.0, 0.2])],
                                 [0.5 * length, 0.5 * length], "head")
    wings = []
    if variant == "insect" and ch.chance("insect_wings"):
        start = np.array([0.3 * body_radius, -0.1 * thorax, 0.9 * body_radius])
        wings = rig.add_chain(["wing.L"], start, [_unit([1.0, ch.uniform(0.3, 1.0), 0.15])], [ch.uniform(0.5, 1.0)], "thorax")
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["multileg"]), axis=None)
    radius = body_radius * unit
    ch.settle()

    head = _head_ellipsoid(ch, "head", head_radii, 0.5)
    ch.rigid("head", _ellipsoid_geometry(head.centre, head.radii, head.frame, ch.spacing), "head", PART_BODY)
    if variant == "centipede":
        ch.tube("body", body, np.full((len(body) + 1, 2), radius) * np.array([0.8, 1.0]), up=_Z)
    else:
        ch.tube("thorax", ["thorax"], [(0.8 * radius, radius), (0.9 * radius, radius), ], up=_Z, bulge=[0.2])
        profile = np.interp(np.linspace(0, 1, len(abdomen) + 1), [0.0, 0.4, 1.0], [1.0, 1.6 if variant == "spider" else 1.3, 0.5])
        ch.tube("abdomen", abdomen, profile[:, None] * radius * np.array([0.9, 1.0]), up=_Z, bulge=[0.15] * len(abdomen))
    leg_radius = ch.uniform(0.02, 0.04) * leg_length * unit
    for k, chain in enumerate(legs):
        radii = np.linspace(1.0, 0.35, len(chain) + 1)[:, None] * np.array([leg_radius, leg_radius])
        ch.tube(chain[0], chain, radii, up=_Z, mirror=True)
    if antennae:
        r = 0.3 * leg_radius
        ch.tube("antenna.L", antennae, [(r, r), (0.8 * r, 0.8 * r), (0.5 * r, 0.5 * r)], up=_Z, mirror=True)
    for wing in wings:
        length = rig.length(wing)
        frame = _frame(_Z, rig.direction(wing))
        centre = 0.5 * (rig.head(wing) + rig.tail(wing))
        ch.rigid("wing.L", _ellipsoid_geometry(centre, np.array([0.5, 0.22, 0.015]) * length, frame, ch.spacing), wing, mirror=True)
    if ch.chance("eyes"):
        _add_eyes(ch, head, "head")
    if abdomen and ch.chance("stinger"):
        tip = abdomen[-1]
        length = 0.4 * rig.length(tip)
        ch.rigid("stinger", _cone_geometry(rig.tail(tip) - 0.3 * length * rig.direction(tip), 0.3 * radius, 1.3 * length,
                                           _frame(rig.direction(tip), _Z), ch.spacing), tip)
    return variant


# ---------------------------------------------------------------------------
# Tailed: theropod, lizard, tailed humanoid
# ---------------------------------------------------------------------------

TAILED_VARIANTS = ("theropod", "lizard", "tailed_humanoid")
#: Tail bones of tailed creatures.
TAILED_TAIL_BONES = (6, 15)
#: Shell semi-axes (height, width), in units of the hip height (theropod) or body length (lizard).
THEROPOD_TORSO_RADII = ((0.2, 0.17), (0.24, 0.2), (0.22, 0.18), (0.16, 0.14))
THEROPOD_NECK_RADII = ((0.12, 0.11), (0.09, 0.085), (0.08, 0.075))
THEROPOD_HEAD_RADII = ((0.11, 0.09), (0.05, 0.045))
THEROPOD_JAW_RADII = ((0.035, 0.07), (0.02, 0.035))
THEROPOD_LEG_RADII = ((0.13, 0.13), (0.075, 0.075), (0.045, 0.045), (0.035, 0.035), (0.025, 0.025))
THEROPOD_ARM_RADII = ((0.045, 0.045), (0.035, 0.035), (0.025, 0.025), (0.018, 0.018))
THEROPOD_TAIL_RADII = (0.17, 0.02)
LIZARD_TORSO_RADII = ((0.05, 0.07), (0.06, 0.09), (0.06, 0.09), (0.05, 0.07))
LIZARD_NECK_RADII = ((0.045, 0.06), (0.04, 0.05))
LIZARD_HEAD_RADII = ((0.04, 0.05), (0.015, 0.02))
LIZARD_LEG_RADII = ((0.03, 0.03), (0.022, 0.022), (0.016, 0.016), (0.01, 0.01))
LIZARD_TAIL_RADII = (0.05, 0.006)


def _tail_radii(tail, radii, scale):
    return np.linspace(radii[0], radii[1], len(tail) + 1)[:, None] * np.array([1.0, 1.0]) * scale


def _build_theropod(ch) -> str:
    rig = ch.rig
    root = ch.maybe_root()
    torso, neck, head, legs, arms, thick = (ch.uniform(0.6, 1.0), ch.uniform(0.4, 1.0), ch.uniform(0.3, 0.5), ch.uniform(0.8, 1.2),
                                            ch.uniform(0.3, 1.0), ch.uniform(0.8, 1.3))
    spine = rig.add_chain(_chain_names("spine", 3), [0.0, 0.0, 1.0], [_unit([0, -1, 0.1]), _unit([0, -1, 0.2]), _unit([0, -1, 0.3])],
                          torso * np.array([0.36, 0.34, 0.3]), root)
    neck_bones = rig.add_chain(["spine.003", "spine.004"], rig.tail("spine.002"), [_unit([0, -0.5, 1.0]), _unit([0, -0.8, 0.6])],
                               neck * np.array([0.5, 0.5]), "spine.002")
    rig.add_chain(["head"], rig.tail("spine.004"), [_unit([0, -1.0, -0.15])], [head], "spine.004")
    rig.add("jaw", rig.head("head") + np.array([0.0, -0.1 * head, -0.12 * head]), rig.tail("head") + np.array([0.0, 0.1 * head, -0.15 * head]), "head")
    leg = rig.add_chain(["thigh.L", "shin.L", "foot.L", "toe.L"], [0.15, 0.05, 0.95],
                        [_unit([0.05, -0.45, -1]), _unit([0, 0.5, -1]), _unit([0, -0.2, -1]), _unit([0, -1, -0.05])],
                        legs * np.array([0.5, 0.5, 0.3, 0.18]), "spine")
    chest = 0.5 * (rig.head("spine.002") + rig.tail("spine.002"))
    arm = rig.add_chain(["upper_arm.L", "forearm.L", "hand.L"], chest + np.array([0.12, 0.0, -0.12]),
                        [_unit([0.3, -0.5, -0.8]), _unit([0.1, -0.9, 0.1]), _unit([0, -1, -0.3])], arms * np.array([0.2, 0.18, 0.08]), "spine.002")
    tail = _grow_tail(ch, "tail", "spine", rig.head("spine"), _unit([0.0, 1.0, -0.1]), ch.uniform(1.0, 2.2),
                      int(ch.rng.integers(*TAILED_TAIL_BONES)), ch.uniform(-3.0, 4.0))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["tailed"]), axis=1)
    scale = thick * unit
    ch.settle()
    ch.tube("torso", spine, _bone_radii(THEROPOD_TORSO_RADII, scale), up=_Z, bulge=[0.05, 0.1, 0.05])
    ch.tube("neck", neck_bones, _bone_radii(THEROPOD_NECK_RADII, scale), up=_Z, child="head")
    ch.tube("head", ["head"], _bone_radii(THEROPOD_HEAD_RADII, scale * np.sqrt(head / 0.4)), up=_Z, bulge=[0.2])
    ch.tube("jaw", ["jaw"], _bone_radii(THEROPOD_JAW_RADII, scale * np.sqrt(head / 0.4)), up=_Z)
    ch.tube("tail", tail, _tail_radii(tail, THEROPOD_TAIL_RADII, scale), up=_Z)
    ch.tube("leg.L", leg, _bone_radii(THEROPOD_LEG_RADII, scale), up=-_Y, mirror=True, bulge=[0.2, 0.1, 0.0, 0.0])
    ch.tube("arm.L", arm, _bone_radii(THEROPOD_ARM_RADII, scale), up=_Z, mirror=True)
    snout = _head_ellipsoid(ch, "head", (0.28, 0.3, 0.45), 0.3, thick)
    if ch.chance("eyes"):
        _add_eyes(ch, snout, "head", forward=-0.5 * _Y)
    if ch.chance("horns"):
        _add_horns(ch, snout, "head")
    if ch.chance("spikes"):
        _add_spikes(ch, spine + neck_bones + tail[: len(tail) // 2])
    return "theropod"


def _build_lizard(ch) -> str:
    rig = ch.rig
    root = ch.maybe_root()
    legs, thick = ch.uniform(0.7, 1.5), ch.uniform(0.8, 1.4)
    spine = rig.add_chain(_chain_names("spine", 3), [0.0, 0.2, 0.2], [-_Y] * 3, [0.15, 0.15, 0.15], root)
    neck = rig.add_chain(["spine.003"], rig.tail("spine.002"), [_unit([0, -1, 0.15])], [ch.uniform(0.06, 0.15)], "spine.002")
    rig.add_chain(["head"], rig.tail("spine.003"), [_unit([0, -1, -0.05])], [ch.uniform(0.12, 0.2)], "spine.003")
    sprawl = [_unit([1.0, 0.1, -0.05]), _unit([0.1, 0.1, -1.0]), _unit([0.2, -0.8, -0.1])]
    hind = rig.add_chain(["thigh.L", "shin.L", "foot.L"], [0.06, 0.17, 0.19], sprawl, legs * np.array([0.12, 0.12, 0.06]), "spine")
    front_sprawl = [_unit([1.0, -0.1, -0.05]), _unit([0.1, -0.1, -1.0]), _unit([0.2, -0.8, -0.1])]
    front = rig.add_chain(["upper_arm.L", "forearm.L", "hand.L"], rig.tail("spine.002") + np.array([0.06, 0.03, -0.01]), front_sprawl,
                          legs * np.array([0.1, 0.1, 0.05]), "spine.002")
    tail = _grow_tail(ch, "tail", "spine", rig.head("spine"), _unit([0.0, 1.0, -0.05]), ch.uniform(0.6, 1.3),
                      int(ch.rng.integers(*TAILED_TAIL_BONES)), ch.uniform(-2.0, 2.0))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["tailed"]), axis=1)
    scale = thick * unit
    ch.settle()
    ch.tube("torso", spine, _bone_radii(LIZARD_TORSO_RADII, scale), up=_Z)
    ch.tube("neck", neck, _bone_radii(LIZARD_NECK_RADII, scale), up=_Z, child="head")
    ch.tube("head", ["head"], _bone_radii(LIZARD_HEAD_RADII, scale), up=_Z)
    ch.tube("tail", tail, _tail_radii(tail, LIZARD_TAIL_RADII, scale), up=_Z)
    ch.tube("hind_leg.L", hind, _bone_radii(LIZARD_LEG_RADII, scale), up=_Z, mirror=True)
    ch.tube("front_leg.L", front, _bone_radii(LIZARD_LEG_RADII, scale), up=_Z, mirror=True)
    head = _head_ellipsoid(ch, "head", (0.25, 0.2, 0.4), 0.3, thick)
    if ch.chance("eyes"):
        _add_eyes(ch, head, "head", forward=-0.3 * _Y)
    if ch.chance("spikes"):
        _add_spikes(ch, spine + tail[: len(tail) // 2])
    return "lizard"


def _build_tailed(ch) -> str:
    variant = TAILED_VARIANTS[int(ch.rng.integers(len(TAILED_VARIANTS)))]
    if variant == "theropod":
        return _build_theropod(ch)
    if variant == "lizard":
        return _build_lizard(ch)
    return _build_biped(ch, tail_bones=int(ch.rng.integers(4, 11)))


# ---------------------------------------------------------------------------
# Long chains: snake, tentacled creature, rope
# ---------------------------------------------------------------------------

LONG_CHAIN_VARIANTS = ("snake", "tentacles", "rope")
#: Bones along a snake or rope; tentacles per side and bones per tentacle.
SNAKE_BONES = (10, 33)
ROPE_BONES = (12, 41)
TENTACLES_PER_SIDE = (2, 5)
TENTACLE_BONES = (6, 15)


def _build_snake(ch) -> str:
    rig = ch.rig
    root = ch.maybe_root()
    count = int(ch.rng.integers(*SNAKE_BONES))
    amplitude, wavelength, phase = ch.uniform(0.0, 0.12), ch.uniform(0.3, 0.7), ch.uniform(0.0, 2 * np.pi)
    y = np.linspace(0.5, -0.5, 256)
    curve = np.column_stack([amplitude * np.sin(2 * np.pi * y / wavelength + phase), y, np.zeros_like(y)])
    head_share = ch.uniform(0.03, 0.06)
    joints = _resample_polyline(curve[: int(256 * (1 - head_share))], count + 1)
    names = _chain_names("spine", count)
    parent = root
    for k, name in enumerate(names):
        rig.add(name, joints[k], joints[k + 1], parent)
        parent = name
    rig.add("head", joints[-1], curve[-1], names[-1])
    radius = ch.uniform(0.012, 0.03)
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["long_chain"]), axis=None)
    rig.transform_all(lambda p: p + np.array([0.0, 0.0, radius * unit]))
    ch.settle()
    r = radius * unit
    position = np.linspace(0.0, 1.0, count + 1)
    profile = np.interp(position, [0.0, 0.25, 0.85, 1.0], [0.12, 1.0, 1.0, 0.75])
    ch.tube("body", names, profile[:, None] * np.array([0.85 * r, r]), up=_Z, child="head")
    head = _Ellipsoid(0.5 * (rig.head("head") + rig.tail("head")), np.array([0.9 * r, 1.3 * r, max(0.55 * rig.length("head"), 1.2 * r)]),
                      _frame(rig.direction("head"), _Z))
    ch.rigid("head", _ellipsoid_geometry(head.centre, head.radii, head.frame, ch.spacing), "head", PART_BODY)
    if ch.chance("eyes"):
        _add_eyes(ch, head, "head", forward=rig.direction("head") * 0.6)
    return "snake"


def _build_tentacles(ch) -> str:
    rig = ch.rig
    root = ch.maybe_root()
    body = rig.add_chain(_chain_names("body", 2), [0.0, 0.0, 0.0], [_Z, _Z], [0.5, 0.5], root)
    per_side = int(ch.rng.integers(*TENTACLES_PER_SIDE))
    count = int(ch.rng.integers(*TENTACLE_BONES))
    length, curl = ch.uniform(1.5, 3.5), ch.uniform(5.0, 20.0)
    tentacles = []
    for k in range(per_side):
        angle = np.pi * (k + 0.5) / per_side
        outward = np.array([np.sin(angle), -np.cos(angle), 0.0])
        start = 0.3 * outward + np.array([0.0, 0.0, 0.1])
        direction = _unit(outward + np.array([0.0, 0.0, -0.8]))
        axis = np.cross(outward, _Z)
        lengths = 0.92 ** np.arange(count)
        lengths *= length / lengths.sum()
        directions = [_rotation(axis, -np.radians(curl) * j) @ direction for j in range(count)]
        tentacles.append(rig.add_chain(_chain_names(f"tentacle_{k + 1}", count, ".L"), start, directions, lengths, body[0]))
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["long_chain"]), axis=None)
    ch.settle()
    mantle = ch.uniform(0.35, 0.6) * unit
    ch.tube("mantle", body, [(mantle, mantle), (1.1 * mantle, 1.1 * mantle), (0.5 * mantle, 0.5 * mantle)], up=-_Y, bulge=[0.2, 0.3])
    for chain in tentacles:
        radii = np.linspace(0.22, 0.03, len(chain) + 1)[:, None] * np.array([mantle, mantle])
        ch.tube(chain[0], chain, radii, up=_Z, mirror=True)
    if ch.chance("eyes"):
        centre = rig.head("body.001")
        _add_eyes(ch, _Ellipsoid(centre, np.full(3, 1.1 * mantle), np.eye(3)), "body.001")
    return "tentacles"


def _build_rope(ch) -> str:
    rig = ch.rig
    root = ch.maybe_root()
    count = int(ch.rng.integers(*ROPE_BONES))
    t = np.linspace(0.0, 1.0, 256)
    frequencies = ch.rng.uniform(0.5, 2.0, size=3)
    phases = ch.rng.uniform(0.0, 2 * np.pi, size=3)
    amplitudes = ch.rng.uniform(0.05, 0.25, size=3)
    curve = np.column_stack([amplitudes[k] * np.sin(2 * np.pi * frequencies[k] * t + phases[k]) for k in range(3)])
    curve[:, 1] += t
    joints = _resample_polyline(curve, count + 1)
    names = _chain_names("segment", count)
    parent = root
    for k, name in enumerate(names):
        rig.add(name, joints[k], joints[k + 1], parent)
        parent = name
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["long_chain"]), axis=None)
    ch.settle()
    r = ch.uniform(0.008, 0.025) * unit
    profile = np.interp(np.linspace(0, 1, count + 1), [0.0, 0.05, 0.95, 1.0], [0.7, 1.0, 1.0, 0.7])
    ch.tube("rope", names, profile[:, None] * np.array([r, r]), up=_Z)
    return "rope"


def _build_long_chain(ch) -> str:
    variant = LONG_CHAIN_VARIANTS[int(ch.rng.integers(len(LONG_CHAIN_VARIANTS)))]
    return {"snake": _build_snake, "tentacles": _build_tentacles, "rope": _build_rope}[variant](ch)


# ---------------------------------------------------------------------------
# Fish (Rigify shark): shark, reef fish, dolphin
# ---------------------------------------------------------------------------

FISH_VARIANTS = ("shark", "reef_fish", "dolphin")
#: Bones of the body from snout to tail, through the root in the middle.
FISH_BODY_PATH = ("spine.007", "spine.006", "spine.005", "spine.004", "spine.008", "spine.003", "spine.002", "spine.001", "spine")
#: Body half-height over body length, and width over height, per variant.
FISH_DEPTH = {"shark": (0.06, 0.09), "reef_fish": (0.15, 0.25), "dolphin": (0.07, 0.1)}
FISH_ASPECT = {"shark": (0.7, 0.9), "reef_fish": (0.3, 0.5), "dolphin": (0.8, 1.0)}
#: Body outline p^a (1 - p)^b along the length p (0 snout, 1 tail), and its
#: smallest value at the snout and at the tail, as fractions of the peak.
FISH_PROFILE_EXPONENTS = (0.45, 0.9)
FISH_PROFILE_FLOOR = (0.15, 0.1)
#: Fin lengths relative to the Rigify shark's; reef fish fins are longer.
FISH_FIN_SIZE = (0.5, 1.1)
FISH_TAIL_FIN_SIZE = (0.6, 1.3)
REEF_FISH_FIN_BOOST = 1.3
#: How deep inside the body fin roots sit, as a fraction of the local radius.
FISH_FIN_ROOT_DEPTH = 0.7
#: Fin shells: part name, bones, (chord, thickness) in template metres at each joint.
FISH_FINS = (
    ("top_fin", ("top_fin", "top_fin.001"), ((0.16, 0.02), (0.08, 0.012), (0.02, 0.006))),
    ("side_fin.L", ("shoulder.L", "side_fin.L", "side_fin.001.L"), ((0.1, 0.03), (0.14, 0.025), (0.1, 0.015), (0.03, 0.008))),
    ("chest_fin.L", ("chest_fin.Bot.L",), ((0.06, 0.012), (0.02, 0.006))),
    ("mid_fin_top", ("mid_fin.Top",), ((0.06, 0.012), (0.02, 0.006))),
    ("mid_fin_bottom", ("mid_fin.Bot",), ((0.06, 0.012), (0.02, 0.006))),
    ("tail_fin_top", ("back_fin.T.Bk", "back_fin.T.001.Bk", "back_fin.T.002.Bk"), ((0.12, 0.02), (0.09, 0.015), (0.06, 0.01), (0.015, 0.005))),
    ("tail_fin_bottom", ("back_fin.B.Bk", "back_fin.B.001.Bk"), ((0.1, 0.02), (0.06, 0.012), (0.015, 0.005))),
    ("fluke.L", ("fluke.L", "fluke.001.L"), ((0.14, 0.02), (0.1, 0.015), (0.03, 0.006))),
)
FISH_JAW_RADII = ((0.05, 0.09), (0.04, 0.07), (0.02, 0.03))  # (height, width)
#: Bones whose subtree is moved so their head sits just inside the body surface.
FISH_FIN_ROOTS = ("top_fin", "shoulder.L", "chest_fin.Bot.L", "mid_fin.Top", "mid_fin.Bot", "back_fin.T.Bk", "back_fin.B.Bk", "jaw.master")


class _FishBody:
    """The analytic outline of a fish body around its spine path."""

    def __init__(self, path, half_height, aspect):
        self.path = path
        self.length = float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
        self.half_height = half_height
        self.aspect = aspect

    def radii(self, fraction):
        """(r, 2) semi-axes (height, width) at path ``fraction`` (r,)."""
        a, b = FISH_PROFILE_EXPONENTS
        peak = (a / (a + b)) ** a * (b / (a + b)) ** b
        fraction = np.clip(np.asarray(fraction, dtype=np.float64), 0.0, 1.0)
        shape = fraction ** a * (1.0 - fraction) ** b / peak
        height = self.half_height * np.maximum(shape, np.interp(fraction, [0.0, 1.0], FISH_PROFILE_FLOOR))
        return np.column_stack([height, self.aspect * height])

    def surface(self, point, direction=None):
        """Centre, unit radial direction and radius of the body surface seen
        from the spine point nearest ``point`` (towards ``point``, or along
        ``direction`` when given)."""
        fraction = polyline_arc_lengths(point[None], self.path)[0] / self.length
        centre = _points_at_fractions(self.path, np.array([fraction]))[0]
        step = 1e-3
        ahead = _points_at_fractions(self.path, np.clip(np.array([fraction - step, fraction + step]), 0, 1))
        tangent = _unit(ahead[1] - ahead[0])
        radial = (point - centre) if direction is None else np.asarray(direction, dtype=np.float64)
        radial = radial - np.dot(radial, tangent) * tangent
        radial = _unit(radial) if np.linalg.norm(radial) > 1e-9 else _unit(_Z - np.dot(_Z, tangent) * tangent)
        normal = _unit(_Z - np.dot(_Z, tangent) * tangent)
        binormal = np.cross(tangent, normal)
        height, width = self.radii(np.array([fraction]))[0]
        radius = 1.0 / np.sqrt((np.dot(radial, normal) / height) ** 2 + (np.dot(radial, binormal) / width) ** 2)
        return centre, radial, radius


def _build_fish(ch) -> str:
    rig = ch.rig
    variant = FISH_VARIANTS[int(ch.rng.integers(len(FISH_VARIANTS)))]
    fins, tail_fins, thick = ch.uniform(*FISH_FIN_SIZE), ch.uniform(*FISH_TAIL_FIN_SIZE), ch.uniform(0.8, 1.3)
    if variant == "reef_fish":
        fins *= REEF_FISH_FIN_BOOST
    fin_bones = {"top_fin", "top_fin.001", "shoulder.L", "side_fin.L", "side_fin.001.L", "chest_fin.Bot.L", "mid_fin.Top", "mid_fin.Bot"}
    tail_bones = {"back_fin.T.Bk", "back_fin.T.001.Bk", "back_fin.T.002.Bk", "back_fin.B.Bk", "back_fin.B.001.Bk"}
    lengths = {**{b: fins for b in fin_bones}, **{b: tail_fins for b in tail_bones}}
    keep = {row[0] for row in templates.SHARK}
    if variant == "dolphin":
        keep -= tail_bones | {"mid_fin.Top", "mid_fin.Bot", "chest_fin.Bot.L"}
    root = ch.maybe_root()
    ch.place_template(templates.SHARK, lengths, None, keep, root)
    rig.set_tail("shoulder.L", rig.head("side_fin.L"))
    if variant == "dolphin":
        start = rig.tail("spine") - 0.3 * rig.length("spine") * rig.direction("spine")
        span = 0.35 * tail_fins
        rig.add_chain(["fluke.L", "fluke.001.L"], start, [_unit([1.0, 0.6, 0.0]), _unit([1.0, 1.2, 0.0])], [0.55 * span, 0.45 * span], "spine")
    body_length = np.linalg.norm(np.diff(rig.path_points(FISH_BODY_PATH), axis=0), axis=1).sum()
    body = _FishBody(rig.path_points(FISH_BODY_PATH), ch.uniform(*FISH_DEPTH[variant]) * body_length, ch.uniform(*FISH_ASPECT[variant]))
    for bone in FISH_FIN_ROOTS:
        if rig.has(bone):
            centre, radial, radius = body.surface(rig.head(bone))
            rig.translate_subtree(bone, centre + FISH_FIN_ROOT_DEPTH * radius * radial - rig.head(bone))
    lure = []
    if ch.chance("lure"):
        centre, radial, radius = body.surface(body.path[0] + 0.12 * (body.path[-1] - body.path[0]), _Z)
        start = centre + 0.8 * radius * radial
        length = ch.uniform(0.15, 0.35) * body.length
        lure = rig.add_chain(_chain_names("lure", 2), start, [_unit([0.0, -0.4, 1.0]), _unit([0.0, -1.0, -0.2])],
                             [0.5 * length, 0.5 * length], "spine.007")
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["fish"]), axis=1)
    ch.settle()
    body = _FishBody(rig.path_points(FISH_BODY_PATH), body.half_height * unit, body.aspect)
    ch.tube("body", list(FISH_BODY_PATH), body.radii, up=_Z, parent=None)
    for name, bones, radii in FISH_FINS:
        if all(rig.has(b) for b in bones):
            scale = thick * unit * (tail_fins if bones[0] in tail_bones or name == "fluke.L" else fins)
            ch.tube(name, list(bones), _bone_radii(radii, scale), up=_Y, mirror=name.endswith(".L"))
    ch.tube("jaw", ["jaw", "jaw.001"], _bone_radii(FISH_JAW_RADII, thick * unit), up=_Z)
    # Eyes on the head surface, each moved by its eye bone.
    centre, radial, radius = body.surface(rig.head("eye.L"), _unit([1.0, 0.0, 0.6]))
    eye_radius = ch.uniform(0.12, 0.25) * radius
    eye_centre = centre + (radius - 0.4 * eye_radius) * radial
    rig.place("eye.L", eye_centre, eye_centre + 2.0 * eye_radius * radial)
    ch.rigid("eye.L", _ellipsoid_geometry(eye_centre, np.full(3, eye_radius), np.eye(3), ch.spacing), "eye.L", mirror=True)
    if lure:
        r = 0.02 * body.half_height
        ch.tube("lure", lure, [(r, r), (0.8 * r, 0.8 * r), (0.6 * r, 0.6 * r)], up=_Y, part_type=PART_DRIVEN)
        light = 0.12 * body.half_height
        ch.rigid("lure_light", _ellipsoid_geometry(rig.tail(lure[-1]), np.full(3, light), np.eye(3), ch.spacing), lure[-1])
    return variant


# ---------------------------------------------------------------------------
# Props: door, lamp, chest (1 to 4 bones, rigid pieces)
# ---------------------------------------------------------------------------

PROP_VARIANTS = ("door", "lamp", "chest")


def _build_door(ch) -> str:
    rig = ch.rig
    width, height, thickness = ch.uniform(0.6, 1.2), ch.uniform(1.8, 2.5), ch.uniform(0.03, 0.07)
    post = ch.uniform(0.05, 0.12)
    frame = ch.chance("door_frame")
    handle = ch.chance("door_handle")
    parent = None
    if frame:
        parent = rig.add("frame", [-0.5 * post, 0.0, 0.0], [-0.5 * post, 0.0, height], None)
    rig.add("door", [0.0, 0.0, 0.0], [0.0, 0.0, height], parent)
    knob = np.array([0.88 * width, -0.5 * thickness - 0.03, 0.45 * height])
    if handle:
        rig.add("handle", knob, knob - np.array([0.12, 0.0, 0.0]), "door")
    ch.settle()
    gap = 0.003
    ch.rigid("door", _box_geometry([0.5 * width, 0.0, 0.5 * height], [0.5 * width - gap, 0.5 * thickness, 0.5 * height - gap], np.eye(3)), "door")
    if frame:
        depth = 1.5 * thickness
        ch.rigid("frame_post_hinge", _box_geometry([-0.5 * post, 0.0, 0.5 * (height + post)], [0.5 * post, depth, 0.5 * (height + post)], np.eye(3)), "frame")
        ch.rigid("frame_post_latch", _box_geometry([width + 0.5 * post, 0.0, 0.5 * (height + post)], [0.5 * post, depth, 0.5 * (height + post)], np.eye(3)), "frame")
        ch.rigid("frame_lintel", _box_geometry([0.5 * width, 0.0, height + 0.5 * post], [0.5 * width, depth, 0.5 * post], np.eye(3)), "frame")
    if handle:
        stem = _prism_geometry(knob + np.array([0.0, 0.015, 0.0]), 0.015, (0.008, 0.008), _frame(_Y, _Z), 8)
        lever = _box_geometry(knob - np.array([0.06, 0.0, 0.0]), [0.012, 0.06, 0.008], _frame(-_X, _Z))
        ch.rigid("handle_stem", stem, "handle")
        ch.rigid("handle_lever", lever, "handle")
    return "door"


def _build_lamp(ch) -> str:
    rig = ch.rig
    base_radius, base_height = ch.uniform(0.08, 0.15), ch.uniform(0.02, 0.05)
    rig.add("base", [0.0, 0.0, 0.0], [0.0, 0.0, base_height], None)
    lower = rig.add_chain(["arm_lower"], rig.tail("base"), [_unit([0.0, -ch.uniform(0.0, 0.6), 1.0])], [ch.uniform(0.25, 0.5)], "base")
    arms = list(lower)
    if ch.chance("lamp_upper_arm"):
        arms += rig.add_chain(["arm_upper"], rig.tail("arm_lower"), [_unit([0.0, -1.0, ch.uniform(-0.3, 0.6)])], [ch.uniform(0.2, 0.45)], "arm_lower")
    shade_length = ch.uniform(0.1, 0.2)
    rig.add_chain(["shade"], rig.tail(arms[-1]), [_unit([0.0, -0.6, -1.0])], [shade_length], arms[-1])
    ch.settle()
    ch.rigid("base", _prism_geometry(np.array([0.0, 0.0, 0.5 * base_height]), 0.5 * base_height, (base_radius, base_radius), np.eye(3),
                                     _ring_segments(base_radius, ch.spacing)), "base")
    rod = 0.012
    for arm in arms:
        middle = 0.5 * (rig.head(arm) + rig.tail(arm))
        ch.rigid(arm, _prism_geometry(middle, 0.5 * rig.length(arm), (rod, rod), _frame(rig.direction(arm), _X), 8), arm)
        ch.rigid(f"{arm}_joint", _ellipsoid_geometry(rig.head(arm), np.full(3, 1.8 * rod), np.eye(3), ch.spacing), arm)
    ch.rigid("shade_joint", _ellipsoid_geometry(rig.head("shade"), np.full(3, 1.8 * rod), np.eye(3), ch.spacing), "shade")
    mouth = ch.uniform(0.06, 0.12)
    direction = rig.direction("shade")
    ch.rigid("shade", _cone_geometry(rig.tail("shade"), mouth, 0.9 * shade_length, _frame(-direction, _X), ch.spacing), "shade")
    ch.rigid("bulb", _ellipsoid_geometry(rig.tail("shade") - 0.2 * shade_length * direction, np.full(3, 0.35 * mouth), np.eye(3), ch.spacing), "shade")
    return "lamp"


def _build_chest(ch) -> str:
    rig = ch.rig
    width, depth, height, lid = ch.uniform(0.5, 1.0), ch.uniform(0.35, 0.6), ch.uniform(0.25, 0.45), ch.uniform(0.08, 0.2)
    rig.add("base", [0.0, 0.0, 0.0], [0.0, 0.0, height], None)
    rig.add("lid", [-0.5 * width, 0.5 * depth, height], [0.5 * width, 0.5 * depth, height], "base")
    lock = ch.chance("chest_lock")
    if lock:
        rig.add("lock", [0.0, -0.5 * depth - 0.01, height - 0.03], [0.0, -0.5 * depth - 0.01, height + 0.03], "base")
    ch.settle()
    ch.rigid("base", _box_geometry([0.0, 0.0, 0.5 * height], [0.5 * width, 0.5 * depth, 0.5 * height], np.eye(3)), "base")
    ch.rigid("lid", _box_geometry([0.0, 0.0, height + 0.5 * lid + 0.002], [0.5 * width, 0.5 * depth, 0.5 * lid], np.eye(3)), "lid")
    if lock:
        ch.rigid("lock", _box_geometry([0.0, -0.5 * depth - 0.012, height], [0.03, 0.01, 0.04], np.eye(3)), "lock")
    return "chest"


def _build_prop(ch) -> str:
    variant = PROP_VARIANTS[int(ch.rng.integers(len(PROP_VARIANTS)))]
    return {"door": _build_door, "lamp": _build_lamp, "chest": _build_chest}[variant](ch)


_BUILDERS: dict = {
    "biped": _build_biped,
    "quadruped": _build_quadruped,
    "multileg": _build_multileg,
    "winged": _build_winged,
    "tailed": _build_tailed,
    "long_chain": _build_long_chain,
    "fish": _build_fish,
    "prop": _build_prop,
}
