"""Network weight files: a flat ``{name: array}`` dict in a compressed ``.npz``.

The names are the torch ``state_dict`` keys of the trained module
(``autorig_addon.training.nn.modules.module_weights`` writes them),
so the numpy forward pass reads the names the torch module wrote. Two
reserved entries travel with the arrays: the file format version
(:data:`WEIGHTS_FORMAT_VERSION`) and a JSON metadata dict (the network's
name and the settings needed to rebuild it, the training run). The file is
written to a temporary name and then renamed, so a failed save never
leaves a half-written file under the final name. Numpy only: Blender loads
these.

The shipped networks are saved at half precision (``half_precision=True``):
it halves the extension's weight files (issue 18 keeps the zip under 40 MB)
and moves the validation scores by less than 0.001 (docs/models.md,
"Half-precision weights"). Half-precision arrays load as float32, which is what
the forward pass computes in.
"""

from __future__ import annotations

import json
import os
import tempfile
import zipfile
from typing import NamedTuple, Optional

import numpy as np

from ..errors import InputError

#: Version of the file layout; raise it when the layout changes, and make
#: :func:`load_weights` read the old versions it still accepts.
WEIGHTS_FORMAT_VERSION = 1
#: Reserved array names (a double underscore starts no ``state_dict`` key).
FORMAT_VERSION_KEY = "__format_version__"
METADATA_KEY = "__metadata__"


class LoadedWeights(NamedTuple):
    """A weights file's contents: ``weights`` (name -> array) and
    ``metadata`` (the JSON dict saved with them, ``{}`` when none)."""

    weights: dict
    metadata: dict


#: Permissions a saved weights file gets before the umask: rw-r--r--.
_NEW_FILE_MODE = 0o644


def _current_umask() -> int:
    """The process's umask (reading it means setting it; it is put back at once)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _at_half_precision(array: np.ndarray) -> np.ndarray:
    """``array`` as float16 when it is a floating-point matrix (two axes or
    more) and float16 holds its every value finitely; as it is otherwise
    (integers, flags, the rare matrix beyond float16's range of 65504).
    Vectors stay whole: biases and a normalisation's running mean and
    variance are a sliver of a network's size, and a mean subtracted from
    features of small variance would carry its rounding into every output."""
    if array.dtype.kind != "f" or array.dtype.itemsize <= 2 or array.ndim < 2:
        return array
    with np.errstate(over="ignore"):  # an overflow is what the test below catches
        halved = array.astype(np.float16)
    return halved if np.array_equal(np.isfinite(halved), np.isfinite(array)) else array


def save_weights(path: str, weights: dict, metadata: Optional[dict] = None, half_precision: bool = False) -> None:
    """Write ``weights`` (and ``metadata``) to ``path``.

    Parameters
    ----------
    path : str
        Destination, conventionally ``NAME.npz`` (used as given).
    weights : dict of str -> array
        Numeric or boolean arrays; names must not start with ``__``.
    metadata : dict, optional
        JSON-serialisable settings saved beside the arrays.
    half_precision : bool
        Store floating-point matrices as float16 where it holds them
        (:func:`_at_half_precision`; vectors stay whole); they load back as float32.

    Raises
    ------
    ValueError
        A reserved or non-string name, or a non-numeric array.
    TypeError
        Metadata that JSON cannot hold. (Both are programming errors;
        nothing is written.)
    """
    arrays = {}
    for name, value in weights.items():
        if not isinstance(name, str) or not name or name.startswith("__") or "/" in name:
            raise ValueError(f"Invalid weight name {name!r}: a non-empty string without '/' not starting with '__'.")
        array = np.asarray(value)
        if array.dtype.kind not in "biuf":
            raise ValueError(f"Weight {name!r} has dtype {array.dtype}; only numeric arrays are saved.")
        arrays[name] = _at_half_precision(array) if half_precision else array
    arrays[FORMAT_VERSION_KEY] = np.asarray(WEIGHTS_FORMAT_VERSION, dtype=np.int64)
    arrays[METADATA_KEY] = np.asarray(json.dumps(metadata or {}, sort_keys=True))
    folder = os.path.dirname(os.path.abspath(path))
    handle, temporary = tempfile.mkstemp(prefix=".weights_", suffix=".npz", dir=folder)
    try:
        with os.fdopen(handle, "wb") as stream:
            np.savez_compressed(stream, **arrays)
        # mkstemp creates the file readable by its owner alone; a saved file
        # gets the usual permissions (read and write for the owner, read for
        # others, less the umask), as open() would give it.
        os.chmod(temporary, _NEW_FILE_MODE & ~_current_umask())
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise


def load_weights(path: str) -> LoadedWeights:
    """Read a file written by :func:`save_weights`.

    Raises
    ------
    InputError
        The file does not exist, is not a weights file, or has a format
        version this add-on does not read; the message names the file.
    """
    if not os.path.isfile(path):
        raise InputError(f"Network weights file {path} does not exist.")
    try:
        archive = np.load(path, allow_pickle=False)
        if not isinstance(archive, np.lib.npyio.NpzFile):  # a plain .npy array
            raise ValueError("a single array, not an .npz archive")
        with archive:
            arrays = {name: archive[name] for name in archive.files}
        arrays = {name: array.astype(np.float32) if array.dtype == np.float16 else array
                  for name, array in arrays.items()}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as error:
        raise InputError(f"{path} is not a network weights file ({error}).") from None
    if FORMAT_VERSION_KEY not in arrays or METADATA_KEY not in arrays:
        raise InputError(f"{path} is not a network weights file (no format version or metadata entry).")
    try:
        version = int(arrays.pop(FORMAT_VERSION_KEY))
        metadata = json.loads(str(arrays.pop(METADATA_KEY)))
    except (TypeError, ValueError) as error:  # json.JSONDecodeError is a ValueError
        raise InputError(f"{path} is not a network weights file (unreadable version or metadata: {error}).") from None
    if version != WEIGHTS_FORMAT_VERSION:
        raise InputError(
            f"{path} holds weights in format {version}, but this add-on reads format {WEIGHTS_FORMAT_VERSION}; "
            "use weights trained for this version of the add-on."
        )
    return LoadedWeights(arrays, metadata)
