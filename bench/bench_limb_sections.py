"""Benchmark the limb-middle step of the standard biped skeleton (core/rigging/limb_sections.py).

Usage (from the repo root)::

    .venv/bin/python bench/bench_limb_sections.py [--repeat 7]

Runs :func:`limb_joints_centred` (six plane sections of the whole mesh: the
elbows, wrists and knees) on the procedural biped of seed 0 and on it
subdivided once to three times (each triangle split in four), at its own joints,
and prints the median and range of ``--repeat`` runs per size.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from autorig_addon.core.geometry.subdivision import subdivide_midpoints
from autorig_addon.core.procedural import generate_character
from autorig_addon.core.rigging.limb_sections import limb_joints_centred
from autorig_addon.core.types import Mesh

#: The landmark roles read from the generator's own bones (each bone's head).
ROLE_BONES = {"shoulder": "upper_arm", "elbow": "forearm", "wrist": "hand", "hip": "thigh", "knee": "shin",
              "ankle": "foot"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    repeat = parser.parse_args().repeat
    character = generate_character(0, "biped")
    heads = dict(zip(character.skeleton.names, character.skeleton.joints))
    points = {role + side: heads[bone + side] for role, bone in ROLE_BONES.items() for side in (".L", ".R")}
    vertices, triangles = character.mesh.vertices, character.mesh.triangles
    print(f"Median of {repeat} runs per size.\n")
    print("| mesh | vertices | triangles | median s | range s |")
    print("|---|---|---|---|---|")
    for times_subdivided in range(4):
        mesh = Mesh(vertices, triangles)
        limb_joints_centred(points, mesh)  # untimed: first-call imports
        seconds = []
        for _ in range(repeat):
            start = time.perf_counter()
            limb_joints_centred(points, mesh)
            seconds.append(time.perf_counter() - start)
        print(f"| procedural biped, subdivided {times_subdivided}x | {len(vertices):,} | {len(triangles):,} | "
              f"{np.median(seconds):.4f} | {min(seconds):.4f}-{max(seconds):.4f} |")
        vertices, triangles, _ = subdivide_midpoints(vertices, triangles, np.zeros((len(vertices), 1)))


if __name__ == "__main__":
    main()
