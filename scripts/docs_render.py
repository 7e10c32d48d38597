"""Headless Workbench rendering helpers shared by the docs render scripts."""

from __future__ import annotations

import math
import os

import bpy
import numpy as np
from mathutils import Quaternion, Vector

#: Pixels of one panel (width, height).
RESOLUTION = (260, 390)
#: The rigged characters of data_split.json, beside the repository.
CHARACTERS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "..", "shared", "data",
                          "characters")
#: The validation characters the skinning and rigging pages picture, paths under :data:`CHARACTERS`.
DOC_CHARACTERS = (
    "quaternius_glb/single_knight_pack/KnightCharacter.glb",
    "quaternius_glb/animals_pack/Wolf.glb",
    "quaternius_glb/dinosaurs_pack/Stegosaurus.glb",
    "kaykit/Rogue_Hooded.glb",
)


def duplicate(obj, name: str):
    copy = obj.copy()
    copy.data = obj.data.copy()
    copy.name = name
    bpy.context.scene.collection.objects.link(copy)
    return copy


def set_pose(armature, pose) -> None:
    for bone_name, axis, degrees in pose:
        bone = armature.pose.bones.get(bone_name)
        if bone is None:
            continue
        bone.rotation_mode = "QUATERNION"
        vector = {"X": (1, 0, 0), "Y": (0, 1, 0), "Z": (0, 0, 1)}[axis]
        bone.rotation_quaternion = Quaternion(vector, math.radians(degrees))
    bpy.context.view_layer.update()


def setup_render(scene, look_at: Vector, height: float, direction=(1.0, -0.8, 0.1)) -> None:
    """Workbench, studio light and an orthographic camera framing ``height``
    around ``look_at``, looking along ``-direction``."""
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.film_transparent = False
    scene.display.shading.light = "STUDIO"
    scene.display.shading.show_cavity = False
    camera_data = bpy.data.cameras.new("DocsCamera")
    camera_data.type = "ORTHO"
    camera_data.ortho_scale = height * 1.1
    camera = bpy.data.objects.new("DocsCamera", camera_data)
    scene.collection.objects.link(camera)
    direction = Vector(direction).normalized()
    camera.location = look_at + direction * 6.0 * max(height, 1e-3)
    camera_data.clip_end = 20.0 * max(height, 1e-3)
    camera.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera


def render(scene, visible, path: str, color_type: str) -> np.ndarray:
    for obj in scene.objects:
        obj.hide_render = obj.type == "MESH" and obj not in visible
    scene.display.shading.color_type = color_type
    scene.display.shading.single_color = (0.8, 0.8, 0.8)
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = np.array(image.pixels[:], dtype=np.float32).reshape(image.size[1], image.size[0], 4)
    bpy.data.images.remove(image)
    os.remove(path)
    return pixels


def save_side_by_side(panels, path: str, alpha: bool = True) -> None:
    """The panels in a row, one PNG (RGB without ``alpha``: a third of the size)."""
    strip = np.concatenate(panels, axis=1)
    image = bpy.data.images.new("strip", strip.shape[1], strip.shape[0], alpha=alpha)
    image.pixels.foreach_set(strip.ravel())
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)
    print("wrote", path)


def heat_colors(values: np.ndarray) -> np.ndarray:
    """(n, 4) blue (0) -> red (1) colours."""
    t = np.clip(values, 0, 1)[:, None]
    blue, red = np.array([0.05, 0.1, 0.9, 1.0]), np.array([0.95, 0.1, 0.05, 1.0])
    return ((1 - t) * blue + t * red).astype(np.float32)


def mesh_from_arrays(name: str, vertices: np.ndarray, triangles: np.ndarray):
    """A new mesh object (linked to the scene) with these world-space triangles."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices.tolist(), [], triangles.tolist())
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def bone_palette(count: int) -> np.ndarray:
    """(count, 4) distinct, saturated RGBA colours, deterministic."""
    hues = (np.arange(count) * 0.61803398875) % 1.0
    rgb = np.stack([np.clip(np.abs((hues * 6 + shift) % 6 - 3) - 1, 0, 1) for shift in (0, 4, 2)], axis=1)
    return np.column_stack([0.15 + 0.85 * rgb, np.ones(count)]).astype(np.float32)


def set_colors(obj, colors: np.ndarray, name: str = "Docs") -> None:
    attribute = obj.data.color_attributes.new(name, "FLOAT_COLOR", "POINT")
    attribute.data.foreach_set("color", colors.ravel())
    obj.data.color_attributes.active_color_name = name


def bone_sticks(joints, tails, radius):
    """Vertices and triangles of a thin octahedron along each bone."""
    vertices, triangles = [], []
    for head, tail in zip(joints, tails):
        axis = tail - head
        length = np.linalg.norm(axis)
        if length < 1e-9:
            continue
        axis /= length
        other = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        side = np.cross(axis, other)
        side /= np.linalg.norm(side)
        up = np.cross(axis, side)
        ring = head + 0.15 * length * axis + radius * np.array([side, up, -side, -up])
        base = sum(len(v) for v in vertices)
        vertices.append(np.vstack([head, ring, tail]))
        for k in range(4):
            a, b = 1 + k, 1 + (k + 1) % 4
            triangles.append([base, base + b, base + a])
            triangles.append([base + a, base + b, base + 5])
    return np.vstack(vertices), np.array(triangles)


#: Colours (RGBA) of bones on the character's left (``.L``), right (``.R``)
#: and midline, and of the text labels.
SIDE_COLORS = {"left": (0.05, 0.3, 0.95, 1.0), "right": (0.9, 0.12, 0.05, 1.0), "mid": (0.05, 0.55, 0.1, 1.0)}
LABEL_COLOR = (0.02, 0.02, 0.02, 1.0)
#: Side suffixes of bone names in the wild (Blender's ``.L``, KayKit's ``.l``, ``_L``).
SIDE_SUFFIXES = {"left": (".l", "_l", "-l", "left"), "right": (".r", "_r", "-r", "right")}


def bone_side(name: str) -> str:
    """``left``, ``right`` or ``mid`` from a bone name's side suffix."""
    lowered = name.lower()
    for side, suffixes in SIDE_SUFFIXES.items():
        if lowered.endswith(suffixes):
            return side
    return "mid"


def sphere_arrays(centres: np.ndarray, radius: float, segments: int = 10) -> tuple:
    """Vertices and triangles of a small UV sphere around each of the (k, 3) centres."""
    rings = segments // 2
    polar = np.linspace(0.0, math.pi, rings + 1)[1:-1]
    azimuth = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    ring = np.stack([np.outer(np.sin(polar), np.cos(azimuth)), np.outer(np.sin(polar), np.sin(azimuth)),
                     np.outer(np.cos(polar), np.ones(segments))], axis=-1).reshape(-1, 3)
    unit = np.vstack([[0.0, 0.0, 1.0], ring, [0.0, 0.0, -1.0]])
    bottom = len(unit) - 1
    faces = []
    for s in range(segments):
        t = (s + 1) % segments
        faces.append([0, 1 + s, 1 + t])
        faces.append([bottom, 1 + (rings - 2) * segments + t, 1 + (rings - 2) * segments + s])
        for r in range(rings - 2):
            a, b = 1 + r * segments, 1 + (r + 1) * segments
            faces += [[a + s, b + s, b + t], [a + s, b + t, a + t]]
    faces = np.array(faces)
    vertices = (np.asarray(centres, dtype=np.float64)[:, None, :] + radius * unit).reshape(-1, 3)
    triangles = (faces[None, :, :] + len(unit) * np.arange(len(centres))[:, None, None]).reshape(-1, 3)
    return vertices, triangles


def skeleton_objects(name: str, joints: np.ndarray, parents: np.ndarray, names, joint_radius: float,
                     bone_radius: float) -> list:
    """Joints as spheres and bones as thin sticks from each parent joint to its
    child, one object per side (:func:`bone_side` of the child's name) in its
    :data:`SIDE_COLORS` object colour (render with ``color_type="OBJECT"``)."""
    objects = []
    sides = np.array([bone_side(bone) for bone in names])
    for side, color in SIDE_COLORS.items():
        chosen = np.flatnonzero(sides == side)
        if not len(chosen):
            continue
        parts = [sphere_arrays(joints[chosen], joint_radius)]
        child = chosen[parents[chosen] >= 0]
        if len(child):
            parts.append(bone_sticks(joints[parents[child]], joints[child], bone_radius))
        vertices = np.vstack([part[0] for part in parts])
        offsets = np.cumsum([0] + [len(part[0]) for part in parts[:-1]])
        triangles = np.vstack([part[1] + offset for part, offset in zip(parts, offsets)])
        obj = mesh_from_arrays(f"{name}_{side}", vertices, triangles)
        obj.color = color
        objects.append(obj)
    return objects


def add_label(scene, text: str, height: float, look_at: Vector):
    """A text object of ``height`` (world units) in the top-left corner of the
    view of the orthographic camera aimed at ``look_at``, facing the camera,
    halfway between the two; remove it before the next panel."""
    camera = scene.camera
    rotation = camera.rotation_euler.to_matrix()
    right, up = rotation.col[0], rotation.col[1]
    visible = camera.data.ortho_scale
    width, tall = scene.render.resolution_x, scene.render.resolution_y
    half_w = 0.5 * visible * min(1.0, width / tall)
    half_h = 0.5 * visible * min(1.0, tall / width)
    curve = bpy.data.curves.new("label", "FONT")
    curve.body = text
    curve.size = height
    obj = bpy.data.objects.new("label", curve)
    obj.color = LABEL_COLOR
    margin = 0.5 * height
    obj.location = (look_at + 0.5 * (camera.location - look_at) - right * (half_w - margin)
                    + up * (half_h - margin - height))
    obj.rotation_euler = camera.rotation_euler
    scene.collection.objects.link(obj)
    return obj
