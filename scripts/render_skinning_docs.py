"""Render the pictures of docs/skinning.md (headless, Workbench engine).

Usage (from the repo root)::

    .venv/bin/python scripts/render_skinning_docs.py [--out docs/images] [CHARACTER.glb ...]

For each character (default: four validation characters of data_split.json)
renders, side by side, the artist's weights, the geometric method's and the
default network's (``core.skinning.methods.DEFAULT_SKIN_METHOD``), each bone
in its own colour and vertices coloured by the weight-blended mix.
"""

from __future__ import annotations

import argparse
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

from autorig_addon.blender.characters import load_character
from autorig_addon.core.skinning.geometric import geometric_weights
from autorig_addon.core.skinning.learned.predict import learned_weights
from autorig_addon.core.skinning.methods import DEFAULT_SKIN_METHOD
from docs_render import (
    CHARACTERS,
    DOC_CHARACTERS,
    bone_palette,
    mesh_from_arrays,
    render,
    save_side_by_side,
    set_colors,
    setup_render,
)

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))



def render_character(path: str, out_dir: str) -> None:
    character = load_character(path)
    deform = character.skeleton.deform_subset()
    ours = geometric_weights(character.mesh, character.skeleton)
    learned = learned_weights(character.mesh, character.skeleton, DEFAULT_SKIN_METHOD)
    artist = character.weights.select_bones(deform.names).matrix
    palette = bone_palette(len(deform.names))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    vertices = character.mesh.vertices
    lo, hi = vertices.min(0), vertices.max(0)
    setup_render(scene, Vector(((lo + hi) / 2).tolist()), float((hi - lo).max()), direction=(0.7, -1.0, 0.35))
    panels = []
    for label, weights in (("artist", artist), ("geometric", ours.select_bones(deform.names).matrix),
                           (DEFAULT_SKIN_METHOD, learned.select_bones(deform.names).matrix)):
        obj = mesh_from_arrays(label, vertices, character.mesh.triangles)
        colors = np.clip(weights @ palette, 0, 1)
        colors[:, 3] = 1.0
        set_colors(obj, colors)
        panels.append(render(scene, [obj], os.path.join(out_dir, "_panel.png"), "VERTEX"))
        bpy.data.objects.remove(obj)
    name = os.path.splitext(os.path.basename(path))[0]
    save_side_by_side(panels, os.path.join(out_dir, f"skinning_{name}.png"))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("characters", nargs="*", default=[os.path.join(CHARACTERS, c) for c in DOC_CHARACTERS])
    parser.add_argument("--out", default=os.path.join(REPO, "docs", "images"))
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    for path in args.characters:
        render_character(path, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
