"""Binary glTF files with skins, written byte by byte (no Blender)."""

import json

import numpy as np

from autorig_addon.core.io.glb import GLB_BINARY_CHUNK, GLB_CHUNK_HEADER, GLB_HEADER, GLB_JSON_CHUNK, GLB_MAGIC


def write_glb(path, document: dict, binary: bytes) -> None:
    """A .glb of ``document`` (its one buffer being ``binary``), chunks padded to 4 bytes."""
    text = json.dumps(document).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    chunks = (GLB_CHUNK_HEADER.pack(len(text), GLB_JSON_CHUNK) + text
              + GLB_CHUNK_HEADER.pack(len(binary), GLB_BINARY_CHUNK) + binary)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(GLB_HEADER.pack(GLB_MAGIC, 2, GLB_HEADER.size + len(chunks)) + chunks)


def skinned_document(names, parents, joints: np.ndarray, weights: np.ndarray, extras=None,
                     buffer_uri=None) -> tuple[dict, bytes]:
    """A glTF document of one skinned point set and the bytes of its buffer.

    Parameters
    ----------
    names, parents : the skin's joints and each one's parent (-1: a root)
    joints : (n, 4) uint8, the JOINTS_0 of ``n`` vertices
    weights : (n, 4) uint8, their WEIGHTS_0 (normalised unsigned bytes: 255 is 1)
    extras : dict for ``asset.extras``, optional
    buffer_uri : the buffer's file for a .gltf; None for a .glb's binary chunk
    """
    count = len(joints)
    positions = np.column_stack([np.arange(count), np.zeros(count), np.zeros(count)]).astype(np.float32)
    binary = positions.tobytes() + np.asarray(joints, np.uint8).tobytes() + np.asarray(weights, np.uint8).tobytes()
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 12 * count},
             {"buffer": 0, "byteOffset": 12 * count, "byteLength": 4 * count},
             {"buffer": 0, "byteOffset": 16 * count, "byteLength": 4 * count}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3"},
                 {"bufferView": 1, "componentType": 5121, "count": count, "type": "VEC4"},
                 {"bufferView": 2, "componentType": 5121, "count": count, "type": "VEC4", "normalized": True}]
    nodes = [{"name": name} for name in names]
    for joint, parent in enumerate(parents):
        if parent >= 0:
            nodes[parent].setdefault("children", []).append(joint)
    nodes.append({"name": "body", "mesh": 0, "skin": 0})
    buffer = {"byteLength": len(binary)}
    if buffer_uri:
        buffer["uri"] = buffer_uri
    asset = {"version": "2.0"}
    if extras:
        asset["extras"] = extras
    document = {
        "asset": asset, "nodes": nodes, "skins": [{"joints": list(range(len(names)))}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}}]}],
        "buffers": [buffer], "bufferViews": views, "accessors": accessors,
    }
    return document, binary


def write_rig_glb(path, names, parents, extras=None) -> None:
    """A .glb whose every joint carries the whole weight of one vertex."""
    count = len(names)
    joints = np.zeros((count, 4), np.uint8)
    joints[:, 0] = np.arange(count)
    weights = np.zeros((count, 4), np.uint8)
    weights[:, 0] = 255
    write_glb(path, *skinned_document(names, parents, joints, weights, extras))
