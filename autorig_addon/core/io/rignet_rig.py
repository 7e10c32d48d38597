"""Read and write RigNet's plain-text rig files (``rig_info``).

The format (one record a line, fields separated by whitespace)::

    joints NAME X Y Z                 one line per joint, world position
    root NAME                         the single root joint
    hier PARENT CHILD                 one line per parent-child link
    skin VID NAME W [NAME W ...]      weights of vertex VID, by joint name

Mapping to :class:`~autorig_addon.core.types.Skeleton`: every RigNet joint
becomes one Skeleton joint, i.e. the head of one bone of the same name. A
RigNet leaf joint (an "end joint" with no bone of its own in RigNet's
convention) therefore becomes a short leaf bone whose tail
:class:`Skeleton` derives by default. Skin weights name the joint at the
bone's head, which is exactly the bone's column in
:class:`~autorig_addon.core.types.Weights`. Bone tails are not stored by
the format: writing keeps heads, hierarchy, names and weights, and reading
derives tails again.

Vertices whose weights are all zero get no ``skin`` line; pass
``vertex_count`` to :func:`read_rignet_rig` to restore such trailing rows.

Reading refuses, with the line at fault, what would build a broken
armature or exhaust memory: files that are not UTF-8 text (a ``.glb``
picked by mistake), joints beyond :data:`MAX_JOINT_COORDINATE` (a float32
armature cannot keep its bones' lengths there), a joint at its parent's
position (a bone with no length or direction), vertex indices no mesh can
have, and weight tables larger than the free memory.
"""

from __future__ import annotations

import math
import os
from typing import Optional, Union

import numpy as np

from ..errors import InputError
from ..memory import require_memory
from ..skeleton.checks import MIN_BONE_LENGTH_FRACTION
from ..skeleton.hierarchy import parents_first_order, reindexed_parents
from ..types import Skeleton, Weights

#: Keyword of each record type.
JOINT_KEYWORD = "joints"
ROOT_KEYWORD = "root"
HIERARCHY_KEYWORD = "hier"
SKIN_KEYWORD = "skin"

#: Field count of the fixed-length records (keyword included).
JOINT_FIELD_COUNT = 5
ROOT_FIELD_COUNT = 2
HIERARCHY_FIELD_COUNT = 3
#: A skin record has the keyword, the vertex index and at least one name-weight pair.
SKIN_MIN_FIELD_COUNT = 4
#: Largest joint coordinate accepted, scene units: Blender keeps positions in
#: float32, which beyond this spaces them more than 0.06 apart, and no
#: character is a thousand kilometres (or, in millimetres, a kilometre) tall.
MAX_JOINT_COORDINATE = 1e6
#: Largest vertex index a mesh can have: Blender counts vertices in 32-bit signed integers.
MAX_VERTEX_INDEX = 2**31 - 2
#: First bytes of a binary glTF file (``.glb``), the likeliest wrong pick in the file browser.
GLB_MAGIC = b"glTF"
#: Bytes of one weight in the dense table :func:`read_rignet_rig` builds (float64).
WEIGHT_BYTES = 8

PathOrText = Union[str, "os.PathLike[str]"]


def read_rignet_rig(path_or_text: PathOrText, vertex_count: Optional[int] = None, *,
                    for_armature: bool = True) -> tuple[Skeleton, Optional[Weights]]:
    """Parse a RigNet rig file.

    Parameters
    ----------
    path_or_text : str or os.PathLike
        A path to the file, or the file's text itself (any ``str`` holding a
        line break is taken as text).
    vertex_count : int, optional
        Number of mesh vertices. Gives the weight matrix that many rows (rows
        without a ``skin`` line are zero) and rejects larger vertex indices.
        Defaults to one more than the largest vertex index in the file.
    for_armature : bool
        The rig becomes an armature: a joint at its parent's position (a
        bone without length or direction) is refused, naming its line.
        False where only the joints are used (a predicted rig scored by
        ``eval``), which accepts such joints.

    Returns
    -------
    skeleton : Skeleton
        One joint per RigNet joint, reordered parents first (stable: a file
        already in that order keeps its order). Tails are Skeleton's defaults.
    weights : Weights or None
        ``(vertex_count, j)`` float64 matrix, one column per skeleton joint in
        skeleton order; ``None`` when the file has no ``skin`` line.

    Raises
    ------
    InputError
        A file that is not UTF-8 text, malformed lines (with their line
        number), joints beyond :data:`MAX_JOINT_COORDINATE` or at their
        parent's position (``for_armature``), unknown joint names, duplicated joints or
        vertices, a joint with two parents, a cycle in the hierarchy, not
        exactly one root, vertex indices beyond :data:`MAX_VERTEX_INDEX` or
        ``vertex_count``, or a weight table larger than the free memory.
    """
    text = _text_from_path_or_text(path_or_text)
    records = _parse_records(text)
    order, parents = _sorted_hierarchy(records)
    if for_armature:
        _check_joints_apart(records, order, parents)
    names = tuple(records.joint_names[j] for j in order)
    skeleton = Skeleton(records.joint_positions[order], parents, names)
    if not records.skin_vertices:
        return skeleton, None
    new_index = np.empty(len(order), dtype=np.int64)
    new_index[order] = np.arange(len(order))
    return skeleton, _weights_from_skin(records, new_index, names, vertex_count)


def write_rignet_rig(path: PathOrText, skeleton: Skeleton, weights: Optional[Weights] = None) -> None:
    """Write ``skeleton`` (and ``weights``) to ``path`` as a RigNet rig file.

    See :func:`rignet_rig_text` for the content and the errors raised.
    """
    text = rignet_rig_text(skeleton, weights)
    with open(path, "w", encoding="utf-8", newline="\n") as handle:
        handle.write(text)


def rignet_rig_text(skeleton: Skeleton, weights: Optional[Weights] = None) -> str:
    """The RigNet rig file text of ``skeleton`` and ``weights``.

    Parameters
    ----------
    skeleton : Skeleton
        Must have exactly one root and whitespace-free bone names.
    weights : Weights, optional
        ``(n, b)`` weights whose ``bone_names`` are all skeleton bones (any
        order, any subset). Only positive entries are written; a vertex with
        no positive weight gets no ``skin`` line.

    Returns
    -------
    str
        Lines in the order ``joints``, ``root``, ``hier``, ``skin``. Floats
        are written with ``repr`` so reading gives back the same numbers.
    """
    names = skeleton.names
    _check_writable_names(names)
    roots = np.flatnonzero(skeleton.parents < 0)
    if len(roots) != 1:
        raise InputError(
            f"A RigNet rig needs exactly one root bone, this skeleton has {len(roots)} "
            f"({', '.join(names[r] for r in roots[:5])}). Parent the extra roots to one bone first."
        )
    lines = [
        f"{JOINT_KEYWORD} {name} {_float_text(x)} {_float_text(y)} {_float_text(z)}"
        for name, (x, y, z) in zip(names, skeleton.joints.tolist())
    ]
    lines.append(f"{ROOT_KEYWORD} {names[roots[0]]}")
    lines.extend(
        f"{HIERARCHY_KEYWORD} {names[parent]} {names[child]}"
        for child, parent in enumerate(skeleton.parents.tolist())
        if parent >= 0
    )
    text = "\n".join(lines) + "\n"
    if weights is not None:
        text += _skin_text(skeleton, weights)
    return text


class _Records:
    """Raw content of a rig file, in file order, before any reordering."""

    def __init__(self) -> None:
        self.joint_names: list[str] = []
        self.joint_index: dict[str, int] = {}
        self.joint_lines: list[int] = []
        self.joint_positions = np.zeros((0, 3))
        self.roots: list[tuple[str, int]] = []
        self.links: list[tuple[str, str, int]] = []
        self.skin_vertices: list[int] = []
        self.skin_joint_names: list[list[str]] = []
        self.skin_weights: list[list[float]] = []
        self.skin_lines: list[int] = []


def _text_from_path_or_text(path_or_text: PathOrText) -> str:
    if isinstance(path_or_text, str) and ("\n" in path_or_text or "\r" in path_or_text):
        return path_or_text
    path = os.fspath(path_or_text)
    if not os.path.isfile(path):
        raise InputError(f"RigNet rig file not found: {path!r}. Check the path (or pass the file's text).")
    with open(path, "rb") as handle:
        data = handle.read()
    name = os.path.basename(path)
    if data.startswith(GLB_MAGIC):
        raise InputError(
            f"'{name}' is a binary glTF file, not a RigNet rig: import it with File > Import > glTF 2.0. "
            "A RigNet rig is a text file of 'joints', 'root', 'hier' and 'skin' lines."
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise InputError(
            f"'{name}' is not a RigNet rig: it is not text (byte {data[error.start]:#04x} at position "
            f"{error.start} is not UTF-8). A RigNet rig is a text file of 'joints', 'root', 'hier' and "
            "'skin' lines."
        ) from None


def _parse_records(text: str) -> _Records:
    records = _Records()
    positions: list[list[float]] = []
    parsers = {
        JOINT_KEYWORD: lambda fields, line: _parse_joint(fields, line, records, positions),
        ROOT_KEYWORD: lambda fields, line: _parse_root(fields, line, records),
        HIERARCHY_KEYWORD: lambda fields, line: _parse_link(fields, line, records),
        SKIN_KEYWORD: lambda fields, line: _parse_skin(fields, line, records),
    }
    for line_number, line in enumerate(text.splitlines(), start=1):
        fields = line.split()
        if not fields:
            continue
        parser = parsers.get(fields[0])
        if parser is None:
            raise InputError(
                f"Line {line_number}: unknown record {fields[0]!r}; a RigNet rig file has only "
                f"'{JOINT_KEYWORD}', '{ROOT_KEYWORD}', '{HIERARCHY_KEYWORD}' and '{SKIN_KEYWORD}' lines."
            )
        parser(fields, line_number)
    if not records.joint_names:
        raise InputError(f"The RigNet rig has no '{JOINT_KEYWORD}' line; it defines no skeleton.")
    records.joint_positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    _check_names_known(records)
    return records


def _parse_joint(fields: list[str], line: int, records: _Records, positions: list[list[float]]) -> None:
    if len(fields) != JOINT_FIELD_COUNT:
        raise InputError(f"Line {line}: expected '{JOINT_KEYWORD} NAME X Y Z', got {len(fields)} fields.")
    name = fields[1]
    if name in records.joint_index:
        first = records.joint_lines[records.joint_index[name]]
        raise InputError(f"Line {line}: joint {name!r} is defined twice (first on line {first}).")
    position = [_finite_float(value, line, "joint coordinate") for value in fields[2:]]
    if max(abs(value) for value in position) > MAX_JOINT_COORDINATE:
        raise InputError(
            f"Line {line}: joint {name!r} lies at {', '.join(f'{value:g}' for value in position)}, beyond "
            f"{MAX_JOINT_COORDINATE:g} units from the origin: Blender cannot keep bone lengths there. "
            "The file is damaged or in the wrong units."
        )
    records.joint_index[name] = len(records.joint_names)
    records.joint_names.append(name)
    records.joint_lines.append(line)
    positions.append(position)


def _parse_root(fields: list[str], line: int, records: _Records) -> None:
    if len(fields) != ROOT_FIELD_COUNT:
        raise InputError(f"Line {line}: expected '{ROOT_KEYWORD} NAME', got {len(fields)} fields.")
    if records.roots:
        raise InputError(
            f"Line {line}: several roots ({records.roots[0][0]!r} on line {records.roots[0][1]} and "
            f"{fields[1]!r}); a RigNet rig has exactly one root."
        )
    records.roots.append((fields[1], line))


def _parse_link(fields: list[str], line: int, records: _Records) -> None:
    if len(fields) != HIERARCHY_FIELD_COUNT:
        raise InputError(f"Line {line}: expected '{HIERARCHY_KEYWORD} PARENT CHILD', got {len(fields)} fields.")
    if fields[1] == fields[2]:
        raise InputError(f"Line {line}: joint {fields[1]!r} is its own parent, which makes a cycle.")
    records.links.append((fields[1], fields[2], line))


def _parse_skin(fields: list[str], line: int, records: _Records) -> None:
    if len(fields) < SKIN_MIN_FIELD_COUNT or len(fields) % 2:
        raise InputError(
            f"Line {line}: expected '{SKIN_KEYWORD} VERTEX NAME WEIGHT [NAME WEIGHT ...]', "
            f"got {len(fields)} fields (names and weights must come in pairs)."
        )
    try:
        vertex = int(fields[1])
    except ValueError:
        raise InputError(f"Line {line}: vertex index {fields[1]!r} is not an integer.") from None
    if vertex < 0:
        raise InputError(f"Line {line}: vertex index {vertex} is negative.")
    if vertex > MAX_VERTEX_INDEX:
        raise InputError(
            f"Line {line}: vertex index {vertex} is larger than any mesh can have "
            f"(Blender meshes hold at most {MAX_VERTEX_INDEX + 1} vertices); the file is damaged."
        )
    weights = [_finite_float(value, line, "weight") for value in fields[3::2]]
    if min(weights) < 0.0:
        raise InputError(f"Line {line}: negative skin weight {min(weights)}; weights must be >= 0.")
    records.skin_vertices.append(vertex)
    records.skin_joint_names.append(fields[2::2])
    records.skin_weights.append(weights)
    records.skin_lines.append(line)


def _finite_float(value: str, line: int, what: str) -> float:
    try:
        number = float(value)
    except ValueError:
        raise InputError(f"Line {line}: {what} {value!r} is not a number.") from None
    if not math.isfinite(number):
        raise InputError(f"Line {line}: {what} {value!r} is not finite.")
    return number


def _check_names_known(records: _Records) -> None:
    known = records.joint_index
    for name, line in records.roots:
        if name not in known:
            raise InputError(f"Line {line}: root {name!r} is not a joint defined by a '{JOINT_KEYWORD}' line.")
    for parent, child, line in records.links:
        for name in (parent, child):
            if name not in known:
                raise InputError(f"Line {line}: unknown joint {name!r} in '{HIERARCHY_KEYWORD}' line.")
    for names, line in zip(records.skin_joint_names, records.skin_lines):
        for name in names:
            if name not in known:
                raise InputError(f"Line {line}: unknown joint {name!r} in '{SKIN_KEYWORD}' line.")


def _sorted_hierarchy(records: _Records) -> tuple[np.ndarray, np.ndarray]:
    """Joint order (parents first, else file order) and the parent of each
    joint in that order.

    Returns
    -------
    order : (j,) int64 array
        ``order[k]`` is the file index of the k-th joint of the result.
    parents : (j,) int64 array
        Parent of each result joint as an index into the result, -1 for the root.
    """
    joint_count = len(records.joint_names)
    parent_of = -np.ones(joint_count, dtype=np.int64)
    parent_line = np.zeros(joint_count, dtype=np.int64)
    for parent, child, line in records.links:
        child_index = records.joint_index[child]
        if parent_of[child_index] >= 0:
            raise InputError(
                f"Line {line}: joint {child!r} already has parent "
                f"{records.joint_names[parent_of[child_index]]!r} (line {parent_line[child_index]}); "
                "a joint has one parent."
            )
        parent_of[child_index] = records.joint_index[parent]
        parent_line[child_index] = line
    _check_single_root(records, parent_of)
    # With one root, the joints left out of the order are those on a cycle.
    order = parents_first_order(parent_of)
    if len(order) < joint_count:
        stuck = sorted(set(range(joint_count)) - set(order.tolist()))
        raise InputError(
            "The joint hierarchy has a cycle through "
            + ", ".join(repr(records.joint_names[j]) for j in stuck[:8])
            + "; these joints cannot be reached from the root. Fix their 'hier' lines."
        )
    return order, reindexed_parents(parent_of, order)


def _check_joints_apart(records: _Records, order: np.ndarray, parents: np.ndarray) -> None:
    """Raise :class:`InputError` for a joint at its parent's position (within
    ``MIN_BONE_LENGTH_FRACTION`` of the joints' extent): the bone between
    them would have no length and no direction."""
    joints = records.joint_positions[order]
    extent = float(np.ptp(joints, axis=0).max()) if len(joints) else 0.0
    children = np.flatnonzero(parents >= 0)
    gaps = np.linalg.norm(joints[children] - joints[parents[children]], axis=1)
    together = children[gaps <= MIN_BONE_LENGTH_FRACTION * extent]
    if len(together):
        child, parent = int(order[together[0]]), int(order[parents[together[0]]])
        raise InputError(
            f"Line {records.joint_lines[child]}: joint {records.joint_names[child]!r} is at the same position as "
            f"its parent {records.joint_names[parent]!r} (line {records.joint_lines[parent]}), so the bone between "
            f"them has no length or direction ({len(together)} such joint(s)). Move one of them, or remove the "
            "duplicate and give its children to the other."
        )


def _check_single_root(records: _Records, parent_of: np.ndarray) -> None:
    """Raise :class:`InputError` unless exactly one joint has no parent and
    it is the one a ``root`` line names (when there is such a line)."""
    orphans = np.flatnonzero(parent_of < 0)
    if not len(orphans):
        raise InputError(
            "The joint hierarchy is a cycle: every joint has a parent, so none can be the root. "
            "Fix the 'hier' lines."
        )
    if records.roots:
        root_name, root_line = records.roots[0]
        root = records.joint_index[root_name]
        if parent_of[root] >= 0:
            raise InputError(
                f"Line {root_line}: root {root_name!r} has a parent "
                f"({records.joint_names[parent_of[root]]!r}); the root must have none."
            )
    elif len(orphans) == 1:
        root = int(orphans[0])
    else:
        root = -1
    extra_roots = [j for j in orphans.tolist() if j != root]
    if root < 0 or extra_roots:
        names = [records.joint_names[j] for j in orphans[:8]]
        raise InputError(
            f"The RigNet rig must have exactly one root; joints without a parent: {', '.join(names)}. "
            "Add the missing 'hier' lines (and one 'root' line)."
        )


def _weights_from_skin(
    records: _Records, new_index: np.ndarray, names: tuple, vertex_count: Optional[int]
) -> Weights:
    vertices = np.asarray(records.skin_vertices, dtype=np.int64)
    unique_vertices, first, counts = np.unique(vertices, return_index=True, return_counts=True)
    if np.any(counts > 1):
        duplicate = int(np.flatnonzero(counts > 1)[0])
        repeated = [records.skin_lines[k] for k in np.flatnonzero(vertices == unique_vertices[duplicate])]
        raise InputError(f"Vertex {unique_vertices[duplicate]} has several '{SKIN_KEYWORD}' lines "
                         f"(lines {repeated[:4]}).")
    largest = int(vertices.max())
    if vertex_count is None:
        vertex_count = largest + 1
        line = records.skin_lines[int(np.argmax(vertices))]
        require_memory(
            float(vertex_count) * len(names) * WEIGHT_BYTES,
            f"Line {line}: vertex index {largest} means a mesh of {vertex_count} vertices; its weight table",
            "The file is damaged, or import it with its mesh selected so the indices are checked against it.",
        )
    elif largest >= vertex_count:
        line = records.skin_lines[int(np.argmax(vertices))]
        raise InputError(
            f"Line {line}: vertex index {largest} is out of range for a mesh of {vertex_count} vertices; "
            "the rig file does not belong to this mesh."
        )
    pair_counts = np.fromiter((len(row) for row in records.skin_weights), dtype=np.int64, count=len(vertices))
    rows = np.repeat(vertices, pair_counts)
    file_columns = np.fromiter(
        (records.joint_index[name] for row in records.skin_joint_names for name in row),
        dtype=np.int64,
        count=int(pair_counts.sum()),
    )
    values = np.fromiter((w for row in records.skin_weights for w in row), dtype=np.float64, count=len(rows))
    matrix = np.zeros((vertex_count, len(names)))
    # A joint named twice on one line adds up, as RigNet's own loader does.
    np.add.at(matrix, (rows, new_index[file_columns]), values)
    return Weights(matrix, names)


def _check_writable_names(names: tuple) -> None:
    for name in names:
        if not name or any(character.isspace() for character in name):
            raise InputError(
                f"Bone name {name!r} is empty or contains whitespace, which the RigNet text format "
                "cannot store. Rename the bone first."
            )


def _float_text(value: float) -> str:
    return repr(float(value))


def _skin_text(skeleton: Skeleton, weights: Weights) -> str:
    known = set(skeleton.names)
    unknown = [name for name in weights.bone_names if name not in known]
    if unknown:
        raise InputError(
            f"Weights name bones missing from the skeleton: {', '.join(unknown[:8])}. "
            "Write weights for the skeleton's own bones."
        )
    _check_writable_names(weights.bone_names)
    matrix = weights.matrix
    if not np.all(np.isfinite(matrix)):
        raise InputError("Weights contain NaN or infinite values; clean them before writing.")
    rows, columns = np.nonzero(matrix > 0.0)
    if not len(rows):
        return ""
    names = np.asarray(weights.bone_names, dtype=object)
    pair_text = (" " + names[columns] + " "
                 + np.asarray(list(map(_float_text, matrix[rows, columns].tolist())), dtype=object))
    row_starts = np.flatnonzero(np.r_[True, rows[1:] != rows[:-1]])
    prefixes = np.asarray([f"{SKIN_KEYWORD} {v}" for v in rows[row_starts].tolist()], dtype=object)
    pair_text[row_starts] = prefixes + pair_text[row_starts]
    line_ends = np.r_[row_starts[1:] - 1, len(rows) - 1]
    pair_text[line_ends] = pair_text[line_ends] + "\n"
    return "".join(pair_text.tolist())
