"""Render the pictures of docs/transfer.md (headless, Workbench engine).

Usage (from the repo root)::

    .venv/bin/python scripts/render_transfer_docs.py [--garment male_casualsuit01] [--out docs/images]

Loads the makehuman body and a garment from ``../shared/data/makehuman``,
weights the garment twice (plain closest-point copy and robust transfer),
poses the body and renders, side by side: the posed garments, the
copied/inpainted status, and the weight of one bone as a heat map.
"""

from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, REPO)

import bpy  # noqa: E402
from mathutils import Quaternion, Vector  # noqa: E402

from autorig_addon.blender.convert import (  # noqa: E402
    deform_bone_names,
    find_armature,
    read_mesh,
    read_weights,
    write_status_attribute,
    write_weights,
)
from autorig_addon.core.closest_point import TriangleMeshQuery  # noqa: E402
from autorig_addon.core.transfer import transfer_weights  # noqa: E402
from autorig_addon.core.types import Weights  # noqa: E402
from autorig_addon.core.weights import normalize_rows  # noqa: E402

MAKEHUMAN = os.path.join(REPO, "..", "shared", "data", "makehuman")
#: Pose used for the comparison: (bone, axis, degrees) in the bone's local frame.
POSE = [
    ("upperleg01.L", "X", -45.0),
    ("upperleg01.R", "X", 30.0),
    ("lowerleg01.R", "X", 35.0),
]
RESOLUTION = (260, 390)


def closest_point_weights(source, source_weights: Weights, target) -> Weights:
    surface = TriangleMeshQuery(source.vertices, source.triangles).closest(target.vertices)
    return Weights(normalize_rows(surface.interpolate(source.triangles, source_weights.matrix)), source_weights.bone_names)


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


def setup_render(scene, look_at: Vector, height: float) -> None:
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
    direction = Vector((1.0, -0.8, 0.1)).normalized()
    camera.location = look_at + direction * 6.0
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


def set_colors(obj, colors: np.ndarray, name: str = "Docs") -> None:
    attribute = obj.data.color_attributes.new(name, "FLOAT_COLOR", "POINT")
    attribute.data.foreach_set("color", colors.ravel())
    obj.data.color_attributes.active_color_name = name


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--garment", default="female_elegantsuit01")
    parser.add_argument("--bone", default="upperleg01.L", help="bone shown in the heat map")
    parser.add_argument("--out", default=os.path.join(REPO, "docs", "images"))
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "body.glb"))
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "garments", args.garment + ".glb"))
    scene = bpy.context.scene
    body = bpy.data.objects["Body"]
    garment = bpy.data.objects[args.garment]
    armature = find_armature(body)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    source = read_mesh([body], depsgraph)
    source_weights = read_weights(body, deform_bone_names(armature))
    target = read_mesh([garment], depsgraph)

    copied = closest_point_weights(source, source_weights, target)
    robust = transfer_weights(source, source_weights, target)
    print(robust.summary())
    copy_obj = duplicate(garment, "closest_point_copy")
    robust_obj = duplicate(garment, "robust_transfer")
    write_weights(copy_obj, copied, armature)
    write_weights(robust_obj, robust.weights, armature)
    write_status_attribute(robust_obj, robust.status)
    garment.hide_render = True

    lo, hi = source.vertices.min(0), source.vertices.max(0)
    setup_render(scene, Vector(((lo + hi) / 2).tolist()), float(hi[2] - lo[2]))
    tmp = os.path.join(args.out, "_panel.png")

    column = list(source_weights.bone_names).index(args.bone)
    set_colors(copy_obj, heat_colors(copied.matrix[:, column]))
    heat_copy = render(scene, [body, copy_obj], tmp, "VERTEX")
    set_colors(robust_obj, heat_colors(robust.weights.matrix[:, column]), "DocsHeat")
    heat_robust = render(scene, [body, robust_obj], tmp, "VERTEX")
    robust_obj.data.color_attributes.active_color_name = "AutoRig Transfer"
    status = render(scene, [body, robust_obj], tmp, "VERTEX")
    save_side_by_side([heat_copy, heat_robust, status], os.path.join(args.out, f"transfer_{args.garment}_weights.png"))

    set_pose(armature, POSE)
    posed_copy = render(scene, [body, copy_obj], tmp, "SINGLE")
    posed_robust = render(scene, [body, robust_obj], tmp, "SINGLE")
    save_side_by_side([posed_copy, posed_robust], os.path.join(args.out, f"transfer_{args.garment}_posed.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
