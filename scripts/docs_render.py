"""Headless Workbench rendering helpers shared by the docs render scripts."""

from __future__ import annotations

import math
import os

import bpy
import numpy as np
from mathutils import Quaternion, Vector

#: Pixels of one panel (width, height).
RESOLUTION = (260, 390)


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


def save_side_by_side(panels, path: str) -> None:
    strip = np.concatenate(panels, axis=1)
    image = bpy.data.images.new("strip", strip.shape[1], strip.shape[0], alpha=True)
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
