"""Build samples/makehuman_dress.glb: the CC0 makehuman body (armature +
weights) and one unweighted garment in a single file, the README's demo input.

Usage (from the repo root): .venv/bin/python scripts/make_sample.py
"""

import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MAKEHUMAN = os.path.join(REPO, "..", "shared", "data", "makehuman")
GARMENT = "female_elegantsuit01"


def main() -> int:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "body.glb"))
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "garments", GARMENT + ".glb"))
    for obj in list(bpy.data.objects):
        if obj.type == "MESH" and obj.name not in ("Body", GARMENT):
            bpy.data.objects.remove(obj)  # the importer's bone-shape helper
    out = os.path.join(REPO, "samples", "makehuman_dress.glb")
    bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_skins=True,
                              export_animations=False, export_materials="NONE")
    print("wrote", out, os.path.getsize(out) // 1024, "KiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
