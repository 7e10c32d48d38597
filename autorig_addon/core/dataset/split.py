"""The train/validation split of the rigged characters and their names and categories."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Sequence

from ..errors import InputError


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
