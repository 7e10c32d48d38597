"""Render the pictures of docs/rigging.md (headless, Workbench engine).

Usage (from the repo root)::

    .venv/bin/python scripts/render_rigging_docs.py [--out docs/images] [--lod-character PATH] [CHARACTER.glb ...]

1. For each character (default: four validation characters of
   data_split.json), side by side: the artist's deform skeleton, the
   skeleton predicted with the defaults (a known relative's rig, then also
   the skeleton without it; else the standard skeleton of the kind the
   landmark network reads) and the free-form skeleton at
   ``core.rigging.predict.DEFAULT_BANDWIDTH`` -> ``rigging_<Name>.png``.
2. For one character (``--lod-character``, default the knight): the
   free-form prediction at :data:`BANDWIDTHS`, the network run once
   -> ``rigging_bandwidths.png``.

The mesh is see-through grey; joints are spheres and bones thin sticks from
each parent joint to its child, coloured by the child's side: left (``.L``)
blue, right (``.R``) red, midline green (``docs_render.SIDE_COLORS``). The
camera is orthographic: from the front, or from the character's left side
(turned a little toward its front) when the mesh is longer along Y than
along X (a quadruped). Prints the joint count of every prediction.
"""

from __future__ import annotations

import argparse
import os
import sys
from functools import lru_cache

import bpy
import numpy as np
from mathutils import Vector

from autorig_addon.blender.characters import load_character
from autorig_addon.core.geometry.bounding_box import largest_side
from autorig_addon.core.rigging.predict import (
    DEFAULT_BANDWIDTH,
    checked_skeleton,
    chosen_template,
    predict_votes,
    skeleton_from_votes,
)
from autorig_addon.core.rigging.rig_library import KNOWN_RIG
from autorig_addon.core.rigging.standard_skeleton import FREE_FORM
from docs_render import (
    CHARACTERS,
    DOC_CHARACTERS,
    add_label,
    mesh_from_arrays,
    render,
    save_side_by_side,
    setup_render,
    skeleton_objects,
)

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: Levels of detail of the bandwidth picture, share of the largest side:
#: finer than the default, the default, coarser.
BANDWIDTHS = (0.012, DEFAULT_BANDWIDTH, 0.04)
#: Size of each picture in pixels (width of the whole row, greatest height;
#: a long, low character gets a lower picture).
IMAGE_SIZE = (1200, 600)
#: Background colour (linear RGB) behind the see-through mesh.
BACKGROUND = (1.0, 1.0, 1.0)
#: Mesh colour (linear RGBA): light grey, mostly see-through so the skeleton shows.
MESH_COLOR = (0.7, 0.7, 0.7, 0.25)
#: Radius of a joint sphere and of a bone stick, share of the mesh's largest side.
JOINT_RADIUS_SHARE = 0.012
BONE_RADIUS_SHARE = 0.005
#: Height of the label text in pixels; the top LABEL_BAND_PIXELS of a
#: panel are kept free for its two lines.
LABEL_PIXELS = 24
LABEL_BAND_PIXELS = 72
#: Empty space around the character, share of its projected size.
FRAME_MARGIN = 1.1
#: Camera directions (from the character toward the camera): front, and the
#: left side turned a little toward the front so both sides' legs show.
FRONT_VIEW = (0.0, -1.0, 0.0)
SIDE_VIEW = (1.0, -0.3, 0.0)


@lru_cache(maxsize=None)
def character_and_votes(path: str):
    """The loaded character and its joint votes (the slow network run, done once per file)."""
    character = load_character(path)
    return character, predict_votes(character.mesh)


def view_direction(vertices: np.ndarray) -> tuple:
    extent = vertices.max(0) - vertices.min(0)
    return SIDE_VIEW if extent[1] > extent[0] else FRONT_VIEW


def frame(scene, points: np.ndarray, direction, panel_width: int) -> tuple:
    """Aim an orthographic camera along ``-direction`` at ``points`` and size
    the panel (``panel_width`` pixels wide, as tall as the points need below
    the label band, at most ``IMAGE_SIZE[1]``) so that they fill it.

    Returns
    -------
    (look_at Vector, label height in world units)
    """
    toward = -np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    right = np.cross(toward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, toward)
    across, along = points @ right, points @ up
    wide, tall = np.ptp(across) * FRAME_MARGIN, np.ptp(along) * FRAME_MARGIN
    panel_height = int(min(IMAGE_SIZE[1], round(LABEL_BAND_PIXELS + panel_width * tall / wide)))
    # World units per pixel: the wider of the two fits decides.
    unit = max(wide / panel_width, tall / (panel_height - LABEL_BAND_PIXELS))
    centre = (0.5 * (across.min() + across.max()) * right + 0.5 * (along.min() + along.max()) * up
              + np.mean(points @ toward) * toward + 0.5 * LABEL_BAND_PIXELS * unit * up)
    look_at = Vector(centre.tolist())
    setup_render(scene, look_at, float(unit * panel_height), direction=tuple(direction))
    scene.render.resolution_x, scene.render.resolution_y = panel_width, panel_height
    scene.camera.data.ortho_scale = float(unit * max(panel_width, panel_height))
    return look_at, float(LABEL_PIXELS * unit)


def render_panels(character, skeletons, path: str, out_dir: str) -> None:
    """One panel per (label, skeleton) over the see-through mesh, side by side in ``path``."""
    vertices = character.mesh.vertices
    size = largest_side(vertices)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.world = bpy.data.worlds.new("background")
    scene.world.color = BACKGROUND
    # Dither noise on the flat background would triple the PNG's size.
    scene.render.dither_intensity = 0.0
    # Colours as given (AgX, the default, greys the white background).
    scene.view_settings.view_transform = "Standard"
    points = np.vstack([vertices] + [skeleton.joints for _, skeleton in skeletons])
    look_at, label_height = frame(scene, points, view_direction(vertices), IMAGE_SIZE[0] // len(skeletons))
    surface = mesh_from_arrays("surface", vertices, character.mesh.triangles)
    surface.color = MESH_COLOR
    panels = []
    for index, (label, skeleton) in enumerate(skeletons):
        bones = skeleton_objects(f"skeleton{index}", skeleton.joints, skeleton.parents, skeleton.names,
                                 JOINT_RADIUS_SHARE * size, BONE_RADIUS_SHARE * size)
        text = add_label(scene, label, label_height, look_at)
        panels.append(render(scene, [surface] + bones, os.path.join(out_dir, "_panel.png"), "OBJECT"))
        for obj in bones + [text]:
            bpy.data.objects.remove(obj)
    save_side_by_side(panels, path, alpha=False)


def render_comparison(path: str, out_dir: str) -> None:
    character, votes = character_and_votes(path)
    artist = character.skeleton.deform_subset()
    checked = checked_skeleton(votes)  # as Auto-Rig builds it
    standard = checked.skeleton
    kind, note = chosen_template(votes, known_rig=checked.known_rig)
    free_form = skeleton_from_votes(votes, bandwidth=DEFAULT_BANDWIDTH, template=FREE_FORM)
    name = os.path.splitext(os.path.basename(path))[0]
    print(f"{name}: artist {artist.bone_count} deform bones, default ({kind}) {standard.bone_count} bones, "
          f"free-form {free_form.bone_count} joints; {note} {' '.join(votes.notes)}")
    if kind == KNOWN_RIG:  # four panels, short labels: the skeleton without the relative's rig beside it
        unknown = skeleton_from_votes(votes, known_rig=False)
        panels = [(f"artist\n{artist.bone_count} bones", artist), (f"known rig\n{standard.bone_count} bones", standard),
                  (f"{chosen_template(votes, known_rig=False)[0]}\n{unknown.bone_count} bones", unknown),
                  (f"free-form\n{free_form.bone_count} joints", free_form)]
    else:
        panels = [(f"artist\n{artist.bone_count} deform bones", artist),
                  (f"predicted ({kind} template)\n{standard.bone_count} bones", standard),
                  (f"free-form, bandwidth {DEFAULT_BANDWIDTH}\n{free_form.bone_count} joints", free_form)]
    render_panels(character, panels, os.path.join(out_dir, f"rigging_{name}.png"), out_dir)


def render_bandwidths(path: str, out_dir: str) -> None:
    character, votes = character_and_votes(path)
    skeletons = []
    for bandwidth in BANDWIDTHS:
        skeleton = skeleton_from_votes(votes, bandwidth=bandwidth, template=FREE_FORM)
        print(f"{os.path.basename(path)} at bandwidth {bandwidth}: {skeleton.bone_count} joints")
        skeletons.append((f"bandwidth {bandwidth}\n{skeleton.bone_count} joints", skeleton))
    render_panels(character, skeletons, os.path.join(out_dir, "rigging_bandwidths.png"), out_dir)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("characters", nargs="*", default=[os.path.join(CHARACTERS, c) for c in DOC_CHARACTERS])
    parser.add_argument("--lod-character", default=os.path.join(CHARACTERS, DOC_CHARACTERS[0]),
                        help="character of the bandwidth picture")
    parser.add_argument("--out", default=os.path.join(REPO, "docs", "images"))
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    for path in args.characters:
        render_comparison(path, args.out)
    render_bandwidths(args.lod_character, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
