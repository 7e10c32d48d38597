"""Building samples of rigged character files once and caching them.

Samples are cached under ``$AUTORIG_CACHE/samples`` (default
``~/.cache/autorig_addon/samples``), one file per source file content and
build parameters, so a changed file or setting makes a new sample and
rebuilding is reproducible. Loading the characters needs Blender
(``blender.characters``); :func:`build_samples` takes the loader as an
argument, so everything here works on arrays. :func:`training_samples`
reads the cached samples of the split's training characters (training runs
and the ``nearest_character`` baseline of ``eval rig``), for skeletons or for
skin weights.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path
from typing import Callable, Iterable, Optional

from ..errors import InputError
from ..progress import ProgressCallback, report
from .sample import SAMPLE_FORMAT_VERSION, CharacterSample
from .split import DEFAULT_SPLIT_FILE, PURPOSE_SKELETON, read_data_split

#: Environment variable naming the cache root (samples go to ``<root>/samples``).
CACHE_ENVIRONMENT_VARIABLE = "AUTORIG_CACHE"
#: Cache root used when the environment variable is not set.
DEFAULT_CACHE_ROOT = Path("~/.cache/autorig_addon")
#: Sub-folder of the cache root holding the sample files.
SAMPLES_FOLDER = "samples"
#: Vertex count the mesh of a sample is simplified to by default. Networks in
#: the RigNet family work on 1k to 5k vertices.
DEFAULT_TARGET_VERTICES = 3000
#: Recommended range of target vertex counts (RigNet's remeshed inputs).
RECOMMENDED_VERTEX_RANGE = (1000, 5000)
#: Smallest target vertex count accepted: fewer cannot describe a character.
MIN_TARGET_VERTICES = 100


def cache_root() -> Path:
    """The cache root: ``$AUTORIG_CACHE`` or ``~/.cache/autorig_addon``."""
    root = os.environ.get(CACHE_ENVIRONMENT_VARIABLE)
    return (Path(root) if root else DEFAULT_CACHE_ROOT).expanduser()


def default_cache_dir() -> Path:
    """Folder of cached samples: ``<cache root>/samples``."""
    return cache_root() / SAMPLES_FOLDER


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
#: (Weights over the deform bones) and optionally ``source_vertex_count``,
#: ``notes`` (tuple of str) and ``sides_named_from_the_viewer`` (bool), as
#: ``blender.characters.RiggedCharacter``.
CharacterLoader = Callable[[Path, Optional[int]], object]


def build_samples(
    paths: Iterable[str | os.PathLike],
    load: CharacterLoader,
    cache_dir: str | os.PathLike | None = None,
    target_vertices: Optional[int] = DEFAULT_TARGET_VERTICES,
    progress: Optional[ProgressCallback] = None,
    key_extras: Optional[Callable[[Path], dict]] = None,
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
    key_extras : callable(path) -> dict, optional
        What else the loader does to a file that its sample's cache key must
        hold (``sides_named_from_the_viewer``); {} for most files.

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
        key_parameters = {**parameters, **(key_extras(path) if key_extras is not None else {})}
        cached = sample_path(cache, path, sample_cache_key(path, key_parameters))
        if cached.is_file():
            samples.append(CharacterSample.load(cached))
            continue
        character = load(path, parameters["target_vertices"])
        sample = CharacterSample.from_character(
            character.name, character.category, character.mesh, character.skeleton, character.weights,
            getattr(character, "source_vertex_count", 0), getattr(character, "notes", ()),
            getattr(character, "sides_named_from_the_viewer", False),
        )
        sample.save(cached)
        samples.append(sample)
    report(progress, 1.0, "Samples ready")
    return samples


def training_samples(sample_dir: str | os.PathLike | None = None, split_file: Optional[str] = None,
                     purpose: str = PURPOSE_SKELETON) -> list[CharacterSample]:
    """The cached samples of the split's training characters usable for ``purpose``, sorted by name.

    Parameters
    ----------
    sample_dir : folder, optional
        Default :func:`default_cache_dir`.
    split_file : path of ``data_split.json``, optional
        Default :data:`~.split.DEFAULT_SPLIT_FILE`.
    purpose : str
        :data:`~.split.PURPOSE_SKELETON` (every training character: skeleton
        training, the ``nearest_character`` baseline) or
        :data:`~.split.PURPOSE_SKIN` (skin training: the split's
        ``skeleton_only`` characters left out, :meth:`~.split.DataSplit.usable_for`).

    Raises
    ------
    InputError when some are missing (build them with ``eval`` or
    ``blender.characters.build_character_samples``: that needs Blender).
    """
    sample_dir = Path(sample_dir) if sample_dir is not None else default_cache_dir()
    split = read_data_split(split_file or DEFAULT_SPLIT_FILE)
    wanted = {os.path.splitext(path)[0] for path in split.subset("train", purpose)}
    found = {}
    for path in sorted(sample_dir.glob("*.npz")):
        try:
            sample = CharacterSample.load(path)
        except InputError:
            continue  # a sample of an older format; the builder replaces it
        if sample.name in wanted:
            found[sample.name] = sample
    missing = sorted(wanted - set(found))
    if missing:
        raise InputError(
            f"{len(missing)} training character(s) have no cached sample in '{sample_dir}' (e.g. {missing[0]}); "
            "build the samples first: python -m autorig_addon train samples (needs the bpy module).")
    return [found[name] for name in sorted(found)]
