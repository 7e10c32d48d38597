"""Benchmark geometric skinning on big meshes: the proxy path against solving every vertex.

Usage (from the repo root)::

    .venv/bin/python bench/bench_skinning.py [--repeat 3] [--sizes 5k 53k 104k 264k] [--full-sizes 5k 53k]
    .venv/bin/python bench/bench_skinning.py --quality

Characters (rest pose, every bone deforming, as the Skin operator sees an
imported armature):

- ``5k``: the synthetic humanoid of ``bench_distances.py`` (5,060 vertices,
  50 bones), below the proxy threshold: both paths are the same code.
- ``53k``, ``104k``, ``264k``: the makehuman body
  (``../shared/data/makehuman/body.glb``, 163 bones) with its seams welded
  (13,380 vertices) and subdivided at edge midpoints once (53,514) or twice
  (214,050); ``104k`` and ``264k`` add the ``male_casualsuit01`` garment as a
  second object (50,012 vertices, a triangle soup).

Each size runs in its own Python process (the meshes come from a cache the
first process writes with Blender), so its memory figures start clean. In
that process the proxy path (``geometric_weights`` as shipped) and, for
``--full-sizes``, the full-resolution path (the same function with
``PROXY_VERTEX_THRESHOLD`` raised above the mesh) alternate ``--repeat``
times; the table gives median seconds, the slowest and fastest run, and the
peak resident memory: added by one call (``memory.peak_rss_added``, the
largest over the calls) and the process's total at that peak (resident
memory before the call plus the addition). The machine is shared: the
medians of repeated runs are the figures to quote.

``--quality`` scores both paths on the 53k body, and the default on the
264k one, against the artist's weights (carried through the subdivision
linearly; 124 bones carry weight; the garment has none and is left out),
with ``core.evaluation.skin_metrics.evaluate_skin``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from autorig_addon.core.geometry.subdivision import subdivide_midpoints
from autorig_addon.core.geometry.weld import weld_mesh
from autorig_addon.core.skinning import geometric
from autorig_addon.core.types import Mesh, Skeleton
from autorig_addon.core.weights import normalize_rows
from memory import _status_mib, peak_rss_added

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.dirname(os.path.abspath(__file__))

MAKEHUMAN = os.path.join(REPO, "..", "shared", "data", "makehuman")
#: How the table names the two paths.
PATH_NAMES = {"proxy": "default", "full": "every vertex"}
#: Size name -> (midpoint subdivisions of the welded body, garment added); None: the synthetic humanoid.
SIZES = {"5k": None, "53k": (1, False), "104k": (1, True), "264k": (2, True)}


def write_cache(folder: str) -> None:
    """The body (mesh, skeleton, artist weights) and the garment as .npz, read through Blender."""
    import bpy

    from autorig_addon.blender.characters import load_character
    from autorig_addon.blender.convert import read_mesh

    body = load_character(os.path.join(MAKEHUMAN, "body.glb"))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "garments", "male_casualsuit01.glb"))
    suit = read_mesh([bpy.data.objects["male_casualsuit01"]], bpy.context.evaluated_depsgraph_get())
    s = body.skeleton
    np.savez(os.path.join(folder, "body.npz"), V=body.mesh.vertices, F=body.mesh.triangles, joints=s.joints,
             parents=s.parents, names=np.array(s.names), tails=s.tails, weighted=s.deform, W=body.weights.matrix,
             suit_V=suit.vertices, suit_F=suit.triangles)


def character(folder: str, size: str, all_bones_deform: bool = True):
    """(mesh, skeleton, reference weights or None) of one benchmark size."""
    if SIZES[size] is None:
        from bench_distances import synthetic_character

        mesh, skeleton = synthetic_character()
        return mesh, skeleton, None
    levels, with_suit = SIZES[size]
    data = np.load(os.path.join(folder, "body.npz"))
    welded, to_welded = weld_mesh(Mesh(data["V"], data["F"]))
    V, F = welded.vertices, welded.triangles
    W = np.zeros((len(V), data["W"].shape[1]))
    np.add.at(W, to_welded, data["W"])
    W = normalize_rows(W)
    for _ in range(levels):
        V, F, W = subdivide_midpoints(V, F, W)
    meshes = [Mesh(V, F, object_names=("Body",))]
    if with_suit:
        meshes.append(Mesh(data["suit_V"], data["suit_F"], object_names=("male_casualsuit01",)))
        W = np.vstack([W, np.zeros((len(data["suit_V"]), W.shape[1]))])
    deform = np.ones(len(data["parents"]), dtype=bool) if all_bones_deform else data["weighted"]
    skeleton = Skeleton(data["joints"], data["parents"], tuple(data["names"]), data["tails"], deform)
    return Mesh.concatenate(meshes), skeleton, W


def skin(mesh: Mesh, skeleton: Skeleton, path: str):
    """``geometric_weights`` with its defaults, through the proxy ("proxy") or
    at full resolution ("full"): (Weights, seconds)."""
    threshold = geometric.PROXY_VERTEX_THRESHOLD
    if path == "full":
        geometric.PROXY_VERTEX_THRESHOLD = max(threshold, mesh.vertex_count)
    try:
        start = time.perf_counter()
        weights = geometric.geometric_weights(mesh, skeleton)
        return weights, time.perf_counter() - start
    finally:
        geometric.PROXY_VERTEX_THRESHOLD = threshold


def run_size(folder: str, size: str, paths: list[str], repeat: int) -> dict:
    """One size in this process: seconds and memory per path."""
    mesh, skeleton, _ = character(folder, size)
    result = {"size": size, "vertices": mesh.vertex_count, "bones": int(skeleton.deform.sum()),
              "objects": len(mesh.object_names), "paths": {}}
    seconds = {path: [] for path in paths}
    added = {path: 0.0 for path in paths}
    before = {path: 0.0 for path in paths}
    for _ in range(repeat):
        for path in paths:
            rss = _status_mib("VmRSS:")
            timing = []
            peak = peak_rss_added(lambda: timing.append(skin(mesh, skeleton, path)[1]))
            seconds[path].append(timing[0])
            if peak > added[path]:
                added[path], before[path] = peak, rss
    for path in paths:
        result["paths"][path] = {
            "median_s": statistics.median(seconds[path]), "min_s": min(seconds[path]), "max_s": max(seconds[path]),
            "added_mib": added[path], "total_mib": before[path] + added[path],
        }
    return result


def quality(folder: str) -> None:
    from autorig_addon.core.evaluation.skin_metrics import evaluate_skin

    print("Against the artist's weights (124 of the 163 bones carry weight; the garment has none and is not scored)\n")
    print("| size | path | seconds | L1 | precision | recall | deformation mean | deformation max |")
    print("|---|---|---|---|---|---|---|---|")
    results = {}
    for size, path in (("53k", "full"), ("53k", "proxy"), ("264k", "proxy")):
        mesh, skeleton, reference = character(folder, size, all_bones_deform=False)
        weights, seconds = skin(mesh, skeleton, path)
        results[size, path] = weights.matrix
        m = evaluate_skin(mesh.vertices, weights, reference, skeleton)
        print(f"| {size} | {PATH_NAMES[path]} | {seconds:.1f} | {m['l1']:.4f} | {m['precision']:.4f} | "
              f"{m['recall']:.4f} | {m['deform_mean']:.6f} | {m['deform_max']:.4f} |", flush=True)
    difference = np.abs(results["53k", "proxy"] - results["53k", "full"])
    print(f"\n53k, default - every vertex: mean |weight difference| {difference.mean():.5f}, 99th percentile of the "
          f"per-vertex largest {np.percentile(difference.max(axis=1), 99):.4f}, largest {difference.max():.4f}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", nargs="+", default=list(SIZES), choices=list(SIZES))
    parser.add_argument("--full-sizes", nargs="*", default=["5k", "53k"], choices=list(SIZES),
                        help="sizes also solved at full resolution (minutes and gigabytes above 53k)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quality", action="store_true", help="score both paths on the 53k body instead")
    parser.add_argument("--cache", help=argparse.SUPPRESS)
    parser.add_argument("--one", help=argparse.SUPPRESS)
    parser.add_argument("--paths", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)

    if args.one:  # a child process: one size
        print(json.dumps(run_size(args.cache, args.one, args.paths, args.repeat)))
        return 0
    with tempfile.TemporaryDirectory() as folder:
        # Run in bench/, where "-c" finds bench_skinning.
        child = subprocess.run([sys.executable, "-c", f"import bench_skinning; bench_skinning.write_cache({folder!r})"],
                               capture_output=True, text=True, cwd=BENCH)
        if child.returncode:
            sys.stderr.write(child.stderr)
            return 1
        if args.quality:
            quality(folder)
            return 0
        print(f"Proxy threshold {geometric.PROXY_VERTEX_THRESHOLD:,} vertices, proxy of about "
              f"{geometric.PROXY_VERTICES:,}; median of {args.repeat} runs per path, {os.cpu_count()} cores.\n")
        print("| size | vertices | objects | bones | path | median s | range s | peak added MiB | process peak MiB |")
        print("|---|---|---|---|---|---|---|---|---|")
        for size in args.sizes:
            paths = ["proxy"] + (["full"] if size in args.full_sizes else [])
            child = subprocess.run([sys.executable, os.path.abspath(__file__), "--cache", folder, "--one", size,
                                    "--paths", *paths, "--repeat", str(args.repeat)], capture_output=True, text=True)
            if child.returncode:
                sys.stderr.write(child.stderr)
                return 1
            result = json.loads(child.stdout.strip().splitlines()[-1])
            for path, r in result["paths"].items():
                print(f"| {size} | {result['vertices']:,} | {result['objects']} | {result['bones']} | "
                      f"{PATH_NAMES[path]} | {r['median_s']:.2f} | {r['min_s']:.2f} to {r['max_s']:.2f} | "
                      f"{r['added_mib']:.0f} | {r['total_mib']:.0f} |", flush=True)
            if len(result["paths"]) == 2:
                ratio = result["paths"]["full"]["median_s"] / result["paths"]["proxy"]["median_s"]
                print(f"| {size} | | | | every vertex / default | **{ratio:.1f}x** | | | |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
