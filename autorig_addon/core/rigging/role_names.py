"""Bone names by role for a predicted skeleton.

A predicted skeleton has joints, parents and mirror twins but no names.
:func:`role_names` gives every joint the name of the bone that starts there:

* When the skeleton is recognisably a **biped** or a **quadruped**
  (:func:`classify_body`), bones are named by role with the names of Rigify's
  metarigs (Blender's ``addons_core/rigify/metarigs``: ``Basic/basic_human.py``,
  ``Basic/basic_quadruped.py`` and ``Animals/wolf.py``, which agree on the
  limbs):

  - biped: the midline from the hips up is ``spine``, ``spine.001``, ... up
    to the joint the arms hang from, then ``neck``, ``neck.001``, ... and the
    top joint ``head``; arms ``shoulder`` (when the chain starts near the
    midline, a clavicle), ``upper_arm``, ``forearm``, ``hand``; fingers
    ``thumb.01``, ``f_index.01``, ``f_middle.01``, ``f_ring.01``,
    ``f_pinky.01`` (numbered ``.02``, ``.03`` along each finger) when the
    hand has five, ``finger_1.01``, ... otherwise; legs ``thigh``, ``shin``,
    ``foot``, ``toe``.
  - quadruped: hind legs ``thigh``, ``shin``, ``foot``, ``toe``; front legs
    ``shoulder`` (when the chain has five joints or more), ``front_thigh``,
    ``front_shin``, ``front_foot``, ``front_toe`` (Rigify's basic quadruped
    and wolf; its horse and cat use other words); the midline from the hips
    to the front legs ``spine``, ``spine.001``, ...; then ``neck``, ...,
    ``head``.

  Rigify's human metarig numbers neck and head on as ``spine.004`` to
  ``spine.006`` and its quadruped the tail as ``spine`` to ``spine.003``;
  we name them ``neck``, ``head`` and ``tail`` as its bird, horse and cat
  metarigs do, which reads better in the outliner.

* Everything else gets structural names: the root ``root``, the midline chain
  that continues it ``spine``, a midline chain running backward (+Y)
  ``tail``, other midline chains ``chain``, mirrored branches ``leg`` when
  they reach the ground and ``limb`` otherwise. Chains are numbered along
  (``limb.L``, ``limb.001.L``); a second chain of the same kind takes
  ``limb_2.L``, ``limb_2.001.L``.

A role chain with more joints than roles continues the role numbered
(``toe.001.L`` after ``toe.L``; extra arm joints before a branching hand are
``forearm.001.L``); one with fewer drops the last roles. Mirror twins get the
same base name, ``.L`` on the one at +X and ``.R`` on the other
(:mod:`autorig_addon.core.skeleton.naming`); midline and unpaired joints get
no suffix. Names are unique whatever the input.

The joints are expected in the normalised frame (:mod:`autorig_addon.core.
dataset.normalise`): Blender's +Z up, the character facing -Y, its left side
at +X. Thresholds are shares of the joints' own extent, so the scale and the
position do not matter, the orientation does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..skeleton.naming import LEFT_SUFFIX, chain_names, mirror_name

#: Kinds of body :func:`classify_body` recognises.
BIPED, QUADRUPED, OTHER = "biped", "quadruped", "other"

#: A mirrored limb reaches the ground when its lowest joint lies at most this
#: share of the skeleton's height (its joints' vertical extent) above the
#: ground (the lowest mirrored joint). The toes of Rigify's human and
#: quadruped sit within 5 % of it, the hands of its A-posed human at 65 %.
GROUND_SHARE = 0.15
#: A biped's head rises above its hips by at least this share of the
#: skeleton's height.
BIPED_MIN_RISE_SHARE = 0.2
#: A biped's trunk is upright: from hips to head it rises at least this many
#: times as far as it runs front to back (ratio of lengths).
BIPED_UPRIGHT_RATIO = 1.0
#: A quadruped's front and hind legs start at least this share of the
#: skeleton's largest side apart along the body (y).
QUADRUPED_MIN_LEG_SPACING = 0.1
#: A quadruped's trunk is level: between the hips and the chest it runs at
#: least this many times as far front to back as it rises or falls (ratio of
#: lengths).
QUADRUPED_LEVEL_RATIO = 1.0
#: An arm chain starts with a shoulder (clavicle) bone when its first joint
#: lies closer to the midline than this share of the chain's sideways reach.
#: Rigify's human puts it at 3 % and the upper arm at 27 %.
CLAVICLE_LATERAL_SHARE = 0.2
#: A biped's arms may hang from a midline side branch off the trunk of at
#: most this many joints (the predictor finds such short branches at the
#: shoulders); counted in joints.
ARM_BRANCH_JOINTS = 2
#: Joints an arm has before its hand (upper arm and forearm): a chain
#: branching earlier is not branching at the hand.
JOINTS_BEFORE_HAND = 2
#: A midline chain is a tail when it runs backward (+Y) more than this many
#: times as far as it runs up, down or sideways (ratio of lengths).
TAIL_BACKWARD_RATIO = 1.0

#: Role names along each limb, root first (Rigify's metarigs).
ARM_ROLES = ("upper_arm", "forearm", "hand")
SHOULDER_ROLE = "shoulder"
LEG_ROLES = ("thigh", "shin", "foot", "toe")
FRONT_LEG_ROLES = ("shoulder", "front_thigh", "front_shin", "front_foot", "front_toe")
#: Rigify's five fingers, thumb first, then front (-Y) to back.
FINGER_ROLES = ("thumb", "f_index", "f_middle", "f_ring", "f_pinky")
#: Base of generic finger chains (``finger_1.01``) when a hand has not five.
GENERIC_FINGER = "finger"
SPINE, NECK, HEAD, ROOT, TAIL = "spine", "neck", "head", "root", "tail"
#: Structural names of chains outside any role.
MIDLINE_CHAIN, LIMB, LEG = "chain", "limb", "leg"

_LEFT, _RIGHT, _MIDLINE = 1, -1, 0


def role_names(joints, parents, mirror) -> tuple:
    """Unique bone names for a predicted skeleton, by role where recognised.

    Parameters
    ----------
    joints : (j, 3) float array
        Joint positions in the normalised frame (+Z up, facing -Y, left at
        +X); joint ``k`` is the head of bone ``k``.
    parents : (j,) int array
        Parent index per joint, parents first (``parents[k] < k``), -1 for
        the one root (joint 0).
    mirror : (j,) int array
        Index of each joint's mirror twin across the character's plane, -1
        for a joint on the midline or without a twin; twins come in pairs
        (``mirror[mirror[k]] == k``).

    Returns
    -------
    tuple of j str
        Unique names; twins share a base name with ``.L`` (the one at +X)
        and ``.R``.

    Raises
    ------
    InputError
        When the arrays are malformed (shapes, non-finite positions, parents
        not first or not one root, twins not in pairs).

    Examples
    --------
    >>> role_names([[0, 0, 0.5], [0.1, 0, 0.5], [-0.1, 0, 0.5]], [-1, 0, 0], [-1, 2, 1])
    ('root', 'limb.L', 'limb.R')
    """
    frame = _Frame.of(joints, parents, mirror)
    names: list = [None] * frame.count
    taken: set = set()
    kind, roles = _recognised_roles(frame)
    for joint, base in roles.items():
        name = base + (LEFT_SUFFIX if frame.side[joint] == _LEFT else "")
        names[joint] = name
        taken.add(name)
    trunk = None if kind == OTHER else {j for j, base in roles.items() if base == ROOT or base.split(".")[0] == SPINE}
    _name_the_rest(frame, trunk, names, taken)
    for joint in np.flatnonzero(frame.side == _RIGHT):
        names[joint] = mirror_name(names[frame.mirror[joint]])
    return tuple(names)


def classify_body(joints, parents, mirror) -> str:
    """Whether a skeleton is recognisably a biped, a quadruped or neither.

    A leg is a mirrored limb that starts above the ground and reaches it
    (:data:`GROUND_SHARE`). A biped has one pair of legs hanging from a
    midline joint (the hips, or a root on the floor), a midline path from the
    hips rising upright to the top (spine, neck, head; it may run up through a
    root above the hips) and a mirrored pair of limbs hanging from that path
    above the hips, or from a short midline branch off it (the arms; they may
    reach the ground too). A quadruped has exactly two pairs of legs hanging
    from midline joints set apart along a level body (where they hang from or
    where they start); the pair further toward -Y is the front legs. Short
    extra branches elsewhere do not matter: predicted skeletons have them.

    Parameters
    ----------
    joints, parents, mirror
        As :func:`role_names` takes them.

    Returns
    -------
    str
        :data:`BIPED`, :data:`QUADRUPED` or :data:`OTHER`.
    """
    return _recognised_roles(_Frame.of(joints, parents, mirror))[0]


@dataclass
class _Frame:
    """A checked skeleton and what the naming steps ask of it."""

    joints: np.ndarray      # (j, 3) float64
    parents: np.ndarray     # (j,) int64, -1 for the root
    mirror: np.ndarray      # (j,) int64, -1 for none
    side: np.ndarray        # (j,) int64: _LEFT, _RIGHT or _MIDLINE (midline or unpaired)
    children: list          # children[k]: joints whose parent is k
    step: np.ndarray        # (j,) distance from each joint to its parent, 0 for the root
    reach: np.ndarray       # (j,) longest path below each joint through joints of its own side
    floor: float            # height of the ground: the lowest mirrored joint (a root bone may lie lower)
    height: float           # vertical extent of the joints
    size: float             # largest side of the joints' bounding box
    midline_x: float        # x of the mirror plane

    @property
    def count(self) -> int:
        return len(self.parents)

    @classmethod
    def of(cls, joints, parents, mirror) -> "_Frame":
        joints, parents, mirror = _checked(joints, parents, mirror)
        count = len(parents)
        twin_x = joints[np.maximum(mirror, 0), 0]
        paired = mirror >= 0
        left = paired & ((joints[:, 0] > twin_x) | ((joints[:, 0] == twin_x) & (np.arange(count) < mirror)))
        side = np.where(paired, np.where(left, _LEFT, _RIGHT), _MIDLINE)
        children: list = [[] for _ in range(count)]
        for child in range(1, count):
            children[parents[child]].append(child)
        step = np.zeros(count)
        step[1:] = np.linalg.norm(joints[1:] - joints[parents[1:]], axis=1)
        reach = np.zeros(count)
        for child in range(count - 1, 0, -1):
            joint = parents[child]
            if side[child] == side[joint]:
                reach[joint] = max(reach[joint], step[child] + reach[child])
        low, high = joints.min(axis=0), joints.max(axis=0)
        floor = float(joints[paired, 2].min()) if paired.any() else float(low[2])
        midline_x = (float(np.median((joints[paired, 0] + twin_x[paired]) / 2.0)) if paired.any()
                     else float(joints[0, 0]))
        return cls(joints, parents, mirror, side, children, step, reach, floor, float(high[2] - low[2]),
                   float((high - low).max()), midline_x)

    def main_path(self, start: int, allowed=None) -> list:
        """Joints from ``start`` down the longest way through joints of
        ``start``'s side (and in ``allowed``, a (j,) bool mask, if given)."""
        path = [start]
        while True:
            here = path[-1]
            options = [c for c in self.children[here]
                       if self.side[c] == self.side[start] and (allowed is None or allowed[c])]
            if not options:
                return path
            path.append(options[int(np.argmax([self.step[c] + self.reach[c] for c in options]))])

    def on_ground(self, joint_indices) -> bool:
        """Whether the lowest of the joints reaches the ground (:data:`GROUND_SHARE`);
        never on a flat skeleton, which has no up and down."""
        return bool(self.height > 0 and self.joints[joint_indices, 2].min() <= self.floor + GROUND_SHARE * self.height)

    def stands_on(self, joint_indices) -> bool:
        """Whether a branch, its first joint first, reaches the ground from
        above it: a leg. Bones lying on the ground (a glTF rig's foot
        controls hanging from a root on the floor) do not."""
        return not self.on_ground(joint_indices[:1]) and self.on_ground(joint_indices)

    def midline_below(self, start: int) -> list:
        """``start`` and the midline joints reached from it through midline joints."""
        found, stack = [], [start]
        while stack:
            joint = stack.pop()
            found.append(joint)
            stack.extend(c for c in self.children[joint] if self.side[c] == _MIDLINE)
        return found

    def path_between(self, start: int, end: int) -> list:
        """Joints on the tree path from ``start`` to ``end``, both included."""
        up_from_start = self.ancestors(start)
        up_from_end = self.ancestors(end)
        shared = set(up_from_end)
        common = next(a for a in up_from_start if a in shared)
        down = up_from_end[:up_from_end.index(common)]
        return up_from_start[:up_from_start.index(common) + 1] + down[::-1]

    def ancestors(self, joint: int) -> list:
        """``joint``, its parent, ... up to the root."""
        chain = [joint]
        while self.parents[chain[-1]] >= 0:
            chain.append(int(self.parents[chain[-1]]))
        return chain


@dataclass
class _Limb:
    """A mirrored branch on the left: the left joint whose parent is not on
    the left, and the longest way down it."""

    root: int
    attach: int  # the parent (on the midline for a body limb), -1 for none
    path: list
    grounded: bool  # starts above the ground and reaches it: a leg
    length: float


def _limbs(frame: _Frame) -> list:
    limbs = []
    for joint in np.flatnonzero(frame.side == _LEFT):
        parent = int(frame.parents[joint])
        if parent >= 0 and frame.side[parent] == _LEFT:
            continue
        members, stack = [], [int(joint)]
        while stack:
            here = stack.pop()
            members.append(here)
            stack.extend(c for c in frame.children[here] if frame.side[c] == _LEFT)
        limbs.append(_Limb(int(joint), parent, frame.main_path(int(joint)), frame.stands_on(members),
                           float(frame.reach[joint])))
    return limbs


def _recognised_roles(frame: _Frame):
    """(kind, {joint: base name}) for the recognised body, or (OTHER, {})."""
    limbs = _limbs(frame)
    grounded = [limb for limb in limbs if limb.grounded]
    roles = _quadruped_roles(frame, grounded)
    if roles is not None:
        return QUADRUPED, roles
    roles = _biped_roles(frame, limbs, grounded)
    if roles is not None:
        return BIPED, roles
    return OTHER, {}


def _on_midline(frame: _Frame, joint: int) -> bool:
    return joint >= 0 and frame.side[joint] == _MIDLINE


def _spine_with_ancestors(frame: _Frame, path: list, roles: dict) -> list:
    """``path`` (starting at the hips) preceded by the midline joints above
    it in the tree; a root lying on the ground (the legs may hang from it)
    becomes ``root``."""
    above = []
    for joint in frame.ancestors(path[0])[1:]:
        if frame.side[joint] != _MIDLINE or joint in path:
            break
        above.append(joint)
    trunk = above[::-1] + path
    if len(trunk) > 1 and frame.parents[trunk[0]] < 0 and frame.on_ground(trunk[:1]):
        roles[trunk[0]] = ROOT
        trunk = trunk[1:]
    return trunk


def _assign(roles: dict, joints, bases) -> None:
    for joint, base in zip(joints, bases):
        roles[int(joint)] = base


def _head_and_neck(roles: dict, joints: list) -> None:
    """Name the joints after the trunk: the last ``head``, those before it ``neck``..."""
    if joints:
        _assign(roles, joints[:-1], chain_names(NECK, len(joints) - 1) if len(joints) > 1 else [])
        roles[joints[-1]] = HEAD


def _biped_roles(frame: _Frame, limbs: list, grounded: list):
    if len(grounded) not in (1, 2):
        return None
    leg = min(grounded, key=lambda limb: frame.joints[limb.attach, 2] if limb.attach >= 0 else np.inf)
    hips = leg.attach
    if not _on_midline(frame, hips):
        return None
    # The whole midline part holding the hips: a predicted root may lie above them.
    trunk = frame.midline_below(_midline_top(frame, hips))
    path = frame.path_between(hips, _head_top(frame, trunk))
    top = path[-1]
    # From where the legs start, when the predictor hangs them from a joint above that.
    rise = frame.joints[top, 2] - min(frame.joints[hips, 2], frame.joints[leg.root, 2])
    # Front-to-back travel along the whole way, not end to end: the way may
    # go forward along a level body and up a fin.
    run = np.abs(np.diff(frame.joints[path, 1])).sum()
    if rise < BIPED_MIN_RISE_SHARE * frame.height or rise < BIPED_UPRIGHT_RATIO * run:
        return None
    on_path = {joint: position for position, joint in enumerate(path)}
    arms = [(limb, _path_position(frame, limb, on_path)) for limb in limbs if limb is not leg]
    # Arms hanging from the hips joint itself (a predicted root there) start well above the legs.
    arms = [(limb, position) for limb, position in arms if position is not None and (
        position > 0 or frame.joints[limb.root, 2] - frame.joints[leg.root, 2] >= BIPED_MIN_RISE_SHARE * frame.height)]
    if not arms:
        return None
    arm, shoulders = max(arms, key=lambda item: (item[0].length, -item[0].root))
    roles: dict = {}
    spine = _spine_with_ancestors(frame, path[:shoulders + 1], roles)
    _assign(roles, spine, chain_names(SPINE, len(spine)))
    _head_and_neck(roles, path[shoulders + 1:])
    _assign(roles, leg.path, _numbered_roles(LEG_ROLES, len(leg.path)))
    _arm_roles(frame, arm, roles)
    return roles


def _midline_top(frame: _Frame, joint: int) -> int:
    """The highest ancestor in the tree reached from ``joint`` through midline joints."""
    for above in frame.ancestors(joint)[1:]:
        if frame.side[above] != _MIDLINE:
            break
        joint = above
    return joint


def _path_position(frame: _Frame, limb: _Limb, on_path: dict):
    """Index in a biped's trunk path of the joint an arm hangs from: its
    attachment, or the nearest trunk joint above it when it hangs from a short
    midline side branch (:data:`ARM_BRANCH_JOINTS` joints at most) off the
    trunk above the hips; None for neither."""
    if not _on_midline(frame, limb.attach):
        return None
    for steps, joint in enumerate(frame.ancestors(limb.attach)[:ARM_BRANCH_JOINTS + 1]):
        if frame.side[joint] != _MIDLINE:
            return None
        if joint in on_path:
            # A branch off the hips themselves is no shoulder (a fish's eyes
            # on its head, its fins at its middle).
            return on_path[joint] if steps == 0 or on_path[joint] > 0 else None
    return None


def _head_top(frame: _Frame, trunk: list) -> int:
    """The top of a biped's trunk: its highest midline joint, or the joint
    below it when that one starts a chain hanging backward and down with no
    limbs on it (hair, a ponytail; a jaw hangs forward and stays below the
    head)."""
    top = max(trunk, key=lambda joint: (frame.joints[joint, 2], -joint))
    hanging = frame.main_path(top)
    run = frame.joints[hanging[-1]] - frame.joints[top]
    # Hair carries no mirrored limbs; a short branch the arms hang from is no hair.
    carries_limbs = any(frame.side[c] != _MIDLINE for joint in hanging for c in frame.children[joint])
    if len(hanging) > 1 and run[1] > 0 and run[2] < 0 and top != trunk[0] and not carries_limbs:
        return int(frame.parents[top])
    return top


def _quadruped_roles(frame: _Frame, grounded: list):
    if len(grounded) != 2 or not all(_on_midline(frame, limb.attach) for limb in grounded):
        return None
    front, hind = sorted(grounded,
                         key=lambda limb: (frame.joints[limb.attach, 1], frame.joints[limb.root, 1], limb.root))
    # The predictor may hang a pair of legs from a midline joint off the
    # trunk, short of where the legs start: legs set apart at either end count.
    along = max(frame.joints[hind.attach, 1] - frame.joints[front.attach, 1],
                frame.joints[hind.root, 1] - frame.joints[front.root, 1])
    rise = abs(frame.joints[front.attach, 2] - frame.joints[hind.attach, 2])
    if along < QUADRUPED_MIN_LEG_SPACING * frame.size or along < QUADRUPED_LEVEL_RATIO * rise:
        return None
    path = frame.path_between(hind.attach, front.attach)
    if any(frame.side[joint] != _MIDLINE for joint in path):
        return None
    roles: dict = {}
    # Joints above the hips in the tree belong to the trunk when the tree runs hips to chest.
    runs_forward = hind.attach in frame.ancestors(front.attach)
    spine = _spine_with_ancestors(frame, path, roles) if runs_forward else path
    _assign(roles, spine, chain_names(SPINE, len(spine)))
    ahead = [joint for joint in frame.midline_below(front.attach) if joint not in roles]
    if ahead:
        head = min(ahead, key=lambda joint: (frame.joints[joint, 1], joint))
        if frame.joints[head, 1] < frame.joints[front.attach, 1]:
            _head_and_neck(roles, frame.path_between(front.attach, head)[1:])
    _assign(roles, hind.path, _numbered_roles(LEG_ROLES, len(hind.path)))
    front_roles = FRONT_LEG_ROLES if len(front.path) >= len(FRONT_LEG_ROLES) else FRONT_LEG_ROLES[1:]
    _assign(roles, front.path, _numbered_roles(front_roles, len(front.path)))
    return roles


def _numbered_roles(roles, count: int, repeated: int = -1) -> list:
    """Base names of ``count`` joints named by ``roles`` in order: the first
    roles when there are fewer joints, the role at index ``repeated``
    continued (``forearm``, ``forearm.001``) when there are more."""
    if count <= len(roles):
        return list(roles[:count])
    repeated %= len(roles)
    extra = count - len(roles)
    return (list(roles[:repeated]) + chain_names(roles[repeated], extra + 1) + list(roles[repeated + 1:]))


def _arm_roles(frame: _Frame, arm: _Limb, roles: dict) -> None:
    """Shoulder, upper arm, forearm and hand along the arm; the hand's
    branches are fingers."""
    path = arm.path
    lateral = np.abs(frame.joints[path, 0] - frame.midline_x)
    with_shoulder = len(path) > 1 and lateral[0] < CLAVICLE_LATERAL_SHARE * lateral.max()
    start = 1 if with_shoulder else 0
    if with_shoulder:
        roles[path[0]] = SHOULDER_ROLE
    hand = next((k for k in range(start + JOINTS_BEFORE_HAND, len(path)) if _left_children(frame, path[k]) >= 2), None)
    if hand is None:
        _assign(roles, path[start:], _numbered_roles(ARM_ROLES, len(path) - start))
        return
    before = _numbered_roles(ARM_ROLES[:-1], hand - start)
    _assign(roles, path[start:hand], before)
    roles[path[hand]] = ARM_ROLES[-1]
    _finger_roles(frame, path[hand], roles)


def _left_children(frame: _Frame, joint: int) -> int:
    return sum(1 for c in frame.children[joint] if frame.side[c] == _LEFT)


def _finger_roles(frame: _Frame, hand: int, roles: dict) -> None:
    """Each branch of the hand is a finger chain: Rigify's five (the thumb
    starts closest to the wrist, the others front to back) or numbered."""
    starts = [c for c in frame.children[hand] if frame.side[c] == _LEFT]
    distances = [frame.step[c] for c in starts]
    if len(starts) == len(FINGER_ROLES):
        thumb = starts[int(np.argmin(distances))]
        others = sorted((c for c in starts if c != thumb), key=lambda c: (frame.joints[c, 1], c))
        ordered, bases = [thumb] + others, list(FINGER_ROLES)
    else:
        ordered = sorted(starts, key=lambda c: (frame.joints[c, 1], c))
        bases = [f"{GENERIC_FINGER}_{k + 1}" for k in range(len(starts))]
    for start, base in zip(ordered, bases):
        finger = frame.main_path(start)
        _assign(roles, finger, [f"{base}.{k + 1:02d}" for k in range(len(finger))])


def _name_the_rest(frame: _Frame, trunk, names: list, taken: set) -> None:
    """Structural names for the joints no role took: chains down the
    longest way, named by where they start and run. ``trunk`` holds the
    joints a tail may hang from (a recognised body's spine and root), None
    for a body not recognised (any joint; the root's main continuation is
    then the ``spine``)."""
    unnamed = np.array([name is None for name in names])
    spine_start = _spine_start(frame, 0, unnamed) if trunk is None else -1
    for joint in range(frame.count):
        if not unnamed[joint] or frame.side[joint] == _RIGHT:
            continue
        parent = int(frame.parents[joint])
        if parent < 0:
            chain, base = [joint], ROOT
        else:
            chain = frame.main_path(joint, unnamed)
            base = _structural_base(frame, chain, trunk, spine_start)
        suffix = LEFT_SUFFIX if frame.side[joint] == _LEFT else ""
        for member, name in zip(chain, _free_chain(base, len(chain), suffix, taken)):
            names[member] = name
            unnamed[member] = False


def _structural_base(frame: _Frame, chain: list, trunk, spine_start: int) -> str:
    """``leg``, ``limb``, ``spine`` (the chain from ``spine_start``), ``tail``
    or ``chain`` for a chain outside any role."""
    parent = int(frame.parents[chain[0]])
    if frame.side[chain[0]] == _LEFT:
        from_body = frame.side[parent] != _LEFT
        return LEG if from_body and frame.stands_on(chain) else LIMB
    if chain[0] == spine_start:
        return SPINE
    if (trunk is None or parent in trunk) and _runs_backward(frame, parent, chain[-1]):
        return TAIL
    return MIDLINE_CHAIN


def _runs_backward(frame: _Frame, start: int, end: int) -> bool:
    """Whether going from joint ``start`` to ``end`` runs mainly backward (+Y)."""
    run = frame.joints[end] - frame.joints[start]
    return bool(run[1] > 0 and run[1] > TAIL_BACKWARD_RATIO * max(abs(run[0]), abs(run[2])))


def _spine_start(frame: _Frame, root: int, unnamed: np.ndarray) -> int:
    """The root's midline child that starts the longest chain not running
    backward (or the longest chain, when all do), -1 for none."""
    options = [c for c in frame.children[root] if frame.side[c] == _MIDLINE and unnamed[c]]
    if not options:
        return -1
    lengths = [frame.step[c] + frame.reach[c] for c in options]
    forward = [not _runs_backward(frame, root, frame.main_path(c, unnamed)[-1]) for c in options]
    best = max(range(len(options)), key=lambda k: (forward[k] or not any(forward), lengths[k], -options[k]))
    return options[best]


def _free_chain(base: str, count: int, suffix: str, taken: set) -> list:
    """``chain_names`` of the first of ``base``, ``base_2``, ``base_3``, ...
    whose names are all free; marks them taken."""
    number = 1
    while True:
        names = chain_names(base if number == 1 else f"{base}_{number}", count, suffix)
        if not taken.intersection(names):
            taken.update(names)
            return names
        number += 1


def _checked(joints, parents, mirror):
    """The three arrays as float64 / int64, or InputError saying what is wrong."""
    joints = np.asarray(joints, dtype=np.float64) if _numeric(joints) else None
    if joints is None or joints.ndim != 2 or joints.shape[1] != 3 or len(joints) == 0:
        raise InputError("The joints must be a non-empty (j, 3) array of positions.")
    if not np.all(np.isfinite(joints)):
        raise InputError("The joint positions must be finite numbers.")
    count = len(joints)
    parents = _index_array(parents, count, "parents")
    mirror = _index_array(mirror, count, "mirror")
    if parents[0] != -1 or np.any(parents[1:] < 0):
        raise InputError("The skeleton must have exactly one root, joint 0 (parent -1).")
    if np.any(parents[1:] >= np.arange(1, count)):
        raise InputError("Parents must come before their children (parents[k] < k).")
    twins = np.flatnonzero(mirror >= 0)
    if np.any(mirror[twins] == twins) or np.any(mirror[mirror[twins]] != twins):
        raise InputError("Mirror twins must come in pairs of different joints (mirror[mirror[k]] == k).")
    return joints, parents, mirror


def _numeric(values) -> bool:
    try:
        array = np.asarray(values)
    except (ValueError, TypeError):
        return False
    return array.dtype.kind in "biuf"


def _index_array(values, count: int, what: str) -> np.ndarray:
    array = np.asarray(values) if _numeric(values) else None
    if array is None or array.dtype.kind == "b" or array.shape != (count,):
        raise InputError(f"{what} must be a ({count},) integer array, one entry per joint.")
    if array.dtype.kind == "f" and not np.all(np.isfinite(array) & (array == np.round(array))):
        raise InputError(f"{what} must hold whole joint indices.")
    array = array.astype(np.int64)
    if np.any((array < -1) | (array >= count)):
        raise InputError(f"{what} must hold joint indices from -1 to {count - 1}.")
    return array
