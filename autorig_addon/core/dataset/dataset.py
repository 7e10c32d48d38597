"""Normalised training and evaluation samples of rigged characters.

A :class:`CharacterSample` is one rigged character (mesh, skeleton,
weights) moved into a common frame, stored as one ``.npz`` file. Loading the
characters needs Blender (``blender.characters``); everything here works on
arrays, and :func:`build_samples` takes the loader as an argument.

Normalisation
-------------
RigNet's (``normalize_obj`` in its ``quick_start.py``), written for
Blender's axes (z up, characters facing -Y, their left side at +X):

1. the bounding box of the mesh is centred on x and y and its lowest point
   (the feet) put at z = 0;
2. the character is turned about the vertical axis by quarter turns so that
   its left-side bones (see :func:`bone_side`) lie at +X of its right-side
   ones (:func:`facing_quarter_turns`): a character facing +Y turns 180
   degrees, one facing +X or -X 90 degrees. When no bone name tells left
   from right the character is kept as the file has it (importers already
   map each format's own front axis to Blender's -Y) and the sample records
   ``facing = "unknown"``;
3. everything is scaled uniformly so that the largest side of the bounding
   box is 1. For an upright biped this is its height; RigNet scales by the
   largest side too, so long animals (snakes, fish) are not blown up.

The up axis is the importer's: glTF is y-up by specification and FBX files
declare theirs; both are converted to Blender's z-up on import.

Cache
-----
Samples are cached under ``$AUTORIG_CACHE/samples`` (default
``~/.cache/autorig_addon/samples``), one file per source file content and
build parameters, so a changed file or setting makes a new sample and
rebuilding is reproducible.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, NamedTuple, Optional, Sequence

import numpy as np

from ..errors import InputError
from ..progress import ProgressCallback, report
from ..types import Mesh, Skeleton, Weights
from ..weights import normalize_rows

#: Environment variable naming the cache root (samples go to ``<root>/samples``).
CACHE_ENVIRONMENT_VARIABLE = "AUTORIG_CACHE"
#: Cache root used when the environment variable is not set.
DEFAULT_CACHE_ROOT = Path("~/.cache/autorig_addon")
#: Sub-folder of the cache root holding the sample files.
SAMPLES_FOLDER = "samples"
#: Bumped whenever the sample content or normalisation changes, so old cache
#: files are not reused.
SAMPLE_FORMAT_VERSION = 1
#: Vertex count the mesh of a sample is simplified to by default. Networks in
#: the RigNet family work on 1k to 5k vertices.
DEFAULT_TARGET_VERTICES = 3000
#: Recommended range of target vertex counts (RigNet's remeshed inputs).
RECOMMENDED_VERTEX_RANGE = (1000, 5000)
#: Smallest target vertex count accepted: fewer cannot describe a character.
MIN_TARGET_VERTICES = 100

#: ``facing`` values of a sample: already facing -Y by its bone names, turned
#: to face -Y, or kept as loaded because no bone name tells left from right.
FACING_AS_NAMED = "named"
FACING_TURNED = "turned"
FACING_UNKNOWN = "unknown"

_LEFT, _RIGHT, _NO_SIDE = 1, -1, 0
# Side markers: a separated single letter at the end (".L", "_l", "-R", " r")
# or start ("L_", "r."), or the words left/right anywhere ("LeftArm",
# "arm_right", "mixamorig:RightHand").
_SUFFIX_SIDE = re.compile(r"[._\-\s]([LlRr])$")
_PREFIX_SIDE = re.compile(r"^([LlRr])[._\-\s]")
_LEFT_WORD = re.compile(r"left", re.IGNORECASE)
_RIGHT_WORD = re.compile(r"right", re.IGNORECASE)


def bone_side(name: str) -> int:
    """Which side of the body a bone name says it is on.

    Recognises ``.L``/``.R`` and ``_l``/``_r``-style suffixes, ``L_``/``r.``
    prefixes and the words ``Left``/``Right`` anywhere (any case).

    Parameters
    ----------
    name : str

    Returns
    -------
    side : int
        1 for left, -1 for right, 0 when the name does not say (or says both).
    """
    left = bool(_LEFT_WORD.search(name))
    right = bool(_RIGHT_WORD.search(name))
    for pattern in (_SUFFIX_SIDE, _PREFIX_SIDE):
        match = pattern.search(name)
        if match:
            letter = match.group(1).lower()
            left |= letter == "l"
            right |= letter == "r"
    if left == right:
        return _NO_SIDE
    return _LEFT if left else _RIGHT


def facing_quarter_turns(skeleton: Skeleton) -> Optional[int]:
    """Quarter turns about +Z that bring the character's left side to +X.

    The direction from the mean of the joints whose names say right to the
    mean of those that say left (:func:`bone_side`; all bones count, deform
    or not), projected on the ground, is the character's left. It is snapped
    to the nearest axis, so a slightly asymmetric pose does not tilt the
    bounding box.

    Parameters
    ----------
    skeleton : Skeleton

    Returns
    -------
    int in 0..3 or None
        Counter-clockwise quarter turns (seen from above); 2 turns a
        character facing +Y around. None when the names give no left and
        right joints, or both sides lie at the same place on the ground.
    """
    sides = np.array([bone_side(name) for name in skeleton.names], dtype=np.int64)
    left, right = sides == _LEFT, sides == _RIGHT
    if not left.any() or not right.any():
        return None
    direction = skeleton.joints[left, :2].mean(axis=0) - skeleton.joints[right, :2].mean(axis=0)
    if not np.any(np.abs(direction) > 0.0):
        return None
    angle = np.degrees(np.arctan2(direction[1], direction[0]))
    return int(np.round(-angle / 90.0)) % 4


def subdivide_midpoints(vertices: np.ndarray, triangles: np.ndarray, values: np.ndarray) -> tuple:
    """Split every triangle into four at its edge midpoints.

    The shape does not change (new vertices lie on the old edges); values
    at a midpoint are the mean of the edge's two ends, i.e. linear
    interpolation.

    Parameters
    ----------
    vertices : (n, 3) float64 array
    triangles : (m, 3) int64 array
    values : (n, k) float64 array, per-vertex values (e.g. weights)

    Returns
    -------
    vertices : (n + e, 3) float64 array, the old vertices first
    triangles : (4 m, 3) int64 array, same orientation
    values : (n + e, k) float64 array
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    values = np.asarray(values, dtype=np.float64).reshape(len(vertices), -1)
    corners = [triangles[:, 0], triangles[:, 1], triangles[:, 2]]
    halves = np.concatenate([np.stack([corners[k], corners[(k + 1) % 3]], axis=1) for k in range(3)])
    edges, edge_of_half = np.unique(np.sort(halves, axis=1), axis=0, return_inverse=True)
    middle = len(vertices) + edge_of_half.reshape(3, -1)  # middle[k]: midpoint of edge (k, k+1)
    new_vertices = np.vstack([vertices, vertices[edges].mean(axis=1)])
    new_values = np.vstack([values, values[edges].mean(axis=1)])
    a, b, c = corners
    ab, bc, ca = middle
    new_triangles = np.concatenate([
        np.stack([a, ab, ca], axis=1), np.stack([ab, b, bc], axis=1),
        np.stack([ca, bc, c], axis=1), np.stack([ab, bc, ca], axis=1),
    ])
    return new_vertices, new_triangles, new_values


class Normalised(NamedTuple):
    """Result of :func:`normalise`.

    Attributes
    ----------
    mesh : Mesh, the moved copy
    skeleton : Skeleton, the moved copy
    transform : (4, 4) float64 array
        Maps original positions ``p`` to normalised ones:
        ``transform[:3, :3] @ p + transform[:3, 3]``.
    facing : str
        :data:`FACING_AS_NAMED`, :data:`FACING_TURNED` or :data:`FACING_UNKNOWN`.
    """

    mesh: Mesh
    skeleton: Skeleton
    transform: np.ndarray
    facing: str


def normalisation_transform(vertices: np.ndarray, quarter_turns: int = 0) -> np.ndarray:
    """The similarity transform of :func:`normalise` for given vertices.

    Parameters
    ----------
    vertices : (n, 3) float64 array
    quarter_turns : int
        Counter-clockwise quarter turns (seen from above) about the vertical
        axis through the box centre.

    Returns
    -------
    transform : (4, 4) float64 array
        ``scale * R @ (p - pivot)`` as an affine matrix, with ``pivot`` the
        box centre in x, y and the box bottom in z.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    if not len(vertices):
        raise InputError("The mesh has no vertices, so it cannot be normalised.")
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    largest_side = float((high - low).max())
    if largest_side <= 0.0:
        raise InputError("All vertices lie at one point, so the mesh cannot be normalised.")
    pivot = np.array([(low[0] + high[0]) / 2.0, (low[1] + high[1]) / 2.0, low[2]])
    cosine, sine = [(1, 0), (0, 1), (-1, 0), (0, -1)][int(quarter_turns) % 4]
    rotation = np.array([[cosine, -sine, 0.0], [sine, cosine, 0.0], [0.0, 0.0, 1.0]])
    linear = rotation / largest_side
    transform = np.eye(4)
    transform[:3, :3] = linear
    transform[:3, 3] = -linear @ pivot
    return transform


def apply_transform(points: np.ndarray, transform: np.ndarray) -> np.ndarray:
    """(n, 3) float64 ``points`` mapped by the (4, 4) affine ``transform``."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return points @ transform[:3, :3].T + transform[:3, 3]


def normalise(mesh: Mesh, skeleton: Skeleton) -> Normalised:
    """Move a character into the common frame (see the module docstring).

    Parameters
    ----------
    mesh : Mesh
    skeleton : Skeleton
        In the mesh's space.

    Returns
    -------
    Normalised
        Copies of both and the transform; triangles, names, parents and
        deform flags are unchanged (a rotation and a positive scale keep the
        triangles' orientation).
    """
    turns = facing_quarter_turns(skeleton)
    transform = normalisation_transform(mesh.vertices, turns or 0)
    moved_mesh = Mesh(
        apply_transform(mesh.vertices, transform), mesh.triangles, mesh.triangle_polygons,
        mesh.object_offsets, mesh.object_names,
    )
    moved_skeleton = Skeleton(
        apply_transform(skeleton.joints, transform), skeleton.parents, skeleton.names,
        apply_transform(skeleton.tails, transform), skeleton.deform,
    )
    facing = FACING_UNKNOWN if turns is None else (FACING_TURNED if turns else FACING_AS_NAMED)
    return Normalised(moved_mesh, moved_skeleton, transform, facing)


@dataclass(frozen=True)
class CharacterSample:
    """One normalised rigged character, as stored in a cache ``.npz`` file.

    Attributes
    ----------
    vertices : (n, 3) float64 array, normalised positions
    triangles : (m, 3) int64 array
    joints : (j, 3) float64 array, bone heads, normalised
    parents : (j,) int64 array, -1 for roots, parents first
    names : tuple of j str, bone names
    tails : (j, 3) float64 array, bone tails, normalised
    deform : (j,) bool array, bones that carry weights
    weights : (n, d) float64 array
        Columns are the ``d`` deform bones in joint order; rows sum to one
        (rows of vertices the artist left unweighted are zero).
    name : str, the character's name
    category : str, e.g. ``"biped"`` or the source folder
    transform : (4, 4) float64 array
        From the source file's world space to the normalised frame (see
        :func:`normalise`); its inverse maps predictions back.
    facing : str, see :class:`Normalised`
    source_vertex_count : int, vertices of the mesh before simplification
    """

    vertices: np.ndarray
    triangles: np.ndarray
    joints: np.ndarray
    parents: np.ndarray
    names: tuple
    tails: np.ndarray
    deform: np.ndarray
    weights: np.ndarray
    name: str
    category: str
    transform: np.ndarray
    facing: str = FACING_UNKNOWN
    source_vertex_count: int = 0

    @property
    def mesh(self) -> Mesh:
        return Mesh(self.vertices, self.triangles, object_names=(self.name,))

    @property
    def skeleton(self) -> Skeleton:
        return Skeleton(self.joints, self.parents, self.names, self.tails, self.deform)

    @property
    def deform_names(self) -> tuple:
        return tuple(name for name, deforms in zip(self.names, self.deform) if deforms)

    @property
    def skin(self) -> Weights:
        """The weights as :class:`Weights` named by deform bone."""
        return Weights(self.weights, self.deform_names)

    @classmethod
    def from_character(
        cls, name: str, category: str, mesh: Mesh, skeleton: Skeleton, weights: Weights, source_vertex_count: int = 0,
    ) -> "CharacterSample":
        """Normalise a character and keep its deform-bone weights.

        Parameters
        ----------
        name, category : str
        mesh : Mesh, world space
        skeleton : Skeleton, world space
        weights : Weights (n, b), matched to the deform bones by name
        source_vertex_count : int, vertices before any simplification
        """
        if weights.vertex_count != mesh.vertex_count:
            raise InputError(
                f"'{name}': the weights have {weights.vertex_count} rows but the mesh has {mesh.vertex_count} vertices."
            )
        normalised = normalise(mesh, skeleton)
        deform_names = skeleton.deform_subset().names
        matrix = normalize_rows(weights.select_bones(deform_names).matrix)
        return cls(
            vertices=normalised.mesh.vertices,
            triangles=normalised.mesh.triangles,
            joints=normalised.skeleton.joints,
            parents=normalised.skeleton.parents,
            names=normalised.skeleton.names,
            tails=normalised.skeleton.tails,
            deform=normalised.skeleton.deform,
            weights=matrix,
            name=name,
            category=category,
            transform=normalised.transform,
            facing=normalised.facing,
            source_vertex_count=int(source_vertex_count or mesh.vertex_count),
        )

    def save(self, path: str | os.PathLike) -> None:
        """Write the sample to ``path`` (``.npz``, compressed), atomically."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = path.with_name(path.name + f".{os.getpid()}.tmp")
        with open(temporary, "wb") as handle:
            np.savez_compressed(
                handle,
                format_version=np.int64(SAMPLE_FORMAT_VERSION),
                vertices=self.vertices,
                triangles=self.triangles,
                joints=self.joints,
                parents=self.parents,
                names=np.asarray(self.names, dtype=np.str_),
                tails=self.tails,
                deform=self.deform,
                weights=self.weights,
                name=np.asarray(self.name, dtype=np.str_),
                category=np.asarray(self.category, dtype=np.str_),
                transform=self.transform,
                facing=np.asarray(self.facing, dtype=np.str_),
                source_vertex_count=np.int64(self.source_vertex_count),
            )
        os.replace(temporary, path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> "CharacterSample":
        """Read a sample written by :meth:`save`.

        Raises
        ------
        InputError for a missing file or one of another format version.
        """
        path = Path(path)
        if not path.is_file():
            raise InputError(f"The sample file '{path}' does not exist.")
        with np.load(path, allow_pickle=False) as data:
            version = int(data["format_version"]) if "format_version" in data else -1
            if version != SAMPLE_FORMAT_VERSION:
                raise InputError(
                    f"'{path.name}' is a sample of format {version}, this version reads {SAMPLE_FORMAT_VERSION}: "
                    "delete it and build the samples again."
                )
            return cls(
                vertices=data["vertices"],
                triangles=data["triangles"],
                joints=data["joints"],
                parents=data["parents"],
                names=tuple(str(name) for name in data["names"]),
                tails=data["tails"],
                deform=data["deform"],
                weights=data["weights"],
                name=str(data["name"]),
                category=str(data["category"]),
                transform=data["transform"],
                facing=str(data["facing"]),
                source_vertex_count=int(data["source_vertex_count"]),
            )


def default_cache_dir() -> Path:
    """Folder of cached samples: ``$AUTORIG_CACHE/samples`` or
    ``~/.cache/autorig_addon/samples``."""
    root = os.environ.get(CACHE_ENVIRONMENT_VARIABLE)
    base = Path(root) if root else DEFAULT_CACHE_ROOT
    return base.expanduser() / SAMPLES_FOLDER


def file_content_hash(path: str | os.PathLike) -> str:
    """SHA-256 hex digest of a file's bytes; for ``.gltf`` also of the
    buffers it references by relative path (``.bin`` files), so editing the
    geometry invalidates the cache."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"The file '{path}' does not exist.")
    digest = hashlib.sha256(path.read_bytes())
    if path.suffix.lower() == ".gltf":
        for buffer_path in _gltf_buffer_paths(path):
            digest.update(buffer_path.name.encode("utf-8"))
            digest.update(buffer_path.read_bytes() if buffer_path.is_file() else b"missing")
    return digest.hexdigest()


def _gltf_buffer_paths(path: Path) -> list[Path]:
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise InputError(f"'{path.name}' is not a readable glTF file: {error}") from None
    uris = [buffer.get("uri", "") for buffer in document.get("buffers", [])]
    return [path.parent / uri for uri in uris if uri and not uri.startswith("data:")]


def sample_cache_key(path: str | os.PathLike, parameters: dict) -> str:
    """Hex key naming the sample of ``path`` built with ``parameters``.

    Parameters
    ----------
    path : path of the source file
    parameters : dict of JSON-serialisable build settings

    Returns
    -------
    str, 64 hex digits: SHA-256 of the content hash, the sorted parameters
    and :data:`SAMPLE_FORMAT_VERSION`.
    """
    payload = json.dumps(
        {"content": file_content_hash(path), "parameters": parameters, "format": SAMPLE_FORMAT_VERSION},
        sort_keys=True,
    )
    return hashlib.sha256(payload.encode("utf-8")).hexdigest()


#: Hex digits of the cache key kept in a sample's file name.
CACHE_KEY_DIGITS = 20


def sample_path(cache_dir: str | os.PathLike, source: str | os.PathLike, key: str) -> Path:
    """Cache file of ``source``'s sample with ``key``: ``<stem>-<key>.npz``."""
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", Path(source).stem) or "character"
    return Path(cache_dir) / f"{stem}-{key[:CACHE_KEY_DIGITS]}.npz"


#: ``load(path, target_vertices)`` returns an object with ``name``,
#: ``category``, ``mesh`` (Mesh), ``skeleton`` (Skeleton), ``weights``
#: (Weights over the deform bones) and optionally ``source_vertex_count``.
CharacterLoader = Callable[[Path, Optional[int]], object]


def build_samples(
    paths: Iterable[str | os.PathLike],
    load: CharacterLoader,
    cache_dir: str | os.PathLike | None = None,
    target_vertices: Optional[int] = DEFAULT_TARGET_VERTICES,
    progress: Optional[ProgressCallback] = None,
) -> list[CharacterSample]:
    """Samples of rigged character files, built once and then read from the cache.

    Parameters
    ----------
    paths : iterable of file paths
    load : CharacterLoader
        Reads one file (needs Blender: ``blender.characters.load_simplified``);
        called only for files without a cached sample.
    cache_dir : folder, optional
        Default :func:`default_cache_dir`.
    target_vertices : int or None
        Vertex count the mesh is simplified to (:data:`RECOMMENDED_VERTEX_RANGE`
        suits networks); None keeps the full mesh.
    progress : ProgressCallback, optional

    Returns
    -------
    list of CharacterSample, in the order of ``paths``.
    """
    if target_vertices is not None and int(target_vertices) < MIN_TARGET_VERTICES:
        raise InputError(
            f"A target of {target_vertices} vertices is too coarse for a character; use at least "
            f"{MIN_TARGET_VERTICES} ({RECOMMENDED_VERTEX_RANGE[0]} to {RECOMMENDED_VERTEX_RANGE[1]} suits networks)."
        )
    cache = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    paths = [Path(path) for path in paths]
    parameters = {"target_vertices": None if target_vertices is None else int(target_vertices)}
    samples = []
    for index, path in enumerate(paths):
        report(progress, index / max(len(paths), 1), f"Sample of {path.name}")
        cached = sample_path(cache, path, sample_cache_key(path, parameters))
        if cached.is_file():
            samples.append(CharacterSample.load(cached))
            continue
        character = load(path, parameters["target_vertices"])
        sample = CharacterSample.from_character(
            character.name, character.category, character.mesh, character.skeleton, character.weights,
            getattr(character, "source_vertex_count", 0),
        )
        sample.save(cached)
        samples.append(sample)
    report(progress, 1.0, "Samples ready")
    return samples


# --------------------------------------------------------------------------- data split


@dataclass(frozen=True)
class DataSplit:
    """The train/validation split of the rigged characters (``data_split.json``).

    Attributes
    ----------
    train, validation : tuple of str
        File paths relative to the characters folder, ``/``-separated.
    categories : dict of str -> str
        Category of each listed path.
    """

    train: tuple
    validation: tuple
    categories: dict

    def subset(self, name: str) -> tuple:
        """Paths of ``"train"``, ``"validation"`` or ``"all"``."""
        if name == "train":
            return self.train
        if name == "validation":
            return self.validation
        if name == "all":
            return tuple(dict.fromkeys(self.train + self.validation))
        raise InputError(f"Unknown split {name!r}: use train, validation or all.")


def read_data_split(path: str | os.PathLike) -> DataSplit:
    """Read ``data_split.json``.

    Accepts ``categories`` as ``{path: category}`` or ``{category: [paths]}``.

    Raises
    ------
    InputError for a missing or malformed file.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"The data split '{path}' does not exist: pass DATA files directly or use --split all.")
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except ValueError as error:
        raise InputError(f"'{path.name}' is not valid JSON: {error}") from None
    if not isinstance(document, dict) or "train" not in document or "validation" not in document:
        raise InputError(f"'{path.name}' must be a JSON object with 'train' and 'validation' lists of paths.")
    train = tuple(_split_path(entry) for entry in document["train"])
    validation = tuple(_split_path(entry) for entry in document["validation"])
    return DataSplit(train, validation, _categories(document.get("categories", {})))


def _split_path(entry) -> str:
    text = entry.get("path", "") if isinstance(entry, dict) else str(entry)
    return Path(text).as_posix()


def _categories(raw) -> dict:
    categories = {}
    if isinstance(raw, dict):
        for key, value in raw.items():
            if isinstance(value, (list, tuple)):
                categories.update({_split_path(item): str(key) for item in value})
            else:
                categories[_split_path(key)] = str(value)
    return categories


def relative_name(path: str | os.PathLike, root: str | os.PathLike | None = None) -> str:
    """A character's name: its path below ``root`` without the extension,
    ``/``-separated (``"animals/Fox"``), or the file's stem without ``root``
    or when the file is not below it."""
    path = Path(path)
    if root is not None:
        try:
            return path.resolve().relative_to(Path(root).resolve()).with_suffix("").as_posix()
        except ValueError:
            pass
    return path.stem


def category_of(relative_path: str, split: Optional[DataSplit] = None) -> str:
    """The category of a character file: from the split when it lists the
    file, else the name of the folder holding it (``""`` at the top)."""
    relative = Path(relative_path).as_posix()
    if split is not None and relative in split.categories:
        return split.categories[relative]
    parent = Path(relative).parent.name
    return parent


def select_split(relative_paths: Sequence[str], split: DataSplit, subset: str) -> list[int]:
    """Indices of ``relative_paths`` listed in ``split``'s ``subset``."""
    wanted = set(split.subset(subset))
    return [index for index, relative in enumerate(relative_paths) if Path(relative).as_posix() in wanted]
