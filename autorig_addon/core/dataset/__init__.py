"""Normalised training and evaluation samples of rigged characters.

:mod:`.normalise` moves a character into RigNet's common frame,
:mod:`.sample` stores one as a :class:`CharacterSample` (``.npz``),
:mod:`.cache` builds samples of files once and reads them from the cache
after, :mod:`.split` reads the train/validation split, names and
categorises the files and picks those of a subset. The public names of all four are here too.
"""

from .cache import (
    CACHE_ENVIRONMENT_VARIABLE,
    CACHE_KEY_DIGITS,
    DEFAULT_CACHE_ROOT,
    DEFAULT_TARGET_VERTICES,
    MIN_TARGET_VERTICES,
    RECOMMENDED_VERTEX_RANGE,
    SAMPLES_FOLDER,
    CharacterLoader,
    build_samples,
    default_cache_dir,
    file_content_hash,
    sample_cache_key,
    sample_path,
    training_samples,
)
from .normalise import (
    FACING_AS_NAMED,
    FACING_TURNED,
    FACING_UNKNOWN,
    Normalised,
    apply_transform,
    bone_side,
    facing_quarter_turns,
    normalisation_transform,
    normalise,
)
from .sample import SAMPLE_FORMAT_VERSION, CharacterSample
from .split import (
    DEFAULT_SPLIT_FILE,
    SUBSETS,
    DataItem,
    DataSplit,
    category_of,
    collect_data,
    read_data_split,
    relative_name,
    select_split,
)

__all__ = [
    "CACHE_ENVIRONMENT_VARIABLE",
    "CACHE_KEY_DIGITS",
    "DEFAULT_CACHE_ROOT",
    "DEFAULT_SPLIT_FILE",
    "DEFAULT_TARGET_VERTICES",
    "FACING_AS_NAMED",
    "FACING_TURNED",
    "FACING_UNKNOWN",
    "MIN_TARGET_VERTICES",
    "RECOMMENDED_VERTEX_RANGE",
    "SAMPLES_FOLDER",
    "SAMPLE_FORMAT_VERSION",
    "SUBSETS",
    "CharacterLoader",
    "CharacterSample",
    "DataItem",
    "DataSplit",
    "Normalised",
    "apply_transform",
    "bone_side",
    "build_samples",
    "category_of",
    "collect_data",
    "default_cache_dir",
    "facing_quarter_turns",
    "file_content_hash",
    "normalisation_transform",
    "normalise",
    "read_data_split",
    "relative_name",
    "sample_cache_key",
    "sample_path",
    "select_split",
    "training_samples",
]
