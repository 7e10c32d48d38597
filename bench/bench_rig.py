"""Benchmark skeleton prediction (core/rigging/predict.py) and the one-click auto-rig core path.

Usage (from the repo root)::

    .venv/bin/python bench/bench_rig.py [--repeat 5] [--sizes 5k 104k] [--json results.json]

Characters are ``bench_skinning.py``'s: ``5k`` the synthetic humanoid
(5,060 vertices; its own skeleton is not used), ``104k`` the subdivided
makehuman body with a garment (103,526 vertices, two objects, read through
Blender once into a temporary cache). Each size runs in its own process, so
its memory figures start clean. There, after one untimed call (it reads the
weights files), each step runs ``--repeat`` times:

* ``predict_votes``: proxy, normalisation, depth features, joint network
  (the slow part, once per character);
* ``skeleton_from_votes`` of the free-form skeleton at :data:`BANDWIDTHS`
  (what the level-of-detail slider re-runs: clustering, connectivity,
  names), with the joint count;
* ``predict_skeleton``: both, as *Predict Skeleton* runs them with the
  default template (a known character's rig when the body lies near one,
  else the standard skeleton when the landmark network reads a biped or
  quadruped), with the default template but no known rig (the standard
  skeleton), and with the free-form template;
* on ``5k`` only, the auto-rig core path: ``predict_skeleton`` then
  ``core.skinning.methods.skin_weights`` with the default method, as
  *Auto-Rig* runs them (without Blender's armature and vertex-group writes);
  and the whole *Auto-Rig* with Rigify in Blender (``blender.jobs.rig``:
  armature, Rigify's metarig and generation, learned skin written into
  vertex groups), on a mesh object made from the arrays.

The table gives the median seconds, the fastest and slowest run, the peak
resident memory one call added (largest over the runs,
``memory.peak_rss_added``) and the process's total at that peak. The
machine is shared: quote the medians.
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

from autorig_addon.core.rigging import predict
from autorig_addon.core.skinning.methods import DEFAULT_SKIN_METHOD, skin_weights
from autorig_addon.core.skinning.options import SkinningOptions
from bench_skinning import character
from memory import _status_mib, peak_rss_added

BENCH = os.path.dirname(os.path.abspath(__file__))

#: Bandwidths of the re-clustering rows (share of the largest side): the
#: finest the slider allows, the default, coarse.
BANDWIDTHS = (predict.MIN_BANDWIDTH, predict.DEFAULT_BANDWIDTH, 0.08)
#: Sizes the auto-rig row is measured on.
AUTO_RIG_SIZES = ("5k",)


def auto_rig(mesh):
    """The one-click core path: a skeleton, then its skin weights."""
    skeleton = predict.predict_skeleton(mesh)
    return skeleton, skin_weights(mesh, skeleton, SkinningOptions(method=DEFAULT_SKIN_METHOD))


def blender_auto_rig_with_rigify(mesh):
    """Auto-Rig with Rigify on a fresh scene holding the mesh; returns the control rig's skeleton."""
    import bpy

    from autorig_addon.blender.jobs.rig import RigSettings, plan_rig, rig_steps, run_steps
    from autorig_addon.blender.jobs.skin import SkinSettings

    bpy.ops.wm.read_factory_settings(use_empty=True)
    data = bpy.data.meshes.new("Character")
    data.from_pydata(mesh.vertices.tolist(), [], mesh.triangles.tolist())
    obj = bpy.data.objects.new("Character", data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    plan = plan_rig([obj], bpy.context.evaluated_depsgraph_get(), "Character", RigSettings(template="biped"),
                    skin=SkinSettings(SkinningOptions(method=DEFAULT_SKIN_METHOD)), rigify=True)
    return run_steps(rig_steps(bpy.context, plan, remember=False)).skeleton


def measured(function, seconds: list, peaks: dict, key: str):
    """Run ``function()``, append its seconds, keep the largest peak memory; return its result."""
    rss = _status_mib("VmRSS:")
    out = []

    def timed():
        start = time.perf_counter()
        out.append(function())
        seconds.append(time.perf_counter() - start)

    added = peak_rss_added(timed)
    if added > peaks.get(key, (-1.0, 0.0))[0]:
        peaks[key] = (added, rss + added)
    return out[0]


def run_size(folder: str, size: str, repeat: int) -> dict:
    mesh, _, _ = character(folder, size)
    steps = (["predict_votes"] + [f"skeleton_from_votes free-form h={h:g}" for h in BANDWIDTHS]
             + ["predict_skeleton", "predict_skeleton without known rigs", "predict_skeleton free-form"])
    rigify_step = f"Auto-Rig with Rigify in Blender ({DEFAULT_SKIN_METHOD} skin)"
    if size in AUTO_RIG_SIZES:
        steps += [f"auto-rig (predict_skeleton + skin_weights {DEFAULT_SKIN_METHOD})", rigify_step]
        auto_rig(mesh)  # first call reads every weights file; not timed
        blender_auto_rig_with_rigify(mesh)  # loads Rigify
    else:
        predict.predict_skeleton(mesh)
    seconds = {step: [] for step in steps}
    peaks, joints = {}, {}
    for _ in range(repeat):
        votes = measured(lambda: predict.predict_votes(mesh), seconds[steps[0]], peaks, steps[0])
        for bandwidth, step in zip(BANDWIDTHS, steps[1:]):
            skeleton = measured(lambda: predict.skeleton_from_votes(votes, bandwidth=bandwidth, template="free-form"),
                                seconds[step], peaks, step)
            joints[step] = skeleton.bone_count
        for step, template, known_rig in (("predict_skeleton", "auto", True),
                                          ("predict_skeleton without known rigs", "auto", False),
                                          ("predict_skeleton free-form", "free-form", True)):
            skeleton = measured(lambda: predict.predict_skeleton(mesh, template=template, known_rig=known_rig),
                                seconds[step], peaks, step)
            joints[step] = skeleton.bone_count
        if size in AUTO_RIG_SIZES:
            step = steps[-2]
            skeleton, _ = measured(lambda: auto_rig(mesh), seconds[step], peaks, step)
            joints[step] = skeleton.bone_count
            skeleton = measured(lambda: blender_auto_rig_with_rigify(mesh), seconds[rigify_step], peaks, rigify_step)
            joints[rigify_step] = skeleton.bone_count
    return {"size": size, "vertices": mesh.vertex_count, "objects": len(mesh.object_names), "steps": {
        step: {"median_s": statistics.median(seconds[step]), "min_s": min(seconds[step]), "max_s": max(seconds[step]),
               "joints": joints.get(step), "added_mib": peaks[step][0], "total_mib": peaks[step][1]}
        for step in steps}}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", nargs="+", default=["5k", "104k"], choices=["5k", "53k", "104k", "264k"])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", help="also write the results to this JSON file")
    parser.add_argument("--cache", help=argparse.SUPPRESS)
    parser.add_argument("--one", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:  # a child process: one size
        print(json.dumps(run_size(args.cache, args.one, args.repeat)))
        return 0
    results = []
    with tempfile.TemporaryDirectory() as folder:
        if any(size != "5k" for size in args.sizes):
            # Run in bench/, where "-c" finds bench_skinning.
            child = subprocess.run(
                [sys.executable, "-c", f"import bench_skinning; bench_skinning.write_cache({folder!r})"],
                capture_output=True, text=True, cwd=BENCH,
            )
            if child.returncode:
                sys.stderr.write(child.stderr)
                return 1
        print(f"Median of {args.repeat} runs per step, {os.cpu_count()} cores; proxy of "
              f"{predict.PROXY_VERTICES:,} vertices; default bandwidth {predict.DEFAULT_BANDWIDTH:g}.\n")
        print("| size | vertices | step | joints | median s | range s | peak added MiB | process peak MiB |")
        print("|---|---|---|---|---|---|---|---|")
        for size in args.sizes:
            child = subprocess.run([sys.executable, os.path.abspath(__file__), "--cache", folder, "--one", size,
                                    "--repeat", str(args.repeat)], capture_output=True, text=True)
            if child.returncode:
                sys.stderr.write(child.stderr)
                return 1
            result = json.loads(child.stdout.strip().splitlines()[-1])
            results.append(result)
            for step, m in result["steps"].items():
                joints = m["joints"] if step != "predict_votes" else ""
                print(f"| {size} | {result['vertices']:,} | {step} | {joints} | {m['median_s']:.2f} | "
                      f"{m['min_s']:.2f}-{m['max_s']:.2f} | {m['added_mib']:.0f} | {m['total_mib']:.0f} |", flush=True)
    if args.json:
        with open(args.json, "w") as out:
            json.dump(results, out, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
