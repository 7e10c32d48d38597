"""glTF copies without animations (autorig_addon.core.io.glb), checked byte by byte."""

import json

import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.io.glb import (
    GLB_CHUNK_HEADER,
    GLB_HEADER,
    GLB_JSON_CHUNK,
    GLB_MAGIC,
    glb_without_animations,
    gltf_without_animations,
)

BINARY_CHUNK = 0x004E4942  # "BIN"


def write_glb(path, document: dict, binary: bytes) -> None:
    text = json.dumps(document).encode("utf-8")
    text += b" " * (-len(text) % 4)
    chunks = (GLB_CHUNK_HEADER.pack(len(text), GLB_JSON_CHUNK) + text
              + GLB_CHUNK_HEADER.pack(len(binary), BINARY_CHUNK) + binary)
    path.write_bytes(GLB_HEADER.pack(GLB_MAGIC, 2, GLB_HEADER.size + len(chunks)) + chunks)


def read_glb(path) -> tuple:
    data = path.read_bytes()
    magic, version, total = GLB_HEADER.unpack_from(data, 0)
    length, kind = GLB_CHUNK_HEADER.unpack_from(data, GLB_HEADER.size)
    start = GLB_HEADER.size + GLB_CHUNK_HEADER.size
    return magic, version, total, len(data), kind, json.loads(data[start:start + length]), data[start + length:]


def test_glb_copy_drops_animations_and_keeps_the_rest(tmp_path):
    document = {"asset": {"version": "2.0"}, "nodes": [{"name": "hips"}], "animations": [{"name": "Walk"}]}
    binary = bytes(range(8))
    write_glb(tmp_path / "in.glb", document, binary)
    glb_without_animations(tmp_path / "in.glb", tmp_path / "out.glb")
    magic, version, total, size, kind, copied, rest = read_glb(tmp_path / "out.glb")
    assert (magic, version, kind) == (GLB_MAGIC, 2, GLB_JSON_CHUNK)
    assert total == size and (total - GLB_HEADER.size) % 4 == 0
    assert copied == {"asset": {"version": "2.0"}, "nodes": [{"name": "hips"}]}
    assert rest == GLB_CHUNK_HEADER.pack(8, BINARY_CHUNK) + binary


def test_glb_copy_refuses_a_file_that_is_not_glb(tmp_path):
    (tmp_path / "fake.glb").write_bytes(b"PK\x03\x04" + bytes(20))
    with pytest.raises(InputError, match="'fake.glb' is not a binary glTF file"):
        glb_without_animations(tmp_path / "fake.glb", tmp_path / "out.glb")


def test_gltf_copy_points_its_buffers_back_to_the_source_folder(tmp_path):
    source_folder, target_folder = tmp_path / "assets" / "hero", tmp_path / "scratch"
    source_folder.mkdir(parents=True)
    target_folder.mkdir()
    document = {
        "buffers": [{"uri": "hero%20mesh.bin"}, {"uri": "data:application/octet-stream;base64,AAAA"}],
        "images": [{"uri": "textures/skin.png"}],
        "animations": [{"name": "Idle"}],
    }
    (source_folder / "hero.gltf").write_text(json.dumps(document), encoding="utf-8")
    gltf_without_animations(source_folder / "hero.gltf", target_folder / "hero.gltf")
    copied = json.loads((target_folder / "hero.gltf").read_text(encoding="utf-8"))
    assert "animations" not in copied
    assert copied["buffers"] == [{"uri": "../assets/hero/hero%20mesh.bin"}, document["buffers"][1]]
    assert copied["images"] == [{"uri": "../assets/hero/textures/skin.png"}]
