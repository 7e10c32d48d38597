"""Which way a character stands: the rotation that brings it upright along
+Z with its mirror plane at x = 0, read from its shape.

The networks expect the frame of Blender's front view: upright along +Z,
facing -Y, the character's left at +X. Users' files often are not so: an
import that left a Y-up character lying on its back, a character modelled
facing +X, one turned by an odd angle on its turntable. :func:`upright_rotation`
finds the rotation; :mod:`.predict` rigs the character in that frame and
brings the skeleton back, so the bones stand where the mesh is and ``.L``
is on the character's own left. Which of the two ways along the found axis
the character faces (-Y or +Y) is :mod:`.facing`'s call, after this.

Up is chosen among the six axis directions of the mesh's own space (a
character is modelled upright along one of them), or along the length of a
tall, thin body that leans 20 to 45 degrees from the nearest
(:func:`_stood_along_its_length`), and the facing among every direction
about up:

1. **The mirror plane.** A character is left-right symmetric: the plane
   through its centre that mirrors it best (:func:`best_mirror_plane`:
   among the shape's principal axes and the mesh's own, refined) has the
   left-right axis as its normal, so up is one of the four directions
   across it. An upright plane the feet straddle gives way to the upright
   plane across it when that one splits them (:func:`_plane_between_the_feet`:
   a biped with one arm turned in its frontal plane mirrors better front to
   back).
2. **Up along that plane**, of those four: the one the :data:`UP_CUES`
   score highest (:func:`up_score`). The cues were measured on the
   cached development characters turned every way (docs/bad_input.md).
3. **The facing** is then the plane's normal: the character is turned
   about up so that normal is x.

When the mirror plane is not clear (a shape as symmetric front to back as
left to right, an asymmetric creature) only axis-aligned quarter turns
about Z are made, by the plane across X or Y alone, as before.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.spatial import cKDTree

from ..errors import InputError
from ..nn.numpy_kernels import NUMPY
from ..nn.spec import shipped_weights
from .facing import TURNED_CONFIDENCE_GAIN
from .networks import upright as upright_network
from .standard_skeleton import KIND_CONFIDENCE, standard_confidence
from .symmetry import CLEARLY_BETTER, mirror_error_across
from .up_features import MIDLINE_SHARE, UP_BANDS, UP_CANDIDATES, area_centroids, candidate_features

#: Angle (degrees) about the best candidate mirror-plane normal within
#: which it is refined, on a 7 x 7 grid, then again three times finer.
PLANE_SEARCH_STEP = 15.0
#: Points mirrored to score a plane (evenly taken from the shape's); the
#: nearest is looked for among all of them.
PLANE_SAMPLE_POINTS = 400
#: A mirror plane within this angle (degrees) of an axis plane is taken as
#: that axis plane: artists' characters are modelled axis-aligned, and their
#: best plane wanders a few degrees with a held prop or a raised arm.
AXIS_SNAP_DEGREES = 12.0
#: A best plane slanted at least this far (degrees) from every axis plane is
#: a character turned on its turntable rather than one posed unevenly (a
#: cheering dancer's raised arms slant hers by 17 degrees), and it is taken
#: when it mirrors better than every axis plane and every plane across it by
#: :data:`TURNED_PLANE_BETTER`, not by :data:`.symmetry.CLEARLY_BETTER`: a
#: turned character in an uneven stance (weight on one leg, an arm forward)
#: mirrors only a little better across its plane, and rigged in the axis
#: frame nearest it (25 to 45 degrees off) its legs were read front to back
#: and its facing by the wrong feet (Nexuiz's idle stances, turned 30 to 43
#: degrees: four were kept so, one of them rigged with .L on its right).
TURNED_PLANE_DEGREES = 25.0
TURNED_PLANE_BETTER = 0.8
#: The mirror frame's up is the mesh axis lying most in the plane; +Z, then
#: +Y, is preferred when its share along the plane's normal is within this
#: of the least (an upright character's plane leans a few degrees).
UP_AXIS_TIE = 0.05
#: A body whose spread in its mirror plane (area-weighted variance) is at
#: least this many times larger along its major axis than across is tall
#: and thin; leaning :data:`LEANING_DEGREES` or more (and under 45) from the
#: mesh axis taken as up, it is stood along its length. Of the 399 cached
#: characters with a mirror plane, 166 are this elongated: 161 lean at most
#: 5 degrees from up, 4 lie within 3 degrees of flat (fish, a hawk: over 45,
#: left to the ways of standing), and the GDQuest mannequin, stored leaning
#: back 40 degrees with its feet forward (81 times), was rigged leaning and
#: got a free-form skeleton (its hips below its knees). Chunkier bodies lean
#: more (Quaternius' monsters, 2 to 10 times, 9 to 16 degrees with their big
#: heads) and are left as they stand (2026-12-08).
LEANING_ELONGATION = 20.0
LEANING_DEGREES = 20.0
#: The upright network must give another way of standing at least this
#: share of its and as-it-is's probability for that way to be tried on a
#: character that reads as a standing biped or quadruped as it is (an
#: upside-down human reads as a biped too, so the shape decides), and to
#: be taken without reading more surely than as it is.
UP_SURE = 0.9
#: A way of standing a character that reads as no standing body as it is
#: is tried only when the upright network gives it at least this share of
#: what it gives as it is (a crab stood on its side reads as a biped; the
#: upright network gives that 0.01 of as it is), and only when it gives it
#: more than the way opposite (head down).
UP_NOT_CONTRADICTED = 0.1
#: Of two ways of standing a lying character up that both read as a
#: standing body (head up and head down), the upright network must give
#: the first this share of the two's probability.
LYING_UP_SURE = 0.75
#: The feet cue of which end is up: standing, a biped's or quadruped's
#: lowest band is its feet, apart (midline share below
#: :data:`FEET_APART_MIDLINE`), and its top a head or a back, whole (at or
#: above :data:`HEAD_WHOLE_MIDLINE`); upside down, the other way round. On
#: the 233 cached humanoids and 65 quadrupeds standing, no character has its
#: lowest band whole and its top apart, and 171 and 53 of them turned upside
#: down read so (docs/bad_input.md).
FEET_APART_MIDLINE = 0.08
HEAD_WHOLE_MIDLINE = 0.15
#: A lying character is stood up only onto something like feet: its lowest
#: band, once stood, with a midline share below this, on both sides and
#: wide enough (below). Chosen with :data:`UP_NOT_CONTRADICTED` and the
#: head-up rule on the training characters, each turned four ways (docs/rigging.md#orientation):
#: the most stood up right with none of them turned as they stand.
STANDING_MIDLINE = 0.15
#: Feet stand on both sides: the less covered side of the lowest band holds
#: at least this share of its area (an L on its short arm does not).
FEET_BALANCE = 0.3
#: ... and stand at least this far (share of the largest side) from the
#: mirror plane: the two faces of a thin plate, a fish's fins, are not feet
#: (every cached humanoid and quadruped whose feet the cue finds stands wider).
FEET_HALF_WIDTH = 0.06
#: An upright mirror plane that runs through the feet is the body's front-back
#: plane when the upright plane across it splits them: at least this share of
#: the lowest band lies on the plane's midline (the band's own centre, so
#: that an arm raised on one side does not move it) ...
FEET_STRADDLED = 0.1
#: ... at most this share on the midline of the plane across it ...
FEET_SPLIT = 0.05
#: ... and the plane across mirrors the whole shape at most this many times
#: worse than the first. A biped with one arm turned 30 to 90 degrees in its frontal plane
#: mirrors better front to back (its arms stay in that plane; error ratios
#: 1.8 to 2.7): with that plane taken, it was rigged turned a quarter, its
#: .L bones on its right. None of the 396 cached characters with an upright
#: plane meets all three as they stand (the nearest, a fish: ratio 17.8;
#: ``scripts/check_orientation.py as-is`` keeps every one).
FEET_ACROSS_ERROR_RATIO = 5.0
#: A quarter turn about +Z: the upright plane across a frame's mirror plane.
QUARTER_TURN = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def best_mirror_plane(points: np.ndarray) -> tuple[np.ndarray, float, float]:
    """The plane halfway across the shape that mirrors ``points`` best.

    Returns
    -------
    normal : (3,) unit normal of the plane
    error : float, its :func:`mirror_error_across`
    across_error : float, the smallest error of the planes perpendicular to it
        (the runner-up a character could be confused with: a human front to back)
    """
    points = np.asarray(points, dtype=np.float64)
    tree = cKDTree(points)
    sample = points[::max(len(points) // PLANE_SAMPLE_POINTS, 1)]

    def error(normal):
        return mirror_error_across(points, normal, tree, sample)

    # A shape's mirror plane is perpendicular to one of its principal axes; the mesh's own axes are tried too
    # (two principal axes of nearly equal spread are ill-defined).
    spread = np.cov((points - points.mean(axis=0)).T)
    candidates = np.concatenate([np.linalg.eigh(spread)[1].T, np.eye(3)])
    errors = np.array([error(normal) for normal in candidates])
    best_candidate = int(np.argmin(errors))
    if best_candidate >= 3:
        # A mesh axis mirrors best, as it does an artist's character modelled axis-aligned: when it mirrors
        # clearly, the plane would be snapped to it anyway, so refining (most of this function's time) is skipped.
        normal, best = candidates[best_candidate], float(errors[best_candidate])
        across = _best_across(normal, error)[0]
        if best < CLEARLY_BETTER * across:
            return normal, best, across
    normal = _refined(candidates[best_candidate], error)
    best = error(normal)
    across, across_normal = _best_across(normal, error)
    if across < best:
        # The coarse grid fell in the wrong basin; the plane across it is the mirror plane.
        normal = _refined(across_normal, error)
        best = error(normal)
        across = _best_across(normal, error)[0]
    return normal, best, across


def _refined(normal: np.ndarray, error: Callable[[np.ndarray], float]) -> np.ndarray:
    """The direction of least ``error`` about ``normal``, searched twice on
    a local grid each three times finer, starting at the coarse step."""
    step = np.radians(PLANE_SEARCH_STEP)
    for _ in range(2):
        u, v = _perpendiculars(normal)
        offsets = np.linspace(-step, step, 7)
        local = [normal + a * u + b * v for a in offsets for b in offsets]
        local = [direction / np.linalg.norm(direction) for direction in local]
        normal = local[int(np.argmin([error(direction) for direction in local]))]
        step /= 3.0
    return normal


def _best_across(normal: np.ndarray, error: Callable[[np.ndarray], float]) -> tuple[float, np.ndarray]:
    """The least ``error`` of the planes perpendicular to ``normal``'s, and its normal."""
    u, v = _perpendiculars(normal)
    directions = [np.cos(angle) * u + np.sin(angle) * v for angle in np.radians(np.arange(0.0, 180.0, 7.5))]
    errors = [error(direction) for direction in directions]
    return float(min(errors)), directions[int(np.argmin(errors))]


def _perpendiculars(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors perpendicular to ``direction`` and to each other."""
    helper = np.eye(3)[int(np.argmin(np.abs(direction)))]
    u = np.cross(direction, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(direction, u)


def _axis_snapped(normal: np.ndarray) -> np.ndarray:
    """``normal`` as the nearest axis direction when within
    :data:`AXIS_SNAP_DEGREES` of it, else unchanged."""
    axis = int(np.argmax(np.abs(normal)))
    if abs(normal[axis]) >= np.cos(np.radians(AXIS_SNAP_DEGREES)):
        snapped = np.zeros(3)
        snapped[axis] = np.sign(normal[axis])
        return snapped
    return normal


def mirror_frame(points: np.ndarray) -> np.ndarray | None:
    """The rotation (3, 3) taking ``points`` (mesh space) to a frame whose x
    is the normal of their mirror plane and whose z is the axis direction of
    the mesh closest to lying in that plane, +Z first (for an upright
    character, its up), or None when no plane mirrors the shape clearly
    better than the planes across it (:data:`.symmetry.CLEARLY_BETTER`).

    The plane is :func:`best_mirror_plane`'s, snapped to an axis plane when
    within :data:`AXIS_SNAP_DEGREES`, and when farther taken only if it
    mirrors clearly better than every axis plane (slanted by
    :data:`TURNED_PLANE_DEGREES` or more, better by
    :data:`TURNED_PLANE_BETTER`): else the best axis plane. On the proxies
    of the 416 cached characters this turns 10, each within 8 degrees of the
    way the artist's skeleton stands (the GDQuest mannequin 11 degrees, nine
    of the eleven Nexuiz characters 30 to 43 degrees; the posed lurk and the
    marine stay as they are), and keeps a cheering dancer whose raised arms
    slant her best plane by 17 degrees (2026-12-08; 6 turned before
    :data:`TURNED_PLANE_BETTER`)."""
    normal, error, across = best_mirror_plane(points)
    normal = _axis_snapped(normal)
    clearly_better = CLEARLY_BETTER
    if np.abs(normal).max() < 1.0:
        tree = cKDTree(points)
        axis_errors = np.array([mirror_error_across(points, axis, tree) for axis in np.eye(3)])
        best_axis = int(np.argmin(axis_errors))
        slant = float(np.degrees(np.arccos(min(float(np.abs(normal).max()), 1.0))))
        if slant >= TURNED_PLANE_DEGREES and error < TURNED_PLANE_BETTER * min(float(axis_errors.min()), across):
            clearly_better = TURNED_PLANE_BETTER  # turned on its turntable, and posed unevenly
        elif error > CLEARLY_BETTER * axis_errors[best_axis]:
            # An axis-aligned character in an asymmetric pose (arms raised unevenly) mirrors a little better across
            # a slanted plane; one turned on its turntable mirrors far better across it.
            normal = np.eye(3)[best_axis]
            error, across = axis_errors[best_axis], float(np.delete(axis_errors, best_axis).min())
    if error >= clearly_better * across:
        return None
    if normal[0] < 0 or (normal[0] == 0 and (normal[1] < 0 or (normal[1] == 0 and normal[2] < 0))):
        normal = -normal  # the same plane; a fixed sign keeps an upright character's frame the identity
    # The axis lying most in the plane (least along its normal), +Z, then +Y, then +X when nearly as much: a
    # turned character lying on its back has its plane slanted about its up (+Y), and +Z lies only partly in it.
    least = float(np.abs(normal).min())
    axis = next(axis for axis in (2, 1, 0) if abs(normal[axis]) <= least + UP_AXIS_TIE)
    up = np.eye(3)[axis] - normal[axis] * normal
    up /= np.linalg.norm(up)
    return np.stack([normal, np.cross(up, normal), up])


def up_probabilities(points: np.ndarray, triangles: np.ndarray, weights: dict | None = None) -> np.ndarray:
    """(4,) probabilities of the :data:`.up_features.UP_CANDIDATES` by the
    upright network, for a mesh (``points`` (n, 3), ``triangles`` (m, 3))
    whose mirror plane is x = const."""
    weights = shipped_weights(upright_network.SPEC).weights if weights is None else weights
    surface, shares = area_centroids(points, triangles)
    scores = np.asarray(upright_network.SPEC.forward(NUMPY, weights, candidate_features(surface, shares)),
                        dtype=np.float64).reshape(-1)
    exp = np.exp(scores - scores.max())
    return exp / exp.sum()


def lowest_band(points: np.ndarray, triangles: np.ndarray) -> tuple[float, float, float]:
    """The lowest of :data:`.up_features.UP_BANDS` height bands of a mesh
    (``points`` (n, 3), ``triangles`` (m, 3)) whose mirror plane is x = its
    box centre: the share of its area on the midline (|x| within
    :data:`.up_features.MIDLINE_SHARE` of the band's half width), the share
    on its less covered side, and its half width (share of the largest side)."""
    surface, shares = area_centroids(points, triangles)
    heights = surface[:, 2] - surface[:, 2].min()
    band = heights < heights.max() / UP_BANDS
    x = surface[band, 0] - 0.5 * (points[:, 0].min() + points[:, 0].max())
    weights = shares[band] / max(shares[band].sum(), 1e-300)
    half_width = float(np.abs(x).max())
    midline = float(weights[np.abs(x) < MIDLINE_SHARE * half_width].sum())
    largest_side = float((points.max(axis=0) - points.min(axis=0)).max())
    return midline, float(min(weights[x < 0].sum(), weights[x > 0].sum())), half_width / largest_side


def on_its_feet(points: np.ndarray, triangles: np.ndarray, apart: float = STANDING_MIDLINE) -> bool:
    """Whether the lowest band of a mesh whose mirror plane is x = its box
    centre stands on both sides (:data:`FEET_BALANCE`, :data:`FEET_HALF_WIDTH`)
    with under ``apart`` of its area on the midline."""
    midline, smaller_side, half_width = lowest_band(points, triangles)
    return midline < apart and smaller_side >= FEET_BALANCE and half_width >= FEET_HALF_WIDTH


@dataclass(frozen=True)
class Stance:
    """How the character is turned for the prediction.

    Attributes
    ----------
    rotation : (3, 3) from the mesh's space to the frame the character stands upright in,
        its mirror plane across x (before the normalisation's scale and shift)
    landmarks : the landmark network's reading in that frame
    notes : tuple of str, what was found and done
    """

    rotation: np.ndarray
    landmarks: object
    notes: tuple = ()


def axis_name(direction: np.ndarray) -> str:
    """'+Y', '-Z'... for a direction near an axis, else its rounded components."""
    axis = int(np.argmax(np.abs(direction)))
    if abs(direction[axis]) >= np.cos(np.radians(AXIS_SNAP_DEGREES)):
        return f"{'+' if direction[axis] > 0 else '-'}{'XYZ'[axis]}"
    return "(" + ", ".join(f"{value:.2f}" for value in direction) + ")"


def stand_upright(points: np.ndarray, triangles: np.ndarray, landmarks_of: Callable[[np.ndarray], object]) -> Stance:
    """Find the rotation that stands the character upright (see the module
    docstring), reading the landmark network through ``landmarks_of``
    (rotation -> Landmarks of the mesh turned by it) as few times as it can.

    1. No clear mirror plane: the character is taken as it is.
    2. Its mirror plane found (:func:`mirror_frame`; the upright plane across
       it when the feet tell, :func:`_plane_between_the_feet`), it is turned
       so the plane is x = 0, up the mesh's axis lying most in the plane:
       *as it is*.
    3. Other ways of standing it (:data:`.up_features.UP_CANDIDATES`) are
       read when the character as it is does not read as a standing biped
       or quadruped (:data:`.standard_skeleton.KIND_CONFIDENCE`; then the
       two lying ways), when it does but the upright network is
       :data:`UP_SURE` of another way against as it is, or its feet seem to
       be on top (upside down: :data:`FEET_APART_MIDLINE`), and when its
       mirror plane lies flat (on its side: all four ways).
    4. A way is taken when the upright network does not plainly contradict
       it (:data:`UP_NOT_CONTRADICTED`) and prefers it to its opposite, and
       it reads as a standing biped or quadruped, more
       surely than as it is by :data:`.facing.TURNED_CONFIDENCE_GAIN`
       unless it was tried as a sure thing, and standing on something like
       feet (:data:`STANDING_MIDLINE`: a fish stood on its tail reads as a
       biped, but stands on a fin). Of two such ways the upright network
       picks, when it gives one :data:`LYING_UP_SURE` of the two; otherwise
       the character is refused, as is one on its side no way stands up.

    Raises
    ------
    InputError for a character lying whose up cannot be told.
    """
    frame = mirror_frame(points)
    if frame is None:
        rotation = np.eye(3)
        return Stance(rotation, landmarks_of(rotation))
    frame, feet_notes = _plane_between_the_feet(points, triangles, frame)
    axis_frame = frame
    frame, lean_notes = _stood_along_its_length(points, triangles, frame)
    framed = points @ frame.T
    probabilities = up_probabilities(framed, triangles)
    on_its_side = abs(frame[0, 2]) >= np.cos(np.radians(45.0))
    if on_its_side:
        landmarks, confidence, ways = None, 0.0, [0, 1, 2, 3]
    else:
        landmarks = landmarks_of(frame)
        confidence = standard_confidence(landmarks)
        if confidence >= KIND_CONFIDENCE:
            ways = [turns for turns in (1, 2, 3)
                    if probabilities[turns] >= UP_SURE * (probabilities[turns] + probabilities[0])
                    or (turns == 2 and _stands_on_its_head(framed, triangles))]
        else:
            # Not a standing body as it is: perhaps a lying one. (Upside down, a body still reads as one.)
            ways = [1, 3]
    standing = []
    for turns in ways:
        turned = UP_CANDIDATES[turns] @ frame
        reading = landmarks_of(turned)
        # Ways tried as sure things (as it is already reads as standing) need not read more surely than it.
        gain = 0.0 if confidence >= KIND_CONFIDENCE else TURNED_CONFIDENCE_GAIN
        if not on_its_side and probabilities[turns] < UP_NOT_CONTRADICTED * probabilities[0]:
            continue  # the shape says plainly it stands as it is (a crab reads as a biped stood on its side)
        if probabilities[turns] <= probabilities[(turns + 2) % 4]:
            continue  # the shape says it would stand on its head that way (a whale stood on its flukes)
        # Stood up, a lying biped or quadruped stands on its feet, apart; a fish stood on its tail or nose
        # reads as a biped to the landmark network, but stands on a fin or a snout.
        if standard_confidence(reading) >= max(KIND_CONFIDENCE, confidence + gain) and on_its_feet(points @ turned.T,
                                                                                                  triangles):
            standing.append((float(probabilities[turns]), turned, reading))
    standing.sort(key=lambda entry: -entry[0])
    how = "lies on its side" if on_its_side else "is not upright"
    if len(standing) > 1 and standing[0][0] < LYING_UP_SURE * (standing[0][0] + standing[1][0]):
        raise InputError(f"The character {how} (its mirror plane found, it reads as a standing {standing[0][2].kind} "
                         "two ways, head up or head down), and which end is up cannot be told: stand it upright "
                         "along +Z, facing -Y, and predict again.")
    if standing:
        _, turned, reading = standing[0]
        return Stance(turned, reading, (*lean_notes, _turn_note(turned, how, reading)))
    if on_its_side:
        raise InputError("The character seems to lie on its side (its mirror plane is horizontal), and no way of "
                         "standing it up reads as a biped or quadruped: stand it upright along +Z, facing -Y, and "
                         "predict again.")
    return Stance(frame, landmarks, (*feet_notes, *_facing_notes(axis_frame), *lean_notes))


def _stood_along_its_length(points: np.ndarray, triangles: np.ndarray, frame: np.ndarray) -> tuple[np.ndarray, list]:
    """``frame``, or it turned about its x (the mirror plane's normal) so that
    its z runs along the body's length, with a note then: for a tall, thin
    body (:data:`LEANING_ELONGATION`) whose length leans
    :data:`LEANING_DEGREES` to 45 degrees from the mesh axis taken as up.
    The length is the major axis of the area's spread in the mirror plane."""
    if abs(frame[0, 2]) >= np.cos(np.radians(45.0)):
        return frame, []  # the plane lies flat: up is told by the ways of standing, not by a lean
    surface, shares = area_centroids(points @ frame.T, triangles)
    in_plane = surface[:, 1:] - np.average(surface[:, 1:], axis=0, weights=shares)
    spread = (in_plane * shares[:, None]).T @ in_plane / max(float(shares.sum()), 1e-300)
    variances, directions = np.linalg.eigh(spread)
    if not variances[1] >= LEANING_ELONGATION * max(float(variances[0]), 1e-300):
        return frame, []
    length = directions[:, 1] * (1.0 if directions[1, 1] >= 0.0 else -1.0)  # (y, z), toward the frame's up
    lean = float(np.arctan2(length[0], length[1]))
    if not np.radians(LEANING_DEGREES) <= abs(lean) < np.radians(45.0):
        return frame, []
    cosine, sine = np.cos(lean), np.sin(lean)
    about_x = np.array([[1.0, 0.0, 0.0], [0.0, cosine, -sine], [0.0, sine, cosine]])
    return about_x @ frame, [f"The character leans {np.degrees(abs(lean)):.0f} degrees from {axis_name(frame[2])} "
                             "of its own space (its length, in its mirror plane, runs that way): it was stood along "
                             "its length for the prediction."]


def _plane_between_the_feet(points: np.ndarray, triangles: np.ndarray, frame: np.ndarray) -> tuple[np.ndarray, list]:
    """``frame``, or the upright frame across it when its mirror plane runs
    through the feet and the plane across splits them (:data:`FEET_STRADDLED`,
    :data:`FEET_SPLIT`, :data:`FEET_ACROSS_ERROR_RATIO`), with a note then."""
    if abs(frame[0, 2]) >= np.cos(np.radians(45.0)):
        return frame, []  # the plane lies flat: no feet to tell by
    across = QUARTER_TURN @ frame
    normal = across[0]
    if normal[0] < -1e-12 or (abs(normal[0]) <= 1e-12 and normal[1] < 0):
        across = np.diag([-1.0, -1.0, 1.0]) @ across  # the same plane, signed as mirror_frame signs it
    if (feet_across(points @ frame.T, triangles)[0] < FEET_STRADDLED
            or feet_across(points @ across.T, triangles)[0] > FEET_SPLIT):
        return frame, []
    tree = cKDTree(points)
    if mirror_error_across(points, across[0], tree) > FEET_ACROSS_ERROR_RATIO * mirror_error_across(points, frame[0],
                                                                                                     tree):
        return frame, []
    return across, ["The shape mirrors best front to back, but its feet stand apart across the other upright plane, "
                    "so that one was taken as its mirror plane (an arm raised on one side, say)."]


def feet_across(framed: np.ndarray, triangles: np.ndarray) -> tuple[float, float]:
    """The lowest height band (:data:`.up_features.UP_BANDS`) of a mesh
    standing along +z, measured along x about the band's own centre (so that
    an arm raised on one side does not move it): the share of its area
    within :data:`.up_features.MIDLINE_SHARE` of its half width of that
    centre (1 when the band has no width), and the centre's x."""
    surface, shares = area_centroids(framed, triangles)
    heights = surface[:, 2] - surface[:, 2].min()
    band = heights < heights.max() / UP_BANDS
    centre = 0.5 * float(surface[band, 0].min() + surface[band, 0].max())
    x = surface[band, 0] - centre
    if not np.abs(x).max() > 0:
        return 1.0, centre  # a band without width lies wholly on its midline: it splits nothing
    weights = shares[band] / max(shares[band].sum(), 1e-300)
    return float(weights[np.abs(x) < MIDLINE_SHARE * np.abs(x).max()].sum()), centre


def _stands_on_its_head(framed: np.ndarray, triangles: np.ndarray) -> bool:
    """The feet cue (:data:`FEET_APART_MIDLINE`): the lowest band of the
    ``framed`` mesh is whole and its top apart."""
    head_whole = lowest_band(framed, triangles)[0] >= HEAD_WHOLE_MIDLINE
    return head_whole and on_its_feet(framed @ UP_CANDIDATES[2].T, triangles, FEET_APART_MIDLINE)


def _facing_notes(frame: np.ndarray) -> list[str]:
    """What turning the mesh by ``frame`` about its vertical axis did ([] when nothing)."""
    # Up within the snap angle of +Z is upright: a turned character's plane leans a few degrees with its stance.
    if np.allclose(frame, np.eye(3), atol=1e-9) or frame[2, 2] < np.cos(np.radians(AXIS_SNAP_DEGREES)):
        return []
    angle = float(np.degrees(np.arctan2(frame[0, 1], frame[0, 0])))
    if round(abs(angle)) == 0:
        return []
    if abs(abs(angle) - 90.0) < 1e-6:
        return ["The character faces +-X; it was turned a quarter for the prediction (its mirror plane is x = 0 of "
                "its own space)."]
    # Said from the nearer pair of axes: a plane 63 degrees off x is a character 27 degrees off facing +-X.
    nearer, off = ("-Y or +Y", abs(angle)) if abs(angle) <= 45.0 else ("+X or -X", 90.0 - abs(angle))
    return [f"The character is turned {off:.0f} degrees about Z from facing {nearer} (its mirror plane was found at "
            "that angle); it was turned back for the prediction."]


def _turn_note(rotation: np.ndarray, how: str, landmarks) -> str:
    up = rotation[2]  # the mesh-space direction the frame's +z is
    return (f"The character {how} (its up is {axis_name(up)} of its own space; stood up, it reads as a "
            f"{landmarks.kind}, {landmarks.confidence:.0%} sure): it was stood upright for the prediction, and the "
            "skeleton is turned back with it.")
