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
import os
import sys

import bpy
from mathutils import Vector

from autorig_addon.blender.armature_binding import find_armature
from autorig_addon.blender.convert import deform_bone_names, read_mesh, read_weights
from autorig_addon.blender.status_attribute import write_status_attribute
from autorig_addon.blender.weight_writer import write_weights
from autorig_addon.core.transfer import transfer_weights
from autorig_addon.core.transfer.matching import closest_point_weights
from docs_render import duplicate, heat_colors, render, save_side_by_side, set_colors, set_pose, setup_render

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

MAKEHUMAN = os.path.join(REPO, "..", "shared", "data", "makehuman")
#: Pose used for the comparison: (bone, axis, degrees) in the bone's local frame.
POSE = [
    ("upperleg01.L", "X", -45.0),
    ("upperleg01.R", "X", 30.0),
    ("lowerleg01.R", "X", 35.0),
]


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
