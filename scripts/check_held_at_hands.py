"""Which objects of the development characters the held-at-hands rule tells
(``core.rigging.held_at_hands``), each file taken whole as ``rig`` takes it.

Usage (from the repo root, with bpy in the venv)::

    .venv/bin/python scripts/check_held_at_hands.py [CHARACTERS_FOLDER] > held.txt

For every .glb of several meshes with faces, read at rest in world space:
the objects :mod:`~autorig_addon.core.rigging.props` tells as props, the
thin and the thick candidates, and those held at the hands. One line per file; files of
several characters are left out, as ``rig`` refuses them.
"""

from __future__ import annotations

import sys
from pathlib import Path

import bpy

from autorig_addon.blender import convert, scene_io
from autorig_addon.core.rigging.character_parts import character_parts
from autorig_addon.core.rigging.held_at_hands import hand_candidates, props_held_at_hands
from autorig_addon.core.rigging.props import rigid_props

DEFAULT_CHARACTERS = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "characters"


def main(folder: Path) -> None:
    for path in sorted(folder.rglob("*.glb")):
        scene_io.load_scene(path)
        objects = sorted((obj for obj in bpy.context.scene.objects if obj.type == "MESH" and len(obj.data.polygons)),
                         key=lambda obj: obj.name)
        if len(objects) < 2:
            continue
        mesh = convert.read_mesh(objects, bpy.context.evaluated_depsgraph_get())
        parts = character_parts(mesh)
        if parts.several:
            continue
        told = [prop.object_index for prop in rigid_props(mesh, parts.left_out) if prop.piece is None]
        candidates = hand_candidates(mesh, parts.left_out, told)
        held = props_held_at_hands(mesh, parts.left_out, told) if candidates else ()
        names = mesh.object_names
        print(f"{path.relative_to(folder)}: {len(objects)} objects, props {[names[index] for index in told]}, "
              f"thin {[names[candidate.object_index] for candidate in candidates if candidate.thin]}, "
              f"thick {[names[candidate.object_index] for candidate in candidates if not candidate.thin]}, "
              f"held {[names[prop.object_index] for prop in held]}", flush=True)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_CHARACTERS)
