"""The train/validation split of the rigged characters and their names and categories.

:func:`read_data_split` reads the split, :func:`relative_name` and
:func:`category_of` name and categorise a file, and :func:`collect_data`
picks the files of given files and folders that a subset of the split lists.
What a character may be used for is decided in one place,
:meth:`DataSplit.usable_for`: every character serves skeletons, and those the
split marks ``skeleton_only`` (weights that are not an artist's skinning)
are left out of skin training and skin evaluation.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional, Sequence

from ..errors import InputError
from ..io.scene_formats import scene_files

#: Names of the subsets of a split: all its files, the training files and the
#: validation files.
SUBSETS = ("all", "train", "validation")
#: What a character is used for: its skeleton (every character of the split)
#: or its skin weights (not the split's ``skeleton_only`` characters).
PURPOSE_SKELETON = "skeleton"
PURPOSE_SKIN = "skin"
PURPOSES = (PURPOSE_SKELETON, PURPOSE_SKIN)
#: Kinds of character the split's ``categories`` name.
HUMANOID, QUADRUPED, BIRD, FISH, OTHER = "humanoid", "quadruped", "bird", "fish", "other"
KINDS = (HUMANOID, QUADRUPED, BIRD, FISH, OTHER)
#: Where the train/validation split lives: the repository's top folder.
DEFAULT_SPLIT_FILE = Path(__file__).resolve().parents[3] / "data_split.json"


@dataclass(frozen=True)
class DataSplit:
    """The train/validation split of the rigged characters (``data_split.json``).

    Attributes
    ----------
    train, validation : tuple of str
        File paths relative to the characters folder, ``/``-separated.
    categories : dict of str -> str
        Category (kind) of each listed path.
    skeleton_only : dict of str -> str
        Paths whose skin weights are not trusted, with the reason: used for
        skeletons, never for skin weights (:meth:`usable_for`).
    excluded : dict of str -> str
        Files of the characters folder on neither side, with the reason.
    families : dict of str -> int
        Skeleton family (index in the file's ``families`` list) of each
        listed path: characters sharing a rig or a body, which the split
        keeps on one side and training samples evenly.
    near_duplicates : tuple of frozenset of str
        Groups of paths whose characters are near-duplicates of one another
        (the same body and rig in other clothes or colours).
    sides_named_from_the_viewer : dict of str -> str
        Paths whose artist named the bones' sides from the viewer (``l-arm``
        on the character's right, its face telling which way it looks), with
        the evidence: their references are read with the sides swapped
        (:func:`~.normalise.normalise`).
    """

    train: tuple
    validation: tuple
    categories: dict
    skeleton_only: dict = field(default_factory=dict)
    excluded: dict = field(default_factory=dict)
    families: dict = field(default_factory=dict)
    near_duplicates: tuple = ()
    sides_named_from_the_viewer: dict = field(default_factory=dict)

    def near_duplicate_names(self, name: str) -> frozenset:
        """``name`` (a path without extension) and the names of its near-duplicates."""
        for group in self.near_duplicates:
            names = frozenset(os.path.splitext(path)[0] for path in group)
            if name in names:
                return names
        return frozenset({name})

    def usable_for(self, path: str, purpose: str) -> bool:
        """Whether the character at ``path`` (relative, as listed) may be used
        for ``purpose`` (:data:`PURPOSES`): any character for skeletons, not a
        ``skeleton_only`` one for skin weights."""
        if purpose not in PURPOSES:
            raise InputError(f"Unknown purpose {purpose!r}: use {' or '.join(PURPOSES)}.")
        return purpose == PURPOSE_SKELETON or path not in self.skeleton_only

    def subset(self, name: str, purpose: str = PURPOSE_SKELETON) -> tuple:
        """Paths of ``"train"``, ``"validation"`` or ``"all"`` usable for ``purpose``."""
        if name == "train":
            paths = self.train
        elif name == "validation":
            paths = self.validation
        elif name == "all":
            paths = tuple(dict.fromkeys(self.train + self.validation))
        else:
            raise InputError(f"Unknown split {name!r}: use train, validation or all.")
        return tuple(path for path in paths if self.usable_for(path, purpose))


def read_data_split(path: str | os.PathLike) -> DataSplit:
    """Read ``data_split.json``.

    Accepts ``categories`` as ``{path: category}`` or ``{category: [paths]}``;
    ``skeleton_only``, ``excluded`` and ``sides_named_from_the_viewer``
    (``{path: reason}``) are optional.

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
    reasons = {}
    for key, meaning in (("skeleton_only", "their weights are not used"), ("excluded", "they are left out"),
                         ("sides_named_from_the_viewer", "their sides are named from the viewer")):
        value = document.get(key, {})
        if not isinstance(value, dict):
            raise InputError(f"'{path.name}': '{key}' must map paths to the reason {meaning}.")
        reasons[key] = {_split_path(entry): str(reason) for entry, reason in value.items()}
    near_duplicates = document.get("near_duplicates", [])
    if not isinstance(near_duplicates, list) or not all(isinstance(group, list) for group in near_duplicates):
        raise InputError(f"'{path.name}': 'near_duplicates' must be a list of lists of paths.")
    return DataSplit(train, validation, _categories(document.get("categories", {})), reasons["skeleton_only"],
                     reasons["excluded"], _families(document.get("families", []), path.name),
                     tuple(frozenset(_split_path(entry) for entry in group) for group in near_duplicates),
                     reasons["sides_named_from_the_viewer"])


def _split_path(entry) -> str:
    text = entry.get("path", "") if isinstance(entry, dict) else str(entry)
    return Path(text).as_posix()


def _families(raw, file_name: str) -> dict:
    """``{path: family index}`` of the file's ``families`` list (``[{"members": [paths], ...}, ...]``)."""
    if not isinstance(raw, list) or not all(isinstance(family, dict) and isinstance(family.get("members"), list)
                                            for family in raw):
        raise InputError(f"'{file_name}': 'families' must be a list of objects with a 'members' list of paths.")
    return {_split_path(member): index for index, family in enumerate(raw) for member in family["members"]}


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


@dataclass(frozen=True)
class DataItem:
    """One file to evaluate: its path, name and category, and whether the
    split says its artist named the sides from the viewer."""

    path: Path
    name: str
    category: str
    sides_named_from_the_viewer: bool = False


def collect_data(inputs: list[str], split_name: str = "all", split_file: Optional[str] = None,
                 purpose: str = PURPOSE_SKELETON,
                 skipped: Optional[Callable[[str, str], None]] = None) -> list[DataItem]:
    """Files to evaluate, named and categorised.

    A folder contributes every loadable file below it, named by its path
    below the folder without extension; a file is named by its stem. With a
    split other than ``all``, only files listed in that subset of the split
    file are kept (matched by the end of their path, since the split holds
    paths relative to the characters folder). Categories come from the
    split when it lists the file, else from the folder holding the file.
    Files the split says are not usable for ``purpose``
    (:meth:`DataSplit.usable_for`) are left out whatever the subset.

    Parameters
    ----------
    inputs : list of str
        Files and folders.
    split_name : str
        One of :data:`SUBSETS`.
    split_file : str, optional
        The split; default :data:`DEFAULT_SPLIT_FILE`.
    purpose : str
        :data:`PURPOSE_SKELETON` (rig evaluation) or :data:`PURPOSE_SKIN`
        (skin and transfer evaluation, which score against the weights).
    skipped : callable(name, reason), optional
        Told about each file left out for ``purpose``.

    Returns
    -------
    items : list of DataItem
        In the order of ``inputs``, a folder's files sorted by path.

    Raises
    ------
    InputError when nothing is left to evaluate.
    """
    split_path = Path(split_file) if split_file else DEFAULT_SPLIT_FILE
    split = None
    if split_name != "all":
        split = read_data_split(split_path)
    elif split_path.is_file():
        try:
            split = read_data_split(split_path)
        except InputError:
            split = None  # only used for categories here; the folder names serve as well
    wanted = set(split.subset(split_name)) if split is not None else set()
    items = []
    for text in inputs:
        root = Path(text)
        if root.is_dir():
            files = scene_files(root)
            names = [path.relative_to(root).with_suffix("").as_posix() for path in files]
        elif root.is_file():
            files, names = [root], [root.stem]
        else:
            raise InputError(f"'{text}' is neither a file nor a folder.")
        for path, name in zip(files, names):
            entry = split_entry(path, split)
            if split_name != "all" and entry not in wanted:
                continue
            if entry is not None and not split.usable_for(entry, purpose):
                if skipped is not None:
                    skipped(name, split.skeleton_only[entry])
                continue
            category = category_of(entry, split) if entry is not None else path.parent.name
            from_the_viewer = entry is not None and entry in split.sides_named_from_the_viewer
            items.append(DataItem(path, name, category or "uncategorised", from_the_viewer))
    if not items:
        where = ", ".join(inputs)
        if split_name != "all":
            raise InputError(
                f"No file under {where} is in the '{split_name}' split of {split_path.name} "
                "(its paths are relative to the characters folder): pass that folder, or use --split all."
            )
        raise InputError(f"No loadable file found in {where}.")
    return items


def split_entry(path: Path, split: Optional[DataSplit], any_extension: bool = False) -> Optional[str]:
    """The split's relative path naming ``path`` (the longest that ends it, whole folder names), if any;
    ``any_extension``: compared without the extensions (a .blend saved from a listed .glb)."""
    if split is None:
        return None
    text = path.resolve().as_posix()

    def bare(name: str) -> str:
        return os.path.splitext(name)[0] if any_extension else name

    matches = [entry for entry in split.subset("all")
               if bare(text) == bare(entry) or bare(text).endswith("/" + bare(entry))]
    return max(matches, key=len) if matches else None
