"""Binary and text glTF files read, and rewritten without their animations.

:func:`read_glb` gives a binary file's JSON document and binary chunk. The
glTF importer poses a skeleton at frame 0 of the first clip; a copy without
``animations`` imports in the file's default pose (the joints' node
transforms), which the bind-pose check compares with the rest pose. Plain
JSON and bytes, no Blender.
"""

from __future__ import annotations

import json
import os
import struct
from pathlib import Path
from urllib.parse import quote, unquote

from ..errors import InputError

#: "glTF" in little-endian bytes, the first word of every .glb file.
GLB_MAGIC = 0x46546C67
#: Chunk type of the JSON chunk ("JSON").
GLB_JSON_CHUNK = 0x4E4F534A
#: File header (magic, version, total length) and chunk header (length, type).
GLB_HEADER = struct.Struct("<III")
GLB_CHUNK_HEADER = struct.Struct("<II")


#: Chunk type of the binary buffer chunk ("BIN").
GLB_BINARY_CHUNK = 0x004E4942


def _glb_json(data: bytes, name: str) -> tuple[dict, int]:
    """The JSON document of a binary glTF file's bytes and where its JSON chunk ends."""
    if len(data) < GLB_HEADER.size + GLB_CHUNK_HEADER.size:
        raise InputError(f"'{name}' is not a binary glTF file (too short).")
    magic, _, _ = GLB_HEADER.unpack_from(data, 0)
    if magic != GLB_MAGIC:
        raise InputError(f"'{name}' is not a binary glTF file (bad magic number).")
    json_length, json_type = GLB_CHUNK_HEADER.unpack_from(data, GLB_HEADER.size)
    if json_type != GLB_JSON_CHUNK:
        raise InputError(f"'{name}' does not start with a JSON chunk.")
    json_start = GLB_HEADER.size + GLB_CHUNK_HEADER.size
    document = json.loads(data[json_start:json_start + json_length].decode("utf-8"))
    return document, json_start + json_length


def read_glb(path: Path) -> tuple[dict, bytes]:
    """The JSON document and the binary chunk (``b""`` when there is none) of a binary glTF file."""
    data = Path(path).read_bytes()
    document, json_end = _glb_json(data, Path(path).name)
    binary = b""
    if len(data) >= json_end + GLB_CHUNK_HEADER.size:
        length, kind = GLB_CHUNK_HEADER.unpack_from(data, json_end)
        if kind == GLB_BINARY_CHUNK:
            start = json_end + GLB_CHUNK_HEADER.size
            binary = data[start:start + length]
    return document, binary


def glb_without_animations(source: Path, target: Path) -> None:
    """Copy the binary glTF ``source`` to ``target`` without its ``animations``."""
    data = source.read_bytes()
    document, json_end = _glb_json(data, source.name)
    _, version, _ = GLB_HEADER.unpack_from(data, 0)
    document.pop("animations", None)
    text = json.dumps(document).encode("utf-8")
    text += b" " * (-len(text) % 4)
    rest = data[json_end:]
    total = GLB_HEADER.size + GLB_CHUNK_HEADER.size + len(text) + len(rest)
    target.write_bytes(
        GLB_HEADER.pack(GLB_MAGIC, version, total) + GLB_CHUNK_HEADER.pack(len(text), GLB_JSON_CHUNK) + text + rest
    )


def gltf_without_animations(source: Path, target: Path) -> None:
    """Copy the text glTF ``source`` to ``target`` (another folder) without its
    ``animations``, its buffer and image references pointing back to ``source``'s folder."""
    document = json.loads(source.read_text(encoding="utf-8"))
    document.pop("animations", None)
    # The copy lives elsewhere, so its relative references must point back.
    for collection in ("buffers", "images"):
        for item in document.get(collection, []):
            uri = item.get("uri", "")
            if uri and not uri.startswith("data:"):
                item["uri"] = uri_from(target.parent, source.parent / unquote(uri))
    target.write_text(json.dumps(document), encoding="utf-8")


def uri_from(folder: Path, path: Path) -> str:
    """``path`` relative to ``folder`` as a glTF URI (absolute across drives)."""
    try:
        return quote(Path(os.path.relpath(path.resolve(), folder.resolve())).as_posix())
    except ValueError:
        return quote(path.resolve().as_posix())
