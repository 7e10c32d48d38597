"""Fingers of a hand, found by cutting the hand across.

A hand with separable fingers falls apart, cut across between the knuckles
and the tips, into one piece per finger; a mitten, a fist or a blocky
hand stays one piece. :func:`hand_fingers` cuts the hand's surface beyond
the wrist with :data:`CUTS` planes across the hand's direction; each cut's
contour (the plane's exact intersection with the triangles, sampled
densely) is split into pieces by single linkage with a gap of
:data:`GAP_SHARE` of the hand's length. At the cut where most pieces show
(4 or 5, or none is separable) each piece is a finger; it is followed cut
by cut to its tip and back to where it joins the palm (its knuckle: the
piece merges there, or jumps to the palm's centre). The finger whose
knuckle lies nearest the wrist is the thumb (with 4 pieces only when it
leads the others by :data:`THUMB_LEAD`); the others are index, middle,
ring and pinky by their knuckle's distance from the thumb's (from the
front without a thumb). Each finger is 3 bones, knuckle to tip, with the
joints at a third and two thirds of the way along the cut centres.

Positions are in the frame of the vertices given (the standard skeleton's
normalised frame: facing -y).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..skeleton.name_presets import DEFAULT_PRESET, preset_names

#: Rigify's finger names, thumb first; a hand with 4 fingers and a thumb has
#: no pinky, one with 4 and no thumb no thumb.
FINGER_NAMES = ("thumb", "f_index", "f_middle", "f_ring", "f_pinky")
#: Bones per finger.
FINGER_BONES = 3
#: Planes cutting the hand across, evenly spaced from the wrist to the tip.
CUTS = 48
#: Two contour points closer than this share of the hand's length belong to
#: the same piece (fingers in rest poses are a few millimetres apart: a
#: hand 19 cm long gives 1.9 mm).
GAP_SHARE = 0.01
#: Contour points are sampled this many times closer than the gap, so one
#: finger's contour never falls apart.
SAMPLES_PER_GAP = 3
#: Pieces this many cut spacings apart on neighbouring cuts are one finger
#: followed along (a finger at 60 degrees to the hand moves about 1.7).
MAX_STEP_SPACINGS = 3.0
#: A piece whose contour is this many times longer than the finger's on the
#: previous cut has merged with another finger or the palm.
MERGED_GROWTH = 1.6
#: With 4 pieces, the one whose knuckle is nearer the wrist than every other
#: by this share of the hand's length is a thumb.
THUMB_LEAD = 0.15
#: The hand is looked for within this share of the forearm's length of the
#: forearm's line beyond the wrist, and no farther than
#: :data:`HAND_LENGTH_SHARE` forearm lengths.
HAND_RADIUS_SHARE = 0.35
#: A human hand is shorter than its forearm, but the forearm the landmarks
#: give may be read short (the box-fingered test biped's 0.091 against its
#: 0.096 once the landmark runs are averaged), and then a cap at one forearm
#: ended the cuts inside long fingers. On 115 humanoids' samples 1.5 found
#: fingers on the same 8 whose artists rigged some and on one fewer without.
HAND_LENGTH_SHARE = 1.5
#: Pieces of a cut reaching farther than this share of the forearm's length
#: from the hand's line are something else (a thigh beside a hanging hand).
PIECE_RADIUS_SHARE = 0.5
#: A finger ends within this many cut spacings past its last cut (along a
#: thumb at 60 degrees to the hand, a cut spacing is two along the thumb).
TIP_CUTS = 3.0
#: The finger's line toward its tip is read over this many cuts, leaving
#: out the last few (they may cut a slanted fingertip off centre).
TIP_LINE_CUTS, TIP_SKIPPED_CUTS = 4, 2
#: A finger's surface reaches this many times its contour's mean radius
#: from its line (a square finger's corners: 1.11).
TIP_REACH = 1.5
#: Fewest pieces that make separable fingers, and most.
MIN_FINGERS, MAX_FINGERS = 4, 5
#: What the report says when no fingers are placed on a biped.
NOT_SEPARABLE_NOTE = ("fingers: not separable on this mesh (mitten hands, a fist or fingers touching), so each hand "
                      "is one bone")


@dataclass(frozen=True)
class Finger:
    """One finger's chain.

    Attributes
    ----------
    name : str, one of :data:`FINGER_NAMES` (no side)
    points : (FINGER_BONES + 1, 3) float64, knuckle, joints and tip
    """

    name: str
    points: np.ndarray


def finger_bone_names(finger: str, side: str = "") -> list:
    """Rigify's names of a finger's bones: ``["f_index.01.L", "f_index.02.L", "f_index.03.L"]``."""
    return [f"{finger}.{index:02d}{side}" for index in range(1, FINGER_BONES + 1)]


def has_fingers(names) -> bool:
    """Whether a standard biped skeleton, named by any preset, has finger bones."""
    rigify_names = preset_names(tuple(names), DEFAULT_PRESET)[0]
    return any(name.split(".")[0] in FINGER_NAMES for name in rigify_names)


def hand_extent(vertices: np.ndarray, wrist: np.ndarray, direction: np.ndarray, forearm_length: float) -> float | None:
    """How far the hand reaches past the wrist along ``direction`` (unit, (3,)):
    the farthest vertex within :data:`HAND_RADIUS_SHARE` of the forearm's
    length of the line, capped at :data:`HAND_LENGTH_SHARE` times ``forearm_length``; None when no vertex lies
    past the wrist."""
    offsets = vertices - wrist
    along = offsets @ direction
    across = np.linalg.norm(offsets - along[:, None] * direction, axis=1)
    reach = along[(along > 0) & (across <= HAND_RADIUS_SHARE * forearm_length)]
    return min(float(reach.max()), HAND_LENGTH_SHARE * forearm_length) if len(reach) else None


@dataclass(frozen=True)
class _Piece:
    centre: np.ndarray
    perimeter: float


def _contour(vertices: np.ndarray, triangles: np.ndarray, heights: np.ndarray, spacing: float) -> tuple:
    """Points every ``spacing`` along where the plane ``heights == 0`` cuts
    the triangles, and the length each point stands for.

    Returns
    -------
    (points (m, 3), lengths (m,)): ``lengths`` sums to the contour's length.
    """
    corner_heights = heights[triangles]
    cut = (corner_heights.min(axis=1) < 0) & (corner_heights.max(axis=1) >= 0)
    if not cut.any():
        return np.zeros((0, 3)), np.zeros(0)
    corners, corner_heights = vertices[triangles[cut]], corner_heights[cut]
    ends = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        ha, hb = corner_heights[:, a], corner_heights[:, b]
        crossing = (ha < 0) != (hb < 0)
        share = np.where(crossing, ha / np.where(crossing, ha - hb, 1.0), 0.0)
        ends.append((crossing, corners[:, a] + share[:, None] * (corners[:, b] - corners[:, a])))
    crossing = np.stack([flag for flag, _ in ends], axis=1)
    points = np.stack([point for _, point in ends], axis=1)
    # Exactly two edges of a cut triangle cross the plane: its segment's ends.
    first_two = np.argsort(~crossing, axis=1, kind="stable")[:, :2]
    starts = points[np.arange(len(points)), first_two[:, 0]]
    stops = points[np.arange(len(points)), first_two[:, 1]]
    lengths = np.linalg.norm(stops - starts, axis=1)
    counts = np.maximum(np.ceil(lengths / spacing).astype(np.int64), 1) + 1
    segment = np.repeat(np.arange(len(starts)), counts)
    step = np.arange(len(segment)) - np.repeat(np.cumsum(counts) - counts, counts)
    share = step / (counts[segment] - 1)
    samples = starts[segment] + share[:, None] * (stops - starts)[segment]
    return samples, (lengths / counts)[segment]


def _pieces(points: np.ndarray, lengths: np.ndarray, gap: float, wrist: np.ndarray, direction: np.ndarray,
            radius: float) -> list:
    """The contour's pieces (single linkage at ``gap``) lying wholly within
    ``radius`` of the hand's line."""
    if not len(points):
        return []
    pairs = cKDTree(points).query_pairs(gap, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(points), len(points)))
    count, labels = connected_components(graph, directed=False)
    offsets = points - wrist
    across = np.linalg.norm(offsets - (offsets @ direction)[:, None] * direction, axis=1)
    pieces = []
    for label in range(count):
        member = labels == label
        if across[member].max() <= radius:
            weights = lengths[member]
            pieces.append(_Piece(weights @ points[member] / weights.sum(), float(weights.sum())))
    return pieces


def _follow(cuts: list, start: int, piece: _Piece, step: int, max_step: float) -> list:
    """The centres of one finger's pieces from cut ``start`` on in ``step``
    (+1 toward the tip, -1 toward the wrist) while it stays one finger: the
    nearest piece of the next cut is within ``max_step`` and not
    :data:`MERGED_GROWTH` times longer around (merged with a neighbour)."""
    centres, previous, index = [], piece, start + step
    while 0 <= index < len(cuts) and cuts[index]:
        distances = [float(np.linalg.norm(candidate.centre - previous.centre)) for candidate in cuts[index]]
        nearest = cuts[index][int(np.argmin(distances))]
        if min(distances) > max_step or nearest.perimeter > MERGED_GROWTH * previous.perimeter:
            break
        centres.append(nearest.centre)
        previous, index = nearest, index + step
    return centres


def _chain(path: np.ndarray) -> np.ndarray:
    """(FINGER_BONES + 1, 3) points evenly spaced by length along ``path`` (k, 3)."""
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
    targets = np.linspace(0.0, lengths[-1], FINGER_BONES + 1)
    return np.stack([np.interp(targets, lengths, path[:, axis]) for axis in range(3)], axis=1)


def _tips(vertices: np.ndarray, ends: list, spacing: float) -> list:
    """Where each finger ends past its last cut: the farthest vertex along
    its line toward the tip (:data:`TIP_LINE_CUTS`), within :data:`TIP_CUTS`
    cut spacings of the last cut and nearer its line than any other finger's.

    Parameters
    ----------
    ends : list of (centres, reach): each finger's cut centres (k, 3) and
        how far from its line its surface reaches
    """
    lines = []
    for centres, _ in ends:
        # The last cuts may pass through a slanted fingertip, off the finger's line: read the line before them.
        origin = centres[max(len(centres) - 1 - TIP_SKIPPED_CUTS, 0)]
        direction = origin - centres[max(len(centres) - 1 - TIP_SKIPPED_CUTS - TIP_LINE_CUTS, 0)]
        norm = float(np.linalg.norm(direction))
        lines.append((origin, direction / norm if norm > 1e-12 else None))
    across = np.full((len(vertices), len(lines)), np.inf)
    along = np.zeros((len(vertices), len(lines)))
    for index, (last, direction) in enumerate(lines):
        if direction is None:
            continue
        offsets = vertices - last
        along[:, index] = offsets @ direction
        across[:, index] = np.linalg.norm(offsets - along[:, index, None] * direction, axis=1)
    nearest = np.argmin(across, axis=1)
    tips = []
    for index, ((last, direction), (_, reach)) in enumerate(zip(lines, ends)):
        if direction is None:
            tips.append(last)
            continue
        mine = ((nearest == index) & (across[:, index] <= reach) & (along[:, index] >= 0)
                & (along[:, index] <= (TIP_CUTS + TIP_SKIPPED_CUTS) * spacing))
        tips.append(last + direction * (float(along[mine, index].max()) if mine.any() else 0.0))
    return tips


def _named(knuckles: np.ndarray, wrist: np.ndarray, direction: np.ndarray, front: np.ndarray, length: float) -> list:
    """Each finger's name of :data:`FINGER_NAMES`, given their knuckles (k, 3)."""
    along = (knuckles - wrist) @ direction
    order = np.argsort(along)
    thumb = int(order[0])
    has_thumb = len(knuckles) == MAX_FINGERS or along[order[1]] - along[thumb] >= THUMB_LEAD * length
    names = [""] * len(knuckles)
    others = [index for index in range(len(knuckles)) if not (has_thumb and index == thumb)]
    if has_thumb:
        names[thumb] = FINGER_NAMES[0]
        others.sort(key=lambda index: float(np.linalg.norm(knuckles[index] - knuckles[thumb])))
    else:
        others.sort(key=lambda index: -float(knuckles[index] @ front))
    for name, index in zip(FINGER_NAMES[1:], others):
        names[index] = name
    return names


def hand_fingers(vertices: np.ndarray, triangles: np.ndarray, elbow: np.ndarray, wrist: np.ndarray,
                 front: np.ndarray = np.array([0.0, -1.0, 0.0])) -> tuple:
    """The fingers of the hand beyond ``wrist`` (see the module docstring).

    Parameters
    ----------
    vertices : (n, 3) float64, the character's surface (full resolution:
        a simplified proxy merges fingers)
    triangles : (t, 3) int
    elbow, wrist : (3,) the forearm's ends; the hand lies beyond the wrist
    front : (3,) unit, the character's front (orders fingers without a thumb)

    Returns
    -------
    tuple of Finger, thumb first then index to pinky; empty when the hand's
    fingers are not separable.
    """
    direction = np.asarray(wrist, dtype=np.float64) - elbow
    forearm_length = float(np.linalg.norm(direction))
    if forearm_length <= 1e-9 or not len(triangles):
        return ()
    direction /= forearm_length
    length = hand_extent(vertices, wrist, direction, forearm_length)
    if length is None:
        return ()
    gap = GAP_SHARE * length
    spacing = length / CUTS
    heights = (vertices - wrist) @ direction
    # Only triangles near the hand are cut.
    across = np.linalg.norm((vertices - wrist) - heights[:, None] * direction, axis=1)
    near = (heights >= -spacing) & (heights <= length + spacing) & (across <= 2.0 * PIECE_RADIUS_SHARE * forearm_length)
    triangles = triangles[near[triangles].any(axis=1)]
    cuts = []
    for step in range(CUTS):
        points, lengths = _contour(vertices, triangles, heights - (step + 0.5) * spacing, gap / SAMPLES_PER_GAP)
        cuts.append(_pieces(points, lengths, gap, wrist, direction, PIECE_RADIUS_SHARE * forearm_length))
    counts = np.array([len(pieces) if MIN_FINGERS <= len(pieces) <= MAX_FINGERS else 0 for pieces in cuts])
    if counts.max() == 0:
        return ()
    # The middle of the longest run of cuts showing the most fingers.
    best = counts == counts.max()
    runs, start = [], None
    for index, flag in enumerate(np.append(best, False)):
        if flag and start is None:
            start = index
        elif not flag and start is not None:
            runs.append((index - start, start, index))
            start = None
    _, first, stop = max(runs)
    reference = (first + stop - 1) // 2
    max_step = MAX_STEP_SPACINGS * spacing
    paths, reaches = [], []
    for piece in cuts[reference]:
        inward = _follow(cuts, reference, piece, -1, max_step)
        outward = _follow(cuts, reference, piece, +1, max_step)
        centres = [*inward[::-1], piece.centre, *outward]
        # It joins the palm half a cut before the first cut where it is not on its own.
        paths.append(np.array([centres[0] - direction * 0.5 * spacing, *centres]))
        reaches.append(TIP_REACH * piece.perimeter / (2.0 * np.pi))
    tips = _tips(vertices, [(path[1:], reach) for path, reach in zip(paths, reaches)], spacing)
    # The last cuts' centres may lie off the finger's line (a slanted tip): the chain leaves them out.
    paths = [np.vstack([path[:max(len(path) - TIP_SKIPPED_CUTS, 2)], tip]) for path, tip in zip(paths, tips)]
    knuckles = [path[0] for path in paths]
    names = _named(np.array(knuckles), wrist, direction, np.asarray(front, dtype=np.float64), length)
    fingers = [Finger(name, _chain(path)) for name, path in zip(names, paths)]
    return tuple(sorted(fingers, key=lambda finger: FINGER_NAMES.index(finger.name)))
