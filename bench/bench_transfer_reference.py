"""Time robust transfer against the published implementation, garment by garment.

Usage (from the repo root)::

    .venv/bin/python bench/bench_transfer_reference.py \\
        --reference-python /tmp/refenv/bin/python \\
        --reference-utils /tmp/reference_utils.py [--repeat 5]

The reference is Abdrashitov et al.'s own code
(``rin-23/RobustSkinWeightsTransferCode``, ``src/utils.py``, MIT), run in a
scratch environment of its own (``libigl==2.5.1`` with numpy 1.26 and scipy
1.11; never the project's): ``--reference-python`` is that environment's
interpreter and ``--reference-utils`` its ``src/utils.py``. Without them
only ours is timed.

Loads ``../shared/data/makehuman/body.glb`` and every garment of
``garments/``. The reference is given each garment already welded (it has
no welding and fails on a triangle soup) and times its matching, inpainting
and default smoothing (10 passes of strength 0.2); ours times the whole
``transfer_weights`` call on the garment as imported (welding, checks,
matching, inpainting, smoothing). Rounds alternate between the two (the
reference in a subprocess that times each garment itself), and each figure
is the median over ``--repeat`` rounds. Ours is timed two ways: one garment
at a time (``transfer_weights(body, weights, garment)``, the body checked and
indexed in every call) and as a wardrobe (the body prepared once,
:class:`~autorig_addon.core.transfer.TransferSource`, its time counted once
in the total). Prints a markdown table for ``docs/transfer.md``.
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

MAKEHUMAN = os.path.join(REPO, "..", "shared", "data", "makehuman")

#: Runs in the reference's environment: imports nothing of ours, times each
#: garment's matching, inpainting and smoothing as the reference's README
#: runs them, prints {garment: seconds or null when it fails}.
REFERENCE_RUNNER = r'''
import importlib.util, json, sys, time
import numpy as np, igl
spec = importlib.util.spec_from_file_location("reference_utils", sys.argv[2])
reference = importlib.util.module_from_spec(spec)
spec.loader.exec_module(reference)
find_matches_closest_surface = reference.find_matches_closest_surface
inpaint, smooth = reference.inpaint, reference.smooth
arrays = np.load(sys.argv[1])
V1, F1, W1 = arrays["body_V"], arrays["body_F"], arrays["body_W"]
times = {}
for name in sys.argv[3].split(","):
    V2, F2 = arrays[name + "_V"], arrays[name + "_F"]
    start = time.perf_counter()
    N1 = igl.per_vertex_normals(V1, F1)
    N2 = igl.per_vertex_normals(V2, F2)
    distance = 0.05 * igl.bounding_box_diagonal(V2)
    matched, W2 = find_matches_closest_surface(V1, F1, N1, V2, F2, N2, W1, distance * distance, 30)
    inpainted, ok = inpaint(V2, F2, W2, matched)
    ok = bool(ok) and bool(np.all(np.isfinite(inpainted)))
    if ok:
        smooth(V2, F2, inpainted, matched, distance, num_smooth_iter_steps=10, smooth_alpha=0.2)
    times[name] = time.perf_counter() - start if ok else None
print(json.dumps(times))
'''


def load_inputs():
    import bpy

    from autorig_addon.blender import convert, scene_io
    from autorig_addon.blender.characters import load_character

    body = load_character(os.path.join(MAKEHUMAN, "body.glb"))
    garments = {}
    for path in sorted(glob.glob(os.path.join(MAKEHUMAN, "garments", "*.glb"))):
        scene_io.load_scene(path)
        objects = sorted((obj for obj in bpy.context.scene.objects if obj.type == "MESH" and len(obj.data.polygons)),
                         key=lambda obj: obj.name)
        garments[os.path.splitext(os.path.basename(path))[0]] = convert.read_mesh(
            objects, bpy.context.evaluated_depsgraph_get())
    return body.mesh, body.weights, garments


def reference_round(python: str, utils: str, arrays_path: str, names: list[str]) -> dict:
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as runner:
        runner.write(REFERENCE_RUNNER)
    try:
        done = subprocess.run([python, runner.name, arrays_path, os.path.abspath(utils), ",".join(names)],
                              capture_output=True, text=True, env=dict(os.environ, OMP_NUM_THREADS="1"))
    finally:
        os.unlink(runner.name)
    if done.returncode:
        raise SystemExit(f"The reference failed:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reference-python", help="interpreter of the reference's scratch environment")
    parser.add_argument("--reference-utils", help="the reference's src/utils.py")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)

    from autorig_addon.core.geometry.weld import weld_mesh
    from autorig_addon.core.transfer import TransferSource, transfer_weights

    body, body_weights, garments = load_inputs()
    names = sorted(garments)
    arrays = {"body_V": body.vertices, "body_F": body.triangles.astype(np.int64), "body_W": body_weights.matrix}
    welded_counts = {}
    for name in names:
        welded, _ = weld_mesh(garments[name])
        arrays[name + "_V"], arrays[name + "_F"] = welded.vertices, welded.triangles.astype(np.int64)
        welded_counts[name] = welded.vertex_count
    with tempfile.TemporaryDirectory() as folder:
        arrays_path = os.path.join(folder, "arrays.npz")
        np.savez(arrays_path, **arrays)
        one_at_a_time = {name: [] for name in names}
        wardrobe = {name: [] for name in names}
        reference = {name: [] for name in names}
        prepare = []
        transfer_weights(body, body_weights, garments[names[0]])  # warm-up: imports, caches
        for _ in range(args.repeat):
            if args.reference_python:
                for name, seconds in reference_round(args.reference_python, args.reference_utils, arrays_path,
                                                     names).items():
                    reference[name].append(seconds)
            for name in names:
                start = time.perf_counter()
                transfer_weights(body, body_weights, garments[name])
                one_at_a_time[name].append(time.perf_counter() - start)
            start = time.perf_counter()
            source = TransferSource.prepare(body, body_weights)
            prepare.append(time.perf_counter() - start)
            for name in names:
                start = time.perf_counter()
                transfer_weights(body, body_weights, garments[name], prepared=source)
                wardrobe[name].append(time.perf_counter() - start)

    def median(values):
        return None if not values or any(v is None for v in values) else statistics.median(values)

    print(f"Median of {args.repeat} alternating rounds, {os.cpu_count()} cores, one BLAS thread. Body: "
          f"{body.vertex_count} vertices, {len(body_weights.bone_names)} bones.\n")
    print("| garment | vertices (welded) | ours, one at a time s | ours, wardrobe s | reference s |")
    print("|---|---|---|---|---|")
    totals = {"one": 0.0, "wardrobe": 0.0, "reference": 0.0}
    for name in names:
        ref = median(reference[name])
        one, worn = median(one_at_a_time[name]), median(wardrobe[name])
        ref_text = "fails" if args.reference_python and ref is None else ("" if ref is None else f"{ref:.3f}")
        print(f"| {name} | {garments[name].vertex_count:,} ({welded_counts[name]:,}) | {one:.3f} | {worn:.3f} | "
              f"{ref_text} |")
        if ref is not None or not args.reference_python:
            totals["one"] += one
            totals["wardrobe"] += worn
            totals["reference"] += ref or 0.0
    prepared = statistics.median(prepare)
    print(f"| preparing the body once (wardrobe) | | | {prepared:.3f} | |")
    completed = "the garments the reference completes" if args.reference_python else "all garments"
    print(f"| **total, {completed}** | | {totals['one']:.2f} | {totals['wardrobe'] + prepared:.2f} | "
          f"{totals['reference']:.2f} |")
    if args.reference_python:
        print(f"\nReference / ours: {totals['reference'] / totals['one']:.2f} times one garment at a time, "
              f"{totals['reference'] / (totals['wardrobe'] + prepared):.2f} times as a wardrobe.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
