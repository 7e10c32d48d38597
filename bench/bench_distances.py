"""Benchmark the voxel vertex-to-bone distances, stage by stage.

Usage (from the repo root)::

    .venv/bin/python bench/bench_distances.py [--resolutions 88 256] [--repeat 5]
    .venv/bin/python bench/bench_distances.py --character ../shared/data/characters/x/y.glb

Without ``--character`` it builds a synthetic humanoid of about 5,000
vertices and 50 bones (closed tubes and spheres overlapping at the joints,
1.8 units tall). With a ``.glb`` path it imports the file with Blender and
uses its meshes and deform bones. For each resolution and each distance
kind it times the stages (voxelise, fill, graph, paths, per-vertex lookup)
``--repeat`` times, reports medians and the peak resident memory added by
one full run, and prints a markdown table for ``docs/benchmarks.md``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

from autorig_addon.core.distances.bone_distances import validate_bones, voxelize_covering_bones
from autorig_addon.core.distances.cell_graph import bone_node_distances
from autorig_addon.core.distances.hollow_dist import build_hollow_graph, refine_hollow_in_sight
from autorig_addon.core.distances.interior import fill_interior
from autorig_addon.core.distances.vertex_distances import combine_vertex_distances, vertex_cell_candidates
from autorig_addon.core.distances.volumetric_geodesic import build_geodesic_graph, refine_geodesic_in_sight
from autorig_addon.core.types import Mesh, Skeleton
from memory import peak_rss_added

#: Each distance kind's own stages (graph, line of sight); the others are shared
#: (see ``autorig_addon.core.distances.bone_distances``).
KINDS = {
    "geodesic": (build_geodesic_graph, refine_geodesic_in_sight),
    "hollow": (build_hollow_graph, refine_hollow_in_sight),
}


# --------------------------------------------------------------------------
# Synthetic character
# --------------------------------------------------------------------------


def tube(start, end, radius, segments, rings) -> Mesh:
    """Closed cylinder from ``start`` to ``end`` with fan caps."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    axis = end - start
    axis_unit = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0, 0]) if abs(axis_unit[0]) < 0.9 else np.array([0, 1.0, 0])
    u = np.cross(axis_unit, helper)
    u /= np.linalg.norm(u)
    w = np.cross(axis_unit, u)
    angle = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    circle = radius * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * w)
    t = np.linspace(0, 1, rings)
    V = (start + t[:, None, None] * axis + circle[None]).reshape(-1, 3)
    r, s = np.meshgrid(np.arange(rings - 1), np.arange(segments), indexing="ij")
    a = (r * segments + s).ravel()
    b = (r * segments + (s + 1) % segments).ravel()
    F = np.concatenate([np.stack([a, b, b + segments], 1), np.stack([a, b + segments, a + segments], 1)])
    bottom, top = len(V), len(V) + 1
    V = np.vstack([V, start, end])
    s = np.arange(segments)
    last = (rings - 1) * segments
    caps = np.concatenate([
        np.stack([np.full(segments, bottom), (s + 1) % segments, s], 1),
        np.stack([np.full(segments, top), last + s, last + (s + 1) % segments], 1),
    ])
    return Mesh(V, np.concatenate([F, caps]))


def sphere(centre, radius, segments, rings) -> Mesh:
    """UV sphere."""
    theta = np.linspace(0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    V = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1).reshape(-1, 3)
    V = np.vstack([V, [0, 0, 1], [0, 0, -1]]) * radius + np.asarray(centre, float)
    r, s = np.meshgrid(np.arange(rings - 2), np.arange(segments), indexing="ij")
    a = (r * segments + s).ravel()
    b = (r * segments + (s + 1) % segments).ravel()
    F = [np.stack([a, b + segments, b], 1), np.stack([a, a + segments, b + segments], 1)]
    top, bottom = len(V) - 2, len(V) - 1
    s = np.arange(segments)
    last = (rings - 2) * segments
    F.append(np.stack([np.full(segments, top), s, (s + 1) % segments], 1))
    F.append(np.stack([np.full(segments, bottom), last + (s + 1) % segments, last + s], 1))
    return Mesh(V, np.concatenate(F))


def synthetic_character() -> tuple[Mesh, Skeleton]:
    """A 1.8-unit humanoid of ~5k vertices and 50 bones."""
    heads, tails, names, parents, parts = [], [], [], [], []

    def bone(name, head, tail, parent, radius=None, segments=16, rings=6):
        heads.append(head)
        tails.append(tail)
        names.append(name)
        parents.append(names.index(parent) if parent else -1)
        if radius:
            parts.append(tube(head, tail, radius, segments, rings))

    bone("hips", (0, 0, 0.95), (0, 0, 1.15), None, 0.15, 32, 10)
    bone("chest", (0, 0, 1.15), (0, 0, 1.45), "hips", 0.16, 32, 14)
    bone("neck", (0, 0, 1.45), (0, 0, 1.55), "chest", 0.05, 12, 4)
    bone("head", (0, 0, 1.55), (0, 0, 1.75), "neck")
    parts.append(sphere((0, 0, 1.65), 0.11, 36, 20))
    for side, x in (("L", 1), ("R", -1)):
        bone(f"shoulder.{side}", (0.03 * x, 0, 1.42), (0.18 * x, 0, 1.42), "chest", 0.05, 16, 5)
        bone(f"upper_arm.{side}", (0.18 * x, 0, 1.42), (0.45 * x, 0, 1.42), f"shoulder.{side}", 0.05, 16, 14)
        bone(f"forearm.{side}", (0.45 * x, 0, 1.42), (0.70 * x, 0, 1.42), f"upper_arm.{side}", 0.04, 16, 14)
        bone(f"hand.{side}", (0.70 * x, 0, 1.42), (0.78 * x, 0, 1.42), f"forearm.{side}", 0.03, 12, 4)
        for f in range(5):
            y = (f - 2) * 0.018
            parent = f"hand.{side}"
            for k in range(3):
                start = ((0.78 + 0.025 * k) * x, y, 1.42)
                end = ((0.78 + 0.025 * (k + 1)) * x, y, 1.42)
                bone(f"finger{f}_{k}.{side}", start, end, parent, 0.007, 8, 3)
                parent = f"finger{f}_{k}.{side}"
        bone(f"thigh.{side}", (0.09 * x, 0, 0.95), (0.1 * x, 0, 0.52), "hips", 0.075, 24, 16)
        bone(f"shin.{side}", (0.1 * x, 0, 0.52), (0.1 * x, 0, 0.08), f"thigh.{side}", 0.055, 20, 16)
        bone(f"foot.{side}", (0.1 * x, 0, 0.08), (0.1 * x, 0.12, 0.04), f"shin.{side}", 0.04, 12, 5)
        bone(f"toe.{side}", (0.1 * x, 0.12, 0.04), (0.1 * x, 0.18, 0.03), f"foot.{side}", 0.025, 10, 3)
    mesh = Mesh.concatenate(parts)
    skeleton = Skeleton(np.array(heads, float), np.array(parents), tuple(names), np.array(tails, float))
    return mesh, skeleton


def load_character(path: str) -> tuple[Mesh, Skeleton]:
    """Meshes and armature of a ``.glb`` file, through Blender."""
    import bpy

    from autorig_addon.blender.armature_binding import find_armature
    from autorig_addon.blender.convert import read_mesh, read_skeleton

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=path)
    objects = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    armature = find_armature(objects[0])
    armature.data.pose_position = "REST"  # distances belong to the rest shape, not an imported pose
    bpy.context.view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    return read_mesh(objects, depsgraph), read_skeleton(armature).deform_subset()


# --------------------------------------------------------------------------
# Timing
# --------------------------------------------------------------------------


def run_stages(mesh: Mesh, heads, tails, resolution: int, kind: str) -> dict[str, float]:
    """One full distance computation, the stages of
    ``core.distances.bone_distances.bone_distances`` called one by one; seconds per stage."""
    build_graph, refine = KINDS[kind]
    heads, tails = validate_bones(heads, tails)
    times = {}
    clock = time.perf_counter()
    grid = voxelize_covering_bones(mesh, heads, tails, resolution)
    times["voxelise"] = time.perf_counter() - clock
    clock = time.perf_counter()
    grid = fill_interior(grid)
    times["fill"] = time.perf_counter() - clock
    clock = time.perf_counter()
    graph = build_graph(grid, heads, tails)
    times["graph"] = time.perf_counter() - clock
    clock = time.perf_counter()
    candidates, query_nodes = vertex_cell_candidates(graph, mesh.vertices)
    node_distances = bone_node_distances(graph, query_nodes)
    times["paths"] = time.perf_counter() - clock
    clock = time.perf_counter()
    distances, layers = combine_vertex_distances(graph, mesh.vertices, candidates, query_nodes, node_distances)
    refine(grid, distances, layers, mesh.vertices, heads, tails)
    times["lookup"] = time.perf_counter() - clock
    times["total"] = sum(times.values())
    times["nodes"] = graph.nodes.count
    times["cells"] = int(np.prod(grid.shape))
    return times


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--character", help="a .glb file; default: synthetic 5k-vertex, 50-bone humanoid")
    parser.add_argument("--resolutions", type=int, nargs="+", default=[88, 256])
    parser.add_argument("--kinds", nargs="+", default=["geodesic", "hollow"], choices=["geodesic", "hollow"])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)

    mesh, skeleton = load_character(args.character) if args.character else synthetic_character()
    heads, tails = skeleton.joints[skeleton.deform], skeleton.tails[skeleton.deform]
    print(f"{mesh.vertex_count} vertices, {len(mesh.triangles)} triangles, {len(heads)} deform bones, "
          f"{os.cpu_count()} CPUs\n")
    stages = ["voxelise", "fill", "graph", "paths", "lookup", "total"]
    print("| distance | cells/side | grid cells | graph nodes | " + " | ".join(f"{s} (s)" for s in stages)
          + " | peak memory (MiB) |")
    print("|---|---|---|---|" + "---|" * len(stages) + "---|")
    for resolution in args.resolutions:
        for kind in args.kinds:
            run_stages(mesh, heads, tails, resolution, kind)  # warm-up
            runs = [run_stages(mesh, heads, tails, resolution, kind) for _ in range(args.repeat)]
            memory = peak_rss_added(lambda: run_stages(mesh, heads, tails, resolution, kind))
            medians = [statistics.median(r[s] for r in runs) for s in stages]
            print(f"| {kind} | {resolution} | {runs[0]['cells']:,} | {runs[0]['nodes']:,} | "
                  + " | ".join(f"{m:.3f}" for m in medians) + f" | {memory:.0f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
