"""The skins of a glTF file read without Blender: joint names, parents and which joints carry weight.

What the data split needs to tell which characters share a rig
(``core.dataset.families``): every skin's joints by name, each joint's parent
inside the skin, and whether any vertex weights the joint. Reads ``.glb``
(the binary chunk) and ``.gltf`` (``.bin`` buffers beside it) with numpy.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import unquote

import numpy as np

from ..errors import InputError
from .glb import read_glb

#: numpy types of glTF accessor component types.
COMPONENT_TYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
#: Components per element of glTF accessor types.
ELEMENT_SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
#: A joint carries weight when some vertex gives it more than this.
WEIGHT_EPSILON = 1e-4
#: Where a file records the skeleton it was made for (the 0 A.D. conversions do).
DECLARED_SKELETON_KEY = "skeleton"


@dataclass(frozen=True)
class SkinRig:
    """One skin of a glTF file.

    Attributes
    ----------
    names : tuple of str, the joints in the skin's order
    parents : tuple of int, each joint's parent as an index into ``names`` (-1: none inside the skin)
    weighted : tuple of bool, whether some vertex bound to this skin weights the joint
    """

    names: tuple
    parents: tuple
    weighted: tuple


def read_gltf(path: str | Path) -> tuple[dict, list[bytes]]:
    """A glTF file's JSON document and its buffers' bytes, in ``buffers`` order.

    A ``.glb`` file's first buffer is its binary chunk; a ``.gltf`` file's
    buffers are read from the files its ``uri`` names, beside it.

    Raises
    ------
    InputError for a file that is not glTF or a missing buffer.
    """
    path = Path(path)
    if path.suffix.lower() == ".glb":
        document, binary = read_glb(path)
        return document, [binary]
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise InputError(f"'{path.name}' is not a readable glTF file: {error}") from None
    buffers = []
    for buffer in document.get("buffers", []):
        uri = buffer.get("uri", "")
        if uri.startswith("data:") or not uri:
            raise InputError(f"'{path.name}' embeds a buffer as a data URI, which this reader does not decode.")
        source = path.parent / unquote(uri)
        if not source.is_file():
            raise InputError(f"'{path.name}' needs the buffer '{uri}', which is not beside it.")
        buffers.append(source.read_bytes())
    return document, buffers


def accessor_array(document: dict, buffers: list[bytes], index: int) -> np.ndarray:
    """The elements of accessor ``index`` as an ``(count, components)`` array
    (normalised integers stay integers; sparse accessors are not read)."""
    accessor = document["accessors"][index]
    view = document["bufferViews"][accessor["bufferView"]]
    dtype = np.dtype(COMPONENT_TYPES[accessor["componentType"]])
    components = ELEMENT_SIZES[accessor["type"]]
    count = accessor["count"]
    offset = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    element_bytes = dtype.itemsize * components
    stride = view.get("byteStride") or element_bytes
    data = np.frombuffer(buffers[view.get("buffer", 0)], dtype=np.uint8)
    rows = np.lib.stride_tricks.as_strided(data[offset:], (count, element_bytes), (stride, 1)) if count else \
        np.zeros((0, element_bytes), np.uint8)
    return np.ascontiguousarray(rows).view(dtype).reshape(count, components)


def normalised_weights(document: dict, buffers: list[bytes], index: int) -> np.ndarray:
    """A ``WEIGHTS_n`` accessor as floats (unsigned bytes and shorts are
    normalised integers by the glTF specification)."""
    values = accessor_array(document, buffers, index)
    if values.dtype.kind == "u":
        return values / float(np.iinfo(values.dtype).max)
    return values.astype(np.float64)


def skin_rigs(document: dict, buffers: list[bytes]) -> tuple[SkinRig, ...]:
    """The skins of a glTF file (:func:`read_gltf`), with the joints some vertex weights (see :class:`SkinRig`)."""
    nodes = document.get("nodes", [])
    parent_node = {child: index for index, node in enumerate(nodes) for child in node.get("children", [])}
    skins = document.get("skins", [])
    weighted = [np.zeros(len(skin["joints"]), dtype=bool) for skin in skins]
    for node in nodes:
        if "mesh" not in node or "skin" not in node:
            continue
        for primitive in document["meshes"][node["mesh"]].get("primitives", []):
            attributes = primitive.get("attributes", {})
            layer = 0
            while f"JOINTS_{layer}" in attributes and f"WEIGHTS_{layer}" in attributes:
                joints = accessor_array(document, buffers, attributes[f"JOINTS_{layer}"]).astype(np.int64)
                weights = normalised_weights(document, buffers, attributes[f"WEIGHTS_{layer}"])
                used = joints[weights > WEIGHT_EPSILON]
                weighted[node["skin"]][used[used < len(weighted[node["skin"]])]] = True
                layer += 1
    rigs = []
    for skin, used in zip(skins, weighted):
        joints = list(skin["joints"])
        position = {node: k for k, node in enumerate(joints)}
        names = tuple(str(nodes[node].get("name", f"node_{node}")) for node in joints)
        parents = tuple(position.get(parent_node.get(node, -1), -1) for node in joints)
        rigs.append(SkinRig(names, parents, tuple(bool(flag) for flag in used)))
    return tuple(rigs)


def declared_skeleton(document: dict) -> str:
    """The skeleton a glTF document says it was made for (``asset.extras.skeleton``), or ``""``."""
    extras = document.get("asset", {}).get("extras") or {}
    return str(extras.get(DECLARED_SKELETON_KEY, "")) if isinstance(extras, dict) else ""
