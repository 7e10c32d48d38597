"""Benchmark robust weight transfer against plain closest-point copying.

Usage (from the repo root)::

    .venv/bin/python bench/bench_transfer.py [--garment male_casualsuit01] [--repeat 7]

Loads ``../shared/data/makehuman/body.glb`` (the skinned source) and one
garment, runs both methods ``--repeat`` times in this process and prints a
markdown table of per-stage medians (the surface smoothing is the ``smooth``
stage; the transfer without it is timed too), the ratio to closest-point
copying and the peak resident memory added by one transfer. The numbers in
``docs/benchmarks.md`` come from this script.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

from autorig_addon.core.transfer import TransferOptions, transfer_weights
from autorig_addon.core.transfer.matching import closest_point_weights
from memory import peak_rss_added

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

MAKEHUMAN = os.path.join(REPO, "..", "shared", "data", "makehuman")


def load_inputs(garment: str):
    import bpy

    from autorig_addon.blender.armature_binding import find_armature
    from autorig_addon.blender.convert import deform_bone_names, read_mesh, read_weights

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "body.glb"))
    body = bpy.data.objects["Body"]
    bpy.ops.import_scene.gltf(filepath=os.path.join(MAKEHUMAN, "garments", garment + ".glb"))
    target = bpy.data.objects[garment]
    depsgraph = bpy.context.evaluated_depsgraph_get()
    bones = deform_bone_names(find_armature(body))
    return read_mesh([body], depsgraph), read_weights(body, bones), read_mesh([target], depsgraph)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--garment", default="male_casualsuit01")
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args(argv)

    source, source_weights, target = load_inputs(args.garment)
    transfer_weights(source, source_weights, target)  # warm-up: imports, caches
    stage_times: dict[str, list[float]] = {}
    totals, baseline, unsmoothed = [], [], []
    without_smoothing = TransferOptions(smoothing_length=0.0)
    for _ in range(args.repeat):
        start = time.perf_counter()
        closest_point_weights(source, source_weights, target)
        baseline.append(time.perf_counter() - start)
        start = time.perf_counter()
        result = transfer_weights(source, source_weights, target)
        totals.append(time.perf_counter() - start)
        start = time.perf_counter()
        transfer_weights(source, source_weights, target, without_smoothing)
        unsmoothed.append(time.perf_counter() - start)
        for stage, seconds in result.timings.items():
            stage_times.setdefault(stage, []).append(seconds)
    memory = peak_rss_added(lambda: transfer_weights(source, source_weights, target))
    baseline_memory = peak_rss_added(lambda: closest_point_weights(source, source_weights, target))

    median_total, median_baseline = statistics.median(totals), statistics.median(baseline)
    print(f"Source: makehuman body, {source.vertex_count} vertices, {len(source.triangles)} triangles, "
          f"{len(source_weights.bone_names)} bones. Target: {args.garment}, {target.vertex_count} vertices, "
          f"{len(target.triangles)} triangles. {result.summary()}. "
          f"Median of {args.repeat} runs, {os.cpu_count()} cores.\n")
    print("| stage | median s |\n|---|---|")
    for stage, values in stage_times.items():
        print(f"| {stage} | {statistics.median(values):.3f} |")
    print(f"| **total robust transfer** | **{median_total:.3f}** |")
    print(f"| robust transfer without surface smoothing | {statistics.median(unsmoothed):.3f} |")
    print(f"| closest-point copy (baseline) | {median_baseline:.3f} |")
    print(f"\nRatio robust / closest-point copy: {median_total / median_baseline:.2f}x "
          f"(min {min(totals):.3f} s, max {max(totals):.3f} s)")
    print(f"Peak resident memory added: transfer {memory:.0f} MiB, closest-point copy {baseline_memory:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
