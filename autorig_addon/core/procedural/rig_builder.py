"""The skeleton of a generated character while it is being built.

:class:`RigBuilder` holds bones by name (head, tail, parent, deform) and
offers the edits the character kinds need: chains, subtree rotations,
mirroring of the left side. Bones are added parents first, which is the
order of the finished :class:`~autorig_addon.core.types.Skeleton`.
"""

from __future__ import annotations

import numpy as np

from ..skeleton.naming import LEFT_SUFFIX, chain_names, mirror_name
from .frames import MIRROR_X, X, Z, normalized, rotation_matrix

#: Each bone of a grown tail is this fraction of the length of the one before.
TAIL_SHRINK = 0.88


def shrinking_lengths(count: int, total: float, ratio: float) -> np.ndarray:
    """(count,) bone lengths summing to ``total``, each ``ratio`` times the one before."""
    lengths = ratio ** np.arange(count)
    lengths *= total / lengths.sum()
    return lengths


def curling_directions(direction: np.ndarray, axis: np.ndarray, step: float, count: int) -> list:
    """``count`` unit directions: ``direction`` turned about ``axis`` by
    ``step`` radians more for each bone (0, step, 2 step...)."""
    return [rotation_matrix(axis, step * k) @ direction for k in range(count)]


class RigBuilder:
    """Bones under construction (mutable; parents added before children).

    Attributes
    ----------
    names : list of str
    heads, tails : list of (3,) float64 arrays
    parents : list of str or None
    deform : list of bool
    index : dict
        Position of each name in the lists.
    """

    def __init__(self):
        self.names: list = []
        self.heads: list = []
        self.tails: list = []
        self.parents: list = []
        self.deform: list = []
        self.index: dict = {}

    # -- adding bones -------------------------------------------------------
    def add(self, name, head, tail, parent=None, deform=True):
        """Add one bone; returns its name."""
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
        """Connected bones from ``start`` along ``directions`` (k, 3) with
        ``lengths`` (k,); returns the names."""
        position = np.asarray(start, dtype=np.float64)
        for name, direction, length in zip(names, directions, lengths):
            tail = position + length * normalized(direction)
            self.add(name, position, tail, parent)
            parent, position = name, tail
        return list(names)

    def add_path(self, names, joints, parent=None):
        """Connected bones through ``joints`` (k + 1, 3), bone ``k`` from
        joint ``k`` to joint ``k + 1``; returns the names."""
        for k, name in enumerate(names):
            self.add(name, joints[k], joints[k + 1], parent)
            parent = name
        return list(names)

    def grow_tail(self, base, parent, start, direction, length, count, bend_deg):
        """A connected chain ``base``, ``base.001``... of total ``length``
        whose bones shorten towards the tip (:data:`TAIL_SHRINK`) and bend by
        ``bend_deg`` degrees each (positive curls up)."""
        axis = np.cross(direction, Z)
        if np.linalg.norm(axis) < 1e-9:
            axis = X
        directions = curling_directions(direction, axis, np.radians(bend_deg), count)
        return self.add_chain(chain_names(base, count), start, directions,
                              shrinking_lengths(count, length, TAIL_SHRINK), parent)

    def symmetrize(self):
        """Add a ``.R`` twin, mirrored across x = 0, for every ``.L`` bone
        that has none yet."""
        for k in range(len(self.names)):
            name = self.names[k]
            twin = mirror_name(name)
            if name.endswith(LEFT_SUFFIX) and twin not in self.index:
                parent = self.parents[k]
                self.add(twin, self.heads[k] * MIRROR_X, self.tails[k] * MIRROR_X,
                         None if parent is None else mirror_name(parent), self.deform[k])

    # -- reading bones --------------------------------------------------------
    def has(self, name) -> bool:
        return name in self.index

    def head(self, name) -> np.ndarray:
        return self.heads[self.index[name]]

    def tail(self, name) -> np.ndarray:
        return self.tails[self.index[name]]

    def middle(self, name) -> np.ndarray:
        """(3,) midpoint of the bone."""
        return 0.5 * (self.head(name) + self.tail(name))

    def point_along(self, name, fraction: float) -> np.ndarray:
        """(3,) point ``fraction`` of the way from the bone's head to its tail."""
        return self.head(name) + fraction * (self.tail(name) - self.head(name))

    def direction(self, name) -> np.ndarray:
        return normalized(self.tail(name) - self.head(name))

    def length(self, name) -> float:
        return float(np.linalg.norm(self.tail(name) - self.head(name)))

    def points(self) -> np.ndarray:
        """(2 j, 3) all heads, then all tails."""
        return np.vstack([np.array(self.heads), np.array(self.tails)])

    def deforming_parent(self, name):
        """Nearest deforming ancestor of ``name`` (None for none)."""
        parent = self.parents[self.index[name]]
        while parent is not None and not self.deform[self.index[parent]]:
            parent = self.parents[self.index[parent]]
        return parent

    def subtree(self, name) -> list:
        """Indices of ``name`` and all its descendants."""
        members = {name}
        for bone, parent in zip(self.names, self.parents):
            if parent in members:
                members.add(bone)
        return [self.index[bone] for bone in self.names if bone in members]

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

    # -- moving bones ---------------------------------------------------------
    def set_tail(self, name, tail):
        self.tails[self.index[name]] = np.array(tail, dtype=np.float64)

    def place(self, name, head, tail):
        """Move bone ``name`` (and its mirrored twin, if any) to ``head``/``tail``."""
        self.heads[self.index[name]] = np.array(head, dtype=np.float64)
        self.tails[self.index[name]] = np.array(tail, dtype=np.float64)
        twin = mirror_name(name)
        if twin != name and twin in self.index:
            self.heads[self.index[twin]] = self.heads[self.index[name]] * MIRROR_X
            self.tails[self.index[twin]] = self.tails[self.index[name]] * MIRROR_X

    def transform(self, indices, function):
        """Apply ``function`` ((3,) -> (3,)) to the heads and tails of the bones at ``indices``."""
        for k in indices:
            self.heads[k] = function(self.heads[k])
            self.tails[k] = function(self.tails[k])

    def transform_all(self, function):
        self.transform(range(len(self.names)), function)

    def rotate_subtree(self, name, axis, angle, pivot=None):
        """Turn ``name`` and its descendants by ``angle`` radians about
        ``axis`` through ``pivot`` (default: the bone's head)."""
        pivot = self.head(name).copy() if pivot is None else np.asarray(pivot, dtype=np.float64)
        rotation = rotation_matrix(axis, angle)
        self.transform(self.subtree(name), lambda p: pivot + rotation @ (p - pivot))

    def raise_subtree(self, name, angle):
        """Swing ``name`` and its children up (towards +z) by ``angle``
        radians about its head; negative angles lower it."""
        axis = np.cross(self.direction(name), Z)
        if np.linalg.norm(axis) < 1e-9:
            axis = X
        self.rotate_subtree(name, axis, angle)

    def translate_subtree(self, name, offset):
        self.transform(self.subtree(name), lambda p: p + offset)
