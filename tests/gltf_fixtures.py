"""glTF files with skins (binary .glb, or .gltf with the buffer embedded), written byte by byte (no Blender)."""

import base64
import json

import numpy as np

from autorig_addon.core.io.glb import GLB_BINARY_CHUNK, GLB_CHUNK_HEADER, GLB_HEADER, GLB_JSON_CHUNK, GLB_MAGIC
from geometry_fixtures import box_mesh

#: Grid spacing of the boxes of write_box_character_gltf, scene units.
BOX_SPACING = 0.03


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


def _y_up(points) -> np.ndarray:
    """Blender's Z-up coordinates as glTF's Y-up ones."""
    points = np.asarray(points, float)
    return np.stack([points[..., 0], points[..., 2], -points[..., 1]], axis=-1)


def write_box_character_gltf(path, bones) -> None:
    """A .gltf (buffer embedded) of boxes skinned rigidly to joints whose frames
    are never turned (no node rotation), as Kenney's minis are exported.

    Parameters
    ----------
    bones : sequence of (name, parent index or -1, head in Blender's Z-up
        coordinates, (low, high) corners of the box it carries or None)
    """
    positions, triangles, owners = [], [], []
    for joint, (_, _, _, extent) in enumerate(bones):
        if extent is None:
            continue
        box = box_mesh(*extent, BOX_SPACING)
        triangles.append(box.triangles + sum(len(block) for block in positions))
        positions.append(box.vertices)
        owners += [joint] * box.vertex_count
    positions = _y_up(np.vstack(positions)).astype(np.float32)
    indices = np.vstack(triangles).astype(np.uint16).ravel()
    joint_ids = np.zeros((len(positions), 4), np.uint8)
    joint_ids[:, 0] = owners
    weights = np.zeros((len(positions), 4), np.float32)
    weights[:, 0] = 1.0
    heads = _y_up([head for _, _, head, _ in bones])
    inverse_binds = []
    for head in heads:
        matrix = np.eye(4)
        matrix[:3, 3] = -head
        inverse_binds.append(matrix.T.ravel())  # glTF matrices are column-major
    nodes = [{"name": name, "translation": [float(x) for x in heads[joint] - (heads[parent] if parent >= 0 else 0)]}
             for joint, (name, parent, _, _) in enumerate(bones)]
    for joint, (_, parent, _, _) in enumerate(bones):
        if parent >= 0:
            nodes[parent].setdefault("children", []).append(joint)
    roots = [joint for joint, (_, parent, _, _) in enumerate(bones) if parent < 0]
    write_skinned_gltf(path, nodes, roots, list(range(len(bones))), positions, joint_ids, weights, indices,
                       inverse_binds)


def write_skinned_gltf(path, nodes, roots, joints, positions, joint_ids, weights, indices, inverse_binds) -> None:
    """A .gltf, its buffer embedded, of one skinned triangle mesh ``Body`` added after ``nodes``.

    Parameters
    ----------
    nodes : list of glTF node dicts (an armature node, joints; ``children`` index among them)
    roots : indices of the scene's root nodes among ``nodes``
    joints : indices of the skin's joints among ``nodes``, in skin order; the first is its skeleton
    positions : (n, 3) float32, glTF's Y-up; joint_ids : (n, 4) uint8; weights : (n, 4) float32
    indices : (3m,) uint16 triangle corners
    inverse_binds : one (16,) column-major matrix per joint of the skin
    """
    blobs = [positions.tobytes(), joint_ids.tobytes(), weights.tobytes(), indices.tobytes(),
             np.array(inverse_binds, np.float32).tobytes()]
    padded = [blob + b"\0" * (-len(blob) % 4) for blob in blobs]
    offsets = np.cumsum([0] + [len(blob) for blob in padded])
    buffer = b"".join(padded)
    nodes = list(nodes) + [{"name": "Body", "mesh": 0, "skin": 0}]
    document = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(roots) + [len(nodes) - 1]}], "nodes": nodes,
        "meshes": [{"name": "Body", "primitives": [
            {"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}, "indices": 3}]}],
        "skins": [{"joints": joints, "inverseBindMatrices": 4, "skeleton": joints[0]}],
        "buffers": [{"byteLength": len(buffer),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(buffer).decode("ascii")}],
        "bufferViews": [{"buffer": 0, "byteOffset": int(offset), "byteLength": len(blob)}
                        for offset, blob in zip(offsets, blobs)],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
             "min": positions.min(0).tolist(), "max": positions.max(0).tolist()},
            {"bufferView": 1, "componentType": 5121, "count": len(positions), "type": "VEC4"},
            {"bufferView": 2, "componentType": 5126, "count": len(positions), "type": "VEC4"},
            {"bufferView": 3, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
            {"bufferView": 4, "componentType": 5126, "count": len(inverse_binds), "type": "MAT4"},
        ],
    }
    path.write_text(json.dumps(document), encoding="utf-8")
