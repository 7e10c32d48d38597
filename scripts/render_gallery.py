"""Render a gallery of procedural characters to small PNGs (docs/images/).

One image per character kind, showing several seeds side by side, coloured by
their ground-truth weights (each bone gets a hue; blended vertices blend the
hues), with the bones drawn as thin dark sticks seen through the surface.

Runs headless with Blender as a Python module (Workbench engine):

    .venv/bin/python scripts/render_gallery.py --out docs/images --seeds 5

Each character is scaled to fit one cell of the row; the caption in
docs/data.md gives the seeds.
"""

from __future__ import annotations

import argparse
import colorsys
import os

import bpy
import mathutils
import numpy as np

from autorig_addon.core.procedural import KINDS, generate_character
from docs_render import bone_sticks

#: Image size in pixels (width per character, height).
CELL_PIXELS = 200
IMAGE_HEIGHT = 230
#: Gap between characters in a row, as a fraction of a cell.
CELL_GAP = 0.15
#: Characters (facing -y) are turned by this yaw so the camera sees them three-quarter on.
TURN_DEG = -40.0
TURN = np.array([[np.cos(np.radians(TURN_DEG)), -np.sin(np.radians(TURN_DEG)), 0.0],
                 [np.sin(np.radians(TURN_DEG)), np.cos(np.radians(TURN_DEG)), 0.0], [0.0, 0.0, 1.0]])
#: Camera pitch looking down at the row, degrees.
CAMERA_ELEVATION_DEG = 20.0
#: Background colour (linear RGB).
BACKGROUND = (0.9, 0.9, 0.9)
#: Opacity of the surfaces (Workbench X-ray), so the bones inside show.
XRAY_ALPHA = 0.75
#: Thickness of the bone sticks as a fraction of the character's size.
BONE_STICK_RADIUS = 0.006


def bone_colours(count: int) -> np.ndarray:
    """(count, 3) well-separated colours (golden-ratio hues)."""
    return np.array([colorsys.hsv_to_rgb((k * 0.618034) % 1.0, 0.6, 0.95) for k in range(count)])


def mesh_object(name, vertices, triangles, colours=None):
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(vertices))
    mesh.vertices.foreach_set("co", vertices.astype(np.float32).ravel())
    mesh.loops.add(triangles.size)
    mesh.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
    mesh.polygons.add(len(triangles))
    mesh.polygons.foreach_set("loop_start", np.arange(0, triangles.size, 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(len(triangles), 3, dtype=np.int32))
    mesh.update()
    mesh.validate()
    if colours is not None:
        attribute = mesh.color_attributes.new("weights", "FLOAT_COLOR", "POINT")
        rgba = np.column_stack([colours, np.ones(len(colours))]).astype(np.float32)
        attribute.data.foreach_set("color", rgba.ravel())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def render_row(kind, seeds, path, cell_pixels=CELL_PIXELS):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    x = 0.0
    for seed in seeds:
        character = generate_character(seed, kind)
        vertices = character.mesh.vertices @ TURN.T
        low, high = vertices.min(0), vertices.max(0)
        scale = 1.0 / max(high - low)
        offset = np.array([x - 0.5 * (low[0] + high[0]) * scale, -0.5 * (low[1] + high[1]) * scale, -low[2] * scale])
        colours = character.weights.matrix @ bone_colours(character.skeleton.bone_count)
        mesh_object(f"{kind}_{seed}", vertices * scale + offset, character.mesh.triangles, colours)
        deform = character.skeleton.deform
        stick_vertices, stick_triangles = bone_sticks(character.skeleton.joints[deform] @ TURN.T,
                                                      character.skeleton.tails[deform] @ TURN.T,
                                                      BONE_STICK_RADIUS / scale)
        mesh_object(f"{kind}_{seed}_bones", stick_vertices * scale + offset, stick_triangles,
                    np.full((len(stick_vertices), 3), 0.05))
        x += 1.0 + CELL_GAP
    width = x - CELL_GAP
    camera_data = bpy.data.cameras.new("camera")
    camera_data.type = "ORTHO"
    camera_data.ortho_scale = max(width, 1.0) * 1.08
    camera = bpy.data.objects.new("camera", camera_data)
    scene.collection.objects.link(camera)
    scene.camera = camera
    target = mathutils.Vector((0.5 * (width - 1.0), 0.0, 0.45))
    camera.location = target + mathutils.Vector((0.0, -6.0, 6.0 * np.tan(np.radians(CAMERA_ELEVATION_DEG))))
    camera.rotation_euler = (target - camera.location).to_track_quat("-Z", "Y").to_euler()
    scene.world = bpy.data.worlds.new("background")
    scene.world.color = BACKGROUND
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "VERTEX"
    scene.display.shading.show_object_outline = True
    # See-through surfaces keep the bones inside visible.
    scene.display.shading.show_xray = True
    scene.display.shading.xray_alpha = XRAY_ALPHA
    scene.render.resolution_x = int(cell_pixels * len(seeds))
    scene.render.resolution_y = int(IMAGE_HEIGHT * cell_pixels / CELL_PIXELS)
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.compression = 100
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="docs/images", help="folder for the PNGs")
    parser.add_argument("--seeds", type=int, default=5, help="characters per image")
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--kinds", nargs="*", default=list(KINDS))
    parser.add_argument("--seed-list", type=int, nargs="*", help="exact seeds (overrides --seeds/--first-seed)")
    parser.add_argument("--cell", type=int, default=CELL_PIXELS, help="pixels per character")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    for kind in args.kinds:
        seeds = args.seed_list or list(range(args.first_seed, args.first_seed + args.seeds))
        path = os.path.abspath(os.path.join(args.out, f"procedural_{kind}.png"))
        render_row(kind, seeds, path, args.cell)
        print(path, os.path.getsize(path), "bytes")


if __name__ == "__main__":
    main()
