"""Key joints of the closest known rig: a library of the training characters' key joints.

The landmark network places key joints the way the bodies it learnt from
have them; a close relative of a training character (the validation cow
of Quaternius' animal pack beside its training bull, the asian elephants of
0 A.D. in other harness) is rigged better by the relative's artist than by
the network's average: on the held-out training characters the copied key
joints are more often right (within 0.05) than the network's
(:data:`LIBRARY_DISTANCE`), above all on animals, whose artists place the
wrists at the hoof or at the carpus and the hips at the pelvis or at the
tail's root, family by family.

The library (``trained/rig_library.npz``, built by ``train library``)
holds, per training character, :data:`LIBRARY_POINTS` points on its
normalised surface (:func:`library_points`) and its kind, and for the bipeds and quadrupeds whose
bone names give key joints, those key joints in that frame. A character
the landmark network reads surely as one of those kinds (or a biped by its
nearest known body) finds the entry of its kind with key joints whose
surface is nearest (symmetric Chamfer distance, in units of the largest side) when that distance is at
most :data:`LIBRARY_DISTANCE`; a standard skeleton of that kind (not of a
kind the user forces instead) takes the entry's key joints, mapped by a
scale and a shift per axis (:func:`entry_map`: the bounding boxes' map,
refined on the two surfaces where that brings them closer), and the landmark
network's stay for the key joints the entry lacks (KayKit's rigs have no
neck). Run on a training character, the search finds that character itself.

The same surfaces also say what kind of body a character is when the
landmark network cannot (:func:`nearest_known_body`): Kenney's chibi minis,
read as "other", lie nearest KayKit's chibi ranger.

Each entry also keeps its artist's whole rig (the deform bones, names and
parents, made one tree by :func:`_one_tree_rig`): a character with a known
relative within :data:`LIBRARY_DISTANCE` gets that rig fitted to it by
default (:func:`fitted_rig`, :data:`KNOWN_RIG`), as the closest-character
baseline does (though that maps the bounding boxes alone) but only where a
relative is near: Quaternius' casual woman takes the joints, names and
hierarchy of her pack's suited woman (not the
bones' rolls, which the library does not keep), so animations made for the
pack retarget onto her by name.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from ..evaluation.skeleton_metrics import symmetric_chamfer
from ..geometry.bounding_box import bounding_box
from ..skeleton.hierarchy import ancestors, parents_first_order, reindexed_parents, subset_parents
from ..skeleton.key_joints import KEY_JOINT_TWINS, KEY_JOINTS
from ..types import Mesh, Skeleton
from .nearest_character import SURFACE_POINTS, surface_points
from .networks.landmarks import BODY_KINDS, STANDARD_KINDS, sample_landmarks
from .networks.trained import TRAINED_FOLDER
from .surface_fit import AxisMap, fitted_axis_map
from .symmetry import mirror_points

#: The shipped library.
LIBRARY_FILE = TRAINED_FOLDER / "rig_library.npz"
#: Nearest surfaces at most this far apart (symmetric Chamfer distance of
#: :data:`SURFACE_POINTS` points each, share of the largest side) give their
#: key joints. Chosen without the validation characters (2026-11-26):
#:
#: - on the 40 held-out training bipeds and quadrupeds (every sixth by name,
#:   which the landmark network never trained on), each with itself and its
#:   near-duplicates out of the library and its kind given (the network's raw
#:   landmarks, without the biped corrections; ``scripts/tune_rig_library.py``),
#:   key joints within 0.05 are 85.9 % (the network's alone), 87.6 % with a
#:   limit of 0.015, 86.3 % at 0.02, 87.3 % at 0.025, 87.7 % at 0.03, 86.2 %
#:   at 0.035: flat from 0.015 to 0.03, one character apart;
#: - over every training character so copied, the copy's key joints are
#:   right for 92 % of those 0.01 to 0.015 away, 81 % at 0.015 to 0.02, 71 %
#:   at 0.02 to 0.025, but 52 % at 0.025 to 0.03 and 23 % beyond: there a
#:   body is like a generic one of its kind, no relative;
#: - on procedural bipeds and quadrupeds (seeds 0 to 9, exact roles), which
#:   no artist rigged, copies 0.025 to 0.03 away placed fewer key joints
#:   than the network on four of five.
#:
#: The surfaces of two near-duplicates lie 0.007 to 0.01 apart.
#:
#: Since the library keeps :data:`LIBRARY_POINTS` points a side (2026-12-07)
#: the same pair of surfaces measures 0.0009 farther at this distance (a
#: straight-line fit over the nearest three entries of every training
#: character), so the limit moved with it, 0.025 to 0.026; the held-out
#: curve above is as flat with the new points (84.9 % the network's alone,
#: 86.9 % at 0.015, 86.7 % at 0.026, 87.0 % at 0.03).
LIBRARY_DISTANCE = 0.026
#: Points each entry keeps (:func:`library_points`): the most spread of the
#: :data:`SURFACE_POINTS` drawn on its surface. Half of them, stored as one
#: byte per coordinate, keep the extension's zip under issue 18's 40 MB
#: (the library's points took 3.6 MB at 2,000 a body in half precision, 0.98 MB so).
#: Measured on the nearest three entries of every training character, the
#: Chamfer distance to a body sampled at :data:`SURFACE_POINTS` points grows
#: by 0.0011 of the largest side (0.0002 more than the full set's rounding
#: to bytes alone, 0.0001): the limits below were chosen again with it.
LIBRARY_POINTS = 1_000
#: Steps per side of an entry's box its points are stored at: 1/255 of a
#: side, at most 0.002 of the largest side from where they were drawn.
STORED_STEPS = 255
#: Points of each entry measured first (:func:`_nearest_entry`): its first
#: ones, kept in random order (a uniform sample; the saved file sorts the
#: rest, :func:`_sorted_after_screen`). Their mean
#: distance estimates the entry's within about 6 % (one standard deviation).
SCREEN_POINTS = 250
#: An entry is measured in full while half its screened distance is at most
#: this many times the best distance so far: four standard deviations of
#: the estimate.
SCREEN_MARGIN = 1.25
#: Entries measured in full at most, the nearest one way first. On every
#: cached validation and held-out training character read as either kind,
#: itself and its near-duplicates out of the library, the same entry as
#: measuring all of them at the shipped limit
#: (``scripts/tune_rig_library.py --check-screen``: 292 readings, the 92
#: validation and 54 held-out training characters each read both ways) but
#: for one reading that picks another 0 A.D. man of the same body and
#: skeleton under another head (the same key joints).
MEASURED_IN_FULL = 16
#: A body the landmark network does not read surely as a biped or a
#: quadruped is a biped when its nearest known body is one, at most this far
#: away (:func:`nearest_known_body`). Chosen on the training characters
#: alone (2026-12-06; ``scripts/tune_relative_kind.py``), each measured
#: against the others of every family but its own: no fish, bird, quadruped or "other" body has a biped nearest
#: within 0.053 (two snakes; Quaternius' blob Mushnubs at 0.07 and 0.087),
#: while 167 of the 178 humanoids have one within 0.045 and 171 within
#: 0.05. Not for quadrupeds: a velociraptor has a quadruped nearest, 0.044
#: away. With :data:`LIBRARY_POINTS` points a side, 0.045 measures 0.0456
#: (as for :data:`LIBRARY_DISTANCE`), and the limit moved to 0.046; the
#: check gives the same counts (no other body with a biped nearest within
#: 0.05, 167 humanoids within 0.045).
RELATIVE_KIND_DISTANCE = 0.046
#: What the *Auto* template gives a body with a known relative within
#: :data:`LIBRARY_DISTANCE` (:func:`fitted_rig`): for a body read as a
#: biped or quadruped, the entry whose key joints it copies
#: (:func:`closest_rig`); for another, its nearest known body.
KNOWN_RIG = "known rig"


@dataclass(frozen=True)
class RigLibrary:
    """The training characters' surfaces and kinds, and the key joints of those that give them.

    Attributes
    ----------
    names : (n,) str, the characters (paths in the data without extension)
    kinds : (n,) str, ``biped``, ``quadruped`` or ``other`` (fish, birds and the rest)
    points : (n, LIBRARY_POINTS, 3) float32, points on each normalised surface
    key_joints : (n, k, 3) float32, in :data:`..skeleton.key_joints.KEY_JOINTS` order
    known : (n, k) bool, which key joints each rig gives (none: the entry only tells a kind)
    boxes : (n, 2, 3) float32, each normalised mesh's bounding box (lowest, highest corner)
    rig_counts : (n,) int64, bones of each entry's rig (:func:`_one_tree_rig`; 0: none, no bone deforms)
    rig_joints, rig_tails : (sum of rig_counts, 3) float32, the rigs' heads and tails, entry after entry
    rig_parents : (sum of rig_counts,) int64, each bone's parent within its rig (-1: the root), parents first
    rig_names : (sum of rig_counts,) str, the artists' bone names
    rig_deform : (sum of rig_counts,) bool, whether each bone deforms (those that only join the
        deform bones into one tree do not)
    """

    names: np.ndarray
    kinds: np.ndarray
    points: np.ndarray
    key_joints: np.ndarray
    known: np.ndarray
    boxes: np.ndarray
    rig_counts: np.ndarray
    rig_joints: np.ndarray
    rig_tails: np.ndarray
    rig_parents: np.ndarray
    rig_names: np.ndarray
    rig_deform: np.ndarray

    def save(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        # The rigs at half precision: 0.0005 of the largest side at worst.
        # The steps axis by axis: the sorted x of each entry's later points then compress (0.96 to 0.81 MB).
        np.savez_compressed(path, names=self.names, kinds=self.kinds,
                            steps_by_axis=_sorted_after_screen(_to_steps(self.points, self.boxes)).transpose(0, 2, 1),
                            key_joints=self.key_joints.astype(np.float32), known=self.known,
                            boxes=self.boxes.astype(np.float32), rig_counts=self.rig_counts.astype(np.int32),
                            rig_joints=self.rig_joints.astype(np.float16), rig_tails=self.rig_tails.astype(np.float16),
                            rig_parents=self.rig_parents.astype(np.int16), rig_names=self.rig_names,
                            rig_deform=self.rig_deform)

    def rig_rows(self, entry: int) -> slice:
        """The rows of entry ``entry``'s rig in the ``rig_*`` arrays."""
        start = int(self.rig_counts[:entry].sum())
        return slice(start, start + int(self.rig_counts[entry]))

    def subset(self, keep: np.ndarray) -> "RigLibrary":
        """The entries where ``keep`` (n,) bool is true."""
        rows = np.repeat(np.asarray(keep, dtype=bool), self.rig_counts)
        return RigLibrary(self.names[keep], self.kinds[keep], self.points[keep], self.key_joints[keep],
                          self.known[keep], self.boxes[keep], self.rig_counts[keep], self.rig_joints[rows],
                          self.rig_tails[rows], self.rig_parents[rows], self.rig_names[rows],
                          self.rig_deform[rows])

    @classmethod
    def load(cls, path: Path) -> "RigLibrary":
        with np.load(path, allow_pickle=False) as data:
            steps = data["steps_by_axis"].transpose(0, 2, 1)
            return cls(data["names"], data["kinds"], _from_steps(steps, data["boxes"]), data["key_joints"],
                       data["known"], data["boxes"], data["rig_counts"].astype(np.int64),
                       data["rig_joints"].astype(np.float32), data["rig_tails"].astype(np.float32),
                       data["rig_parents"].astype(np.int64), data["rig_names"], data["rig_deform"])


def _box_sides(boxes: np.ndarray) -> np.ndarray:
    """(n, 1, 3) sides of (n, 2, 3) boxes, a flat side counted as 1 (its points all lie at its low corner)."""
    sides = (boxes[:, 1] - boxes[:, 0]).astype(np.float64)[:, None, :]
    return np.where(sides > 0.0, sides, 1.0)


def _to_steps(points: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """(n, p, 3) points inside their (n, 2, 3) boxes as uint8 steps of :data:`STORED_STEPS` per side."""
    fractions = (points - boxes[:, :1].astype(np.float64)) / _box_sides(boxes)
    return np.rint(np.clip(fractions, 0.0, 1.0) * STORED_STEPS).astype(np.uint8)


def _sorted_after_screen(steps: np.ndarray) -> np.ndarray:
    """(n, p, 3) steps with each entry's first :data:`SCREEN_POINTS` in their
    random order (the screening's uniform sample) and the rest, a set whose
    order nothing reads, sorted by x, then y, then z, so that the saved file
    compresses."""
    steps = steps.copy()
    rest = steps[:, SCREEN_POINTS:]
    order = np.lexsort((rest[..., 2], rest[..., 1], rest[..., 0]), axis=-1)
    steps[:, SCREEN_POINTS:] = np.take_along_axis(rest, order[..., None], axis=1)
    return steps


def _from_steps(steps: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """The float32 points :func:`_to_steps` stored."""
    return (boxes[:, :1] + steps / STORED_STEPS * _box_sides(boxes)).astype(np.float32)


def as_stored(points: np.ndarray, box: np.ndarray) -> np.ndarray:
    """One entry's (p, 3) points inside its (2, 3) box as the saved library gives them back (there, those after
    the first :data:`SCREEN_POINTS` in another order)."""
    return _from_steps(_to_steps(points[None], box[None]), box[None])[0]


def library_points(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(LIBRARY_POINTS, 3) points of a surface as the library keeps them: of
    :data:`SURFACE_POINTS` drawn uniformly by area, the farthest-point
    subset (each next point the one farthest from those taken; it spreads
    over the surface as a random subset does not, so the Chamfer distance
    grows less), then in a fixed random order so that any first part of
    them is a uniform sample (:data:`SCREEN_POINTS`)."""
    drawn = surface_points(vertices, triangles, SURFACE_POINTS)
    taken = np.zeros(LIBRARY_POINTS, dtype=np.int64)
    distance = np.linalg.norm(drawn - drawn[0], axis=1)
    for index in range(1, LIBRARY_POINTS):
        taken[index] = int(np.argmax(distance))
        distance = np.minimum(distance, np.linalg.norm(drawn - drawn[taken[index]], axis=1))
    return drawn[taken[np.random.default_rng(0).permutation(LIBRARY_POINTS)]]


@dataclass(frozen=True)
class ClosestRig:
    """The library entry nearest a character: its name, the surface distance,
    its key joints mapped onto the character (normalised frame), the
    ones its rig has only, and the map that took them there
    (:func:`entry_map`)."""

    name: str
    distance: float
    points: dict
    axis_map: AxisMap

    @property
    def note(self) -> str:
        copied = (f"Key joints copied from the closest known rig, {self.name} (surfaces {self.distance:.3f} of the "
                  "largest side apart)")
        lacking = len(KEY_JOINTS) - len(self.points)
        return f"{copied}; the landmark network's kept for the {lacking} it lacks." if lacking else f"{copied}."


@dataclass(frozen=True)
class KnownRelative:
    """The known body nearest a character (:func:`nearest_known_body`): its
    name, its kind and the surface distance."""

    name: str
    kind: str
    distance: float

    @property
    def note(self) -> str:
        return f"the closest known body, {self.name} ({self.distance:.3f} of the largest side away), is a {self.kind}"


@dataclass(frozen=True)
class KnownRig:
    """The rig of a known body near a character (:func:`fitted_rig`): the
    entry's name, kind and surface distance, and its artist's rig
    (:func:`_one_tree_rig`) mapped onto the character (normalised frame)."""

    name: str
    kind: str
    distance: float
    skeleton: Skeleton

    @property
    def note(self) -> str:
        return (f"Template: the rig of the closest known character, {self.name} (surfaces {self.distance:.3f} of the "
                f"largest side apart), fitted to this body: its artist's {len(self.skeleton.names)} bones and names")


@lru_cache(maxsize=1)
def _loaded_library() -> RigLibrary | None:
    """The shipped library file, read once; None when it is absent (a checkout before ``train library``)."""
    return RigLibrary.load(LIBRARY_FILE) if LIBRARY_FILE.is_file() else None


#: Libraries standing in for the shipped one while :func:`shipped_library_without` runs, innermost last.
_STAND_INS: list = []


def shipped_library() -> RigLibrary | None:
    """The shipped library (without the characters :func:`shipped_library_without` leaves out, inside it)."""
    return _STAND_INS[-1] if _STAND_INS else _loaded_library()


@contextmanager
def shipped_library_without(names):
    """Inside, :func:`shipped_library` lacks the characters ``names`` (paths in the data without
    extension): scoring a training character (``eval rig``), its own rig and its near-duplicates' are
    not there to copy, as for a character the project has never seen. Each call leaves its names out
    of the whole shipped library: nested calls do not add up."""
    library = _loaded_library()
    if library is not None:
        library = library.subset(~np.isin(library.names, sorted(names)))
    _STAND_INS.append(library)
    try:
        yield
    finally:
        _STAND_INS.pop()


def closest_rig(surface: Mesh, kind: str, library: RigLibrary | None = None,
                limit: float = LIBRARY_DISTANCE) -> ClosestRig | None:
    """The entry of ``kind`` with key joints whose surface is nearest
    ``surface`` (normalised frame) when at most ``limit`` away, else None
    (:func:`_nearest_entry`)."""
    library = shipped_library() if library is None else library
    if library is None:
        return None
    # One draw of the surface's points serves the search and the fit (the same seed gives the same points).
    drawn = surface_points(surface.vertices, surface.triangles, SURFACE_POINTS)
    found = _nearest_entry(drawn, library, np.flatnonzero((library.kinds == kind) & library.known.any(axis=1)),
                           limit)
    if found is None:
        return None
    best, distance = found
    axis_map = entry_map(library, best, surface, drawn)
    mapped = axis_map(library.key_joints[best])
    points = {name: mapped[index] for index, name in enumerate(KEY_JOINTS) if library.known[best, index]}
    return ClosestRig(str(library.names[best]), distance, points, axis_map)


def entry_map(library: RigLibrary, entry: int, surface: Mesh, drawn: np.ndarray | None = None) -> AxisMap:
    """The per-axis map taking entry ``entry``'s body onto ``surface``
    (normalised frame): its bounding box onto the surface's, refined on the
    two surfaces (:func:`.surface_fit.fitted_axis_map`). ``drawn``: the
    surface's :data:`SURFACE_POINTS` points when the caller has drawn them."""
    if drawn is None:
        drawn = surface_points(surface.vertices, surface.triangles, SURFACE_POINTS)
    return fitted_axis_map(library.points[entry], library.boxes[entry], drawn, bounding_box(surface.vertices))


def fitted_rig(name: str, distance: float, surface: Mesh, library: RigLibrary | None = None,
               axis_map: AxisMap | None = None) -> KnownRig | None:
    """The rig of the entry ``name`` (found ``distance`` from ``surface``,
    normalised frame) mapped onto it as its key joints are
    (:func:`closest_rig`, :func:`entry_map`; ``axis_map``: that map when the
    caller has it already, :attr:`ClosestRig.axis_map`); None when
    that is farther than :data:`LIBRARY_DISTANCE` or the entry keeps no rig."""
    library = shipped_library() if library is None else library
    if library is None or distance > LIBRARY_DISTANCE:
        return None
    found = np.flatnonzero(library.names == name)
    if not len(found) or not library.rig_counts[found[0]]:
        return None
    entry = int(found[0])
    rows = library.rig_rows(entry)
    fitted = entry_map(library, entry, surface) if axis_map is None else axis_map
    joints, tails = fitted(library.rig_joints[rows]), fitted(library.rig_tails[rows])
    skeleton = Skeleton(joints, library.rig_parents[rows].copy(), tuple(str(bone) for bone in library.rig_names[rows]),
                        tails, library.rig_deform[rows].copy())
    return KnownRig(name, str(library.kinds[entry]), distance, skeleton)


def nearest_known_body(surface: Mesh, library: RigLibrary | None = None,
                       limit: float = RELATIVE_KIND_DISTANCE) -> KnownRelative | None:
    """The entry of any kind whose surface is nearest ``surface`` (normalised
    frame) when at most ``limit`` away, else None."""
    library = shipped_library() if library is None else library
    if library is None:
        return None
    found = _nearest_entry(surface_points(surface.vertices, surface.triangles, SURFACE_POINTS), library,
                           np.arange(len(library.names)), limit)
    if found is None:
        return None
    best, distance = found
    return KnownRelative(str(library.names[best]), str(library.kinds[best]), distance)


def _nearest_entry(target: np.ndarray, library: RigLibrary, entries: np.ndarray, limit: float) -> tuple | None:
    """(index, distance) of the entry among ``entries`` whose surface is
    nearest the surface drawn as ``target`` (its :data:`SURFACE_POINTS`
    points) when at most ``limit`` away, else None.

    Measuring every entry in full would take about a second (162 bipeds;
    twice that over all 324 entries).
    Each entry is first measured one way on :data:`SCREEN_POINTS` of its
    points; then, in that order, at most :data:`MEASURED_IN_FULL` are
    measured in full, and none whose screened half-distance exceeds
    :data:`SCREEN_MARGIN` times the best so far or the limit (an entry's
    Chamfer distance is at least half its one-way distance).
    """
    if not len(entries):
        return None
    target_tree = cKDTree(target)
    screened = target_tree.query(library.points[entries, :SCREEN_POINTS].reshape(-1, 3))[0]
    estimates = screened.reshape(len(entries), -1).mean(axis=1)
    best, best_distance = None, np.inf
    for rank in np.argsort(estimates, kind="stable")[:MEASURED_IN_FULL]:
        if 0.5 * estimates[rank] > SCREEN_MARGIN * min(best_distance, limit):
            break
        distance = symmetric_chamfer(target, library.points[entries[rank]], target_tree)
        if distance < best_distance:
            best, best_distance = entries[rank], distance
    if best is None or best_distance > limit:
        return None
    return int(best), float(best_distance)


#: Largest distance (share of the largest side) from a key joint's mirror
#: image to its twin in an entry: the key-joint tolerance. A midline key
#: joint is its own twin, so one more than half this off the midline also
#: leaves the entry out.
MAX_TWIN_MIRROR_ERROR = 0.05


def twin_mirror_error(key_joints: np.ndarray, known: np.ndarray) -> float:
    """The largest distance from a known key joint's mirror image (across
    x = 0) to its known twin; 0 when no pair is known."""
    twins = np.array(KEY_JOINT_TWINS)
    both = known & known[twins]
    if not both.any():
        return 0.0
    return float(np.linalg.norm(mirror_points(key_joints)[both] - key_joints[twins][both], axis=1).max())


def build_rig_library(samples: list) -> RigLibrary:
    """The library of ``samples`` (normalised CharacterSamples), by name:
    every one, with its kind (the split's category,
    :data:`.networks.landmarks.CATEGORY_KINDS`: biped, quadruped, or other
    for the rest). Key joints are kept for those of a kind of
    :data:`.networks.landmarks.STANDARD_KINDS` whose bone names give one
    (:func:`.networks.landmarks.sample_landmarks`, the landmark network's own
    targets) and whose twin key joints are mirror images
    (:data:`MAX_TWIN_MIRROR_ERROR`): Nexuiz's and some SuperTuxKart
    characters rest in a pose, and one 0 A.D. elephant's left legs are
    rigged elsewhere than its body's, while a standard skeleton is built
    symmetric."""
    names, kinds, points, key_joints, known, boxes, rigs = [], [], [], [], [], [], []
    for sample in sorted(samples, key=lambda sample: sample.name):
        targets, known_joints, kind = sample_landmarks(sample)
        copied = (BODY_KINDS[kind] in STANDARD_KINDS and known_joints.any()
                  and twin_mirror_error(targets, known_joints > 0) <= MAX_TWIN_MIRROR_ERROR)
        names.append(sample.name)
        kinds.append(BODY_KINDS[kind])
        points.append(library_points(sample.vertices, sample.triangles))
        key_joints.append(targets if copied else np.zeros_like(targets))
        known.append(known_joints > 0 if copied else np.zeros(len(known_joints), dtype=bool))
        boxes.append([sample.vertices.min(axis=0), sample.vertices.max(axis=0)])
        rigs.append(_one_tree_rig(sample.skeleton))
    kept = [rig for rig in rigs if rig is not None]
    return RigLibrary(np.array(names), np.array(kinds), np.array(points, dtype=np.float32),
                      np.array(key_joints, dtype=np.float32), np.array(known, dtype=bool),
                      np.array(boxes, dtype=np.float32),
                      np.array([len(rig.names) if rig is not None else 0 for rig in rigs], dtype=np.int64),
                      np.concatenate([rig.joints for rig in kept] or [np.zeros((0, 3))]).astype(np.float32),
                      np.concatenate([rig.tails for rig in kept] or [np.zeros((0, 3))]).astype(np.float32),
                      np.concatenate([rig.parents for rig in kept] or [np.zeros(0)]).astype(np.int64),
                      np.array([name for rig in kept for name in rig.names], dtype=str),
                      np.concatenate([rig.deform for rig in kept] or [np.zeros(0)]).astype(bool))


def _one_tree_rig(skeleton: Skeleton) -> Skeleton | None:
    """An artist's rig as one tree (a rig handed to an animator must be one),
    parents first: its deform bones and, when they hang from bones that
    deform nothing (Quaternius' modular men from a ``Root``), the chains
    joining them, which stay non-deforming. Trees that nothing joins
    (YellowDragon's head, IK bones an artist weighted) hang from the nearest
    joint of the largest tree. None when no bone deforms."""
    parents = np.asarray(skeleton.parents, dtype=np.int64)
    deform = np.asarray(skeleton.deform, dtype=bool)
    if not deform.any():
        return None
    tops = [int(joint) for joint in np.flatnonzero(deform) if not deform[ancestors(parents, int(joint))].any()]
    keep = deform.copy()
    paths = [[top, *ancestors(parents, top)] for top in tops]
    for root in {path[-1] for path in paths}:  # the tops under one root of the artist's tree are joined there
        joined = [path for path in paths if path[-1] == root]
        if len(joined) < 2:
            continue
        shared = set(joined[0]).intersection(*map(set, joined[1:]))
        meeting = next(joint for joint in joined[0] if joint in shared)  # the lowest joint above each of them
        for path in joined:
            keep[path[: path.index(meeting) + 1]] = True
    rows = np.flatnonzero(keep)
    joints = skeleton.joints[rows]
    kept_parents = _joined_trees(subset_parents(parents, keep), joints)
    order = parents_first_order(kept_parents)
    return Skeleton(joints[order], reindexed_parents(kept_parents, order),
                    tuple(skeleton.names[rows[index]] for index in order), skeleton.tails[rows][order],
                    deform[rows][order])


def _joined_trees(parents: np.ndarray, joints: np.ndarray) -> np.ndarray:
    """``parents`` with every tree but the largest hung, by its root, from
    the nearest joint of the trees already joined, largest first."""
    parents = parents.copy()
    roots = np.flatnonzero(parents < 0)
    if len(roots) < 2:
        return parents
    tree = np.array([([joint, *ancestors(parents, joint)])[-1] for joint in range(len(parents))])
    roots = sorted(roots.tolist(), key=lambda root: -int(np.sum(tree == root)))
    joined = tree == roots[0]
    for root in roots[1:]:
        candidates = np.flatnonzero(joined)
        parents[root] = candidates[np.argmin(np.linalg.norm(joints[candidates] - joints[root], axis=1))]
        joined |= tree == root
    return parents
