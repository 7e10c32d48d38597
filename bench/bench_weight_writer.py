"""Benchmark writing weights into vertex groups.

Usage (from the repo root)::

    .venv/bin/python bench/bench_weight_writer.py [--garment male_casualsuit01] [--repeat 5] [--grid-side 506]

Transfers the makehuman body's weights onto one garment (50,012 vertices
for ``male_casualsuit01``) and times writing

- those weights (many vertices share values copied from the body),
- the same weights made continuous (each non-zero scaled by a random factor
  within 1e-3, rows renormalised: every entry its own value, as skinning and
  smoothed transfers produce), and optionally (``--grid-side``)
- a grid of side**2 vertices with one group per body bone, four continuous
  influences per vertex in bands across it (skinning on a sculpt-resolution mesh),

and (``--reversed``, alone) 163 groups written onto a 2,000-vertex grid whose
existing groups are in reverse order (the refilled groups must be put back
in place: once one ``vertex_group_move`` per place, now one rebuild),

each into a fresh copy of the mesh (first write) and again into the same,
now bound, copy (a re-run, as Adjust Last Operation does), with
``weight_writer.write_weights`` (now) and with the former writer, one
``VertexGroup.add`` call per distinct weight value of each group, reproduced
here. Both are checked to store the same float32 weights. Prints a markdown
table of medians; the numbers in ``docs/benchmarks.md`` come from this script.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

MAKEHUMAN = os.path.join(REPO, "..", "shared", "data", "makehuman")


def write_per_value(obj, weights, armature) -> None:
    """The former writer: each deform group emptied, then one ``add`` call per distinct value."""
    from autorig_addon.blender.weight_writer import ensure_armature_binding

    vertex_count = len(obj.data.vertices)
    for column, name in enumerate(weights.bone_names):
        values = weights.matrix[:, column]
        members = np.flatnonzero(values > 0)
        group = obj.vertex_groups.get(name)
        if group is None:
            if not len(members):
                continue
            group = obj.vertex_groups.new(name=name)
        else:
            group.remove(list(range(vertex_count)))
        distinct, inverse = np.unique(values[members].astype(np.float32), return_inverse=True)
        order = np.argsort(inverse, kind="stable")
        boundaries = np.flatnonzero(np.diff(inverse[order])) + 1
        for value, indices in zip(distinct, np.split(members[order], boundaries)):
            group.add(indices.tolist(), float(value), "REPLACE")
    ensure_armature_binding(obj, armature)


#: Groups and vertices of the ``--reversed`` case (the reviewer's measurement).
REVERSED_GROUPS = 163
REVERSED_VERTICES = 2000


def time_reversed(repeat: int) -> float:
    """Median seconds of ``fill_groups`` refilling REVERSED_GROUPS groups that
    exist in reverse order on a REVERSED_VERTICES-vertex mesh."""
    import bpy

    from autorig_addon.blender.weight_writer import fill_groups

    bpy.ops.wm.read_factory_settings(use_empty=True)
    rng = np.random.default_rng(0)
    names = [f"Bone{k:03d}" for k in range(REVERSED_GROUPS)]
    values = {name: rng.random(REVERSED_VERTICES) for name in names}
    seconds = []
    for _ in range(repeat):
        mesh = bpy.data.meshes.new("Grid")
        mesh.vertices.add(REVERSED_VERTICES)
        obj = bpy.data.objects.new("Grid", mesh)
        bpy.context.scene.collection.objects.link(obj)
        for name in reversed(names):
            obj.vertex_groups.new(name=name).add([0], 1.0, "REPLACE")
        clock = time.perf_counter()
        fill_groups(obj, values)
        seconds.append(time.perf_counter() - clock)
        assert [group.name for group in obj.vertex_groups] == names[::-1]
    return statistics.median(seconds)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--garment", default="male_casualsuit01")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--grid-side", type=int, default=0, help="also a side x side vertex grid (0: no)")
    parser.add_argument("--reversed", action="store_true", help="only the reversed-order case")
    args = parser.parse_args(argv)
    if args.reversed:
        print(f"reversed order, {REVERSED_GROUPS} groups, {REVERSED_VERTICES} vertices: "
              f"{time_reversed(args.repeat):.3f} s")
        return 0

    import bpy

    from autorig_addon.blender.convert import read_group_weights
    from autorig_addon.blender.jobs.transfer import TransferSettings, compute_transfer, plan_transfer
    from autorig_addon.blender.weight_writer import write_weights
    from autorig_addon.core.types import Weights

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "body.glb"))
    body = bpy.data.objects["Body"]
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "garments", args.garment + ".glb"))
    garment = bpy.data.objects[args.garment]
    depsgraph = bpy.context.evaluated_depsgraph_get()
    plan = plan_transfer(body, [garment], TransferSettings(), depsgraph)
    clock = time.perf_counter()
    (outcome,) = compute_transfer(plan, depsgraph)
    transfer_seconds = time.perf_counter() - clock
    copied = outcome.weights
    rng = np.random.default_rng(0)
    jittered = copied.matrix * (1.0 + 1e-3 * rng.random(copied.matrix.shape))
    continuous = Weights(jittered / jittered.sum(axis=1, keepdims=True), copied.bone_names)
    cases = [("transferred", garment, copied), ("continuous", garment, continuous)]
    if args.grid_side:
        bpy.ops.mesh.primitive_grid_add(x_subdivisions=args.grid_side - 1, y_subdivisions=args.grid_side - 1, size=2)
        grid = bpy.context.active_object
        x = np.array([vertex.co.x for vertex in grid.data.vertices])
        bones = len(copied.bone_names)
        band = np.clip(((x + 1.0) / 2.0 * (bones - 4)).astype(int), 0, bones - 4)
        banded = np.zeros((len(x), bones))
        for offset in range(4):
            banded[np.arange(len(x)), band + offset] = rng.random(len(x))
        banded_weights = Weights(banded / banded.sum(axis=1, keepdims=True), copied.bone_names)
        cases.append((f"grid, {bones} bones", grid, banded_weights))
    writers = {"now": lambda obj, weights: write_weights(obj, weights, plan.armature),
               "before": lambda obj, weights: write_per_value(obj, weights, plan.armature)}

    warm_up = garment.copy()
    warm_up.data = garment.data.copy()
    bpy.context.scene.collection.objects.link(warm_up)
    for write in writers.values():  # first calls load operators and caches
        write(warm_up, copied)
    bpy.data.objects.remove(warm_up)

    print(f"{args.garment}: {copied.vertex_count} vertices; transfer {transfer_seconds:.3f} s")
    print("| weights | vertices | distinct (group, value) pairs | first write, now / before "
          "| again (bound), now / before |")
    print("|---|---|---|---|---|")
    for label, original, weights in cases:
        distinct = sum(len(np.unique(column[column > 0])) for column in weights.matrix.astype(np.float32).T)
        times = {(writer, run): [] for writer in writers for run in ("first", "again")}
        stored = []
        for _ in range(args.repeat):
            for writer, write in writers.items():
                target = original.copy()
                target.data = original.data.copy()
                target.modifiers.clear()
                bpy.context.scene.collection.objects.link(target)
                for run in ("first", "again"):
                    start = time.perf_counter()
                    write(target, weights)
                    times[writer, run].append(time.perf_counter() - start)
                    bpy.context.view_layer.update()  # the bound copy is evaluated, as in a session
                stored.append(read_group_weights(target, weights.bone_names))
                mesh = target.data
                bpy.data.objects.remove(target)
                bpy.data.meshes.remove(mesh)
        assert all(np.array_equal(stored[0], other) for other in stored[1:]), "the writers stored different weights"
        cells = [" / ".join(f"{statistics.median(times[writer, run]):.3f}" for writer in writers)
                 for run in ("first", "again")]
        print(f"| {label} | {weights.vertex_count} | {distinct} | {cells[0]} s | {cells[1]} s |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
