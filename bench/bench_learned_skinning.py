"""Benchmark the learned skinning networks against the geometric method, in the same process.

Usage (from the repo root)::

    .venv/bin/python bench/bench_learned_skinning.py [--repeat 3] [--sizes 5k 104k]

Characters are ``bench_skinning.py``'s: ``5k`` the synthetic humanoid
(5,060 vertices, 50 bones), ``104k`` the subdivided makehuman body with a
garment (103,526 vertices, 163 bones, two objects). Each size runs in its
own process; in it the geometric method and every network alternate
``--repeat`` times. The table gives the median seconds of the whole skin
step (distances, prior, network, influence limit), the ratio to the
geometric method's median in the same process, and the peak resident
memory one call added and the process's total at that peak.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time

from autorig_addon.core.skinning.geometric import geometric_weights
from autorig_addon.core.skinning.learned.networks import NETWORK_NAMES
from autorig_addon.core.skinning.learned.predict import learned_weights
from bench_skinning import character, write_cache
from memory import _status_mib, peak_rss_added

METHODS = ("geometric",) + NETWORK_NAMES


def skin(mesh, skeleton, method: str) -> float:
    start = time.perf_counter()
    if method == "geometric":
        geometric_weights(mesh, skeleton)
    else:
        learned_weights(mesh, skeleton, method)
    return time.perf_counter() - start


def run_size(folder: str, size: str, repeat: int) -> dict:
    mesh, skeleton, _ = character(folder, size)
    for method in NETWORK_NAMES:  # first call reads the weights file; not timed
        learned_weights(*character(folder, "5k")[:2], method)
    seconds = {method: [] for method in METHODS}
    added = {method: 0.0 for method in METHODS}
    before = {method: 0.0 for method in METHODS}
    for _ in range(repeat):
        for method in METHODS:
            rss = _status_mib("VmRSS:")
            timing = []
            peak = peak_rss_added(lambda: timing.append(skin(mesh, skeleton, method)))
            seconds[method].append(timing[0])
            if peak > added[method]:
                added[method], before[method] = peak, rss
    baseline = statistics.median(seconds["geometric"])
    return {"size": size, "vertices": mesh.vertex_count, "bones": int(skeleton.deform.sum()), "methods": {
        method: {"median_s": statistics.median(seconds[method]), "min_s": min(seconds[method]),
                 "max_s": max(seconds[method]), "ratio": statistics.median(seconds[method]) / baseline,
                 "added_mib": added[method], "total_mib": before[method] + added[method]}
        for method in METHODS}}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", nargs="+", default=["5k", "104k"], choices=["5k", "53k", "104k", "264k"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--cache", help=argparse.SUPPRESS)
    parser.add_argument("--one", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        print(json.dumps(run_size(args.cache, args.one, args.repeat)))
        return 0
    with tempfile.TemporaryDirectory() as folder:
        if any(size != "5k" for size in args.sizes):
            write_cache(folder)
        print("| size | vertices | bones | method | median s | min-max s | x geometric | added MiB | total MiB |")
        print("|---|---|---|---|---|---|---|---|---|")
        for size in args.sizes:
            output = subprocess.run([sys.executable, __file__, "--cache", folder, "--one", size, "--repeat",
                                     str(args.repeat)], check=True, capture_output=True, text=True).stdout
            result = json.loads(output.strip().splitlines()[-1])
            for method, m in result["methods"].items():
                print(f"| {size} | {result['vertices']:,} | {result['bones']} | {method} | {m['median_s']:.2f} | "
                      f"{m['min_s']:.2f}-{m['max_s']:.2f} | {m['ratio']:.2f} | {m['added_mib']:.0f} | "
                      f"{m['total_mib']:.0f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
