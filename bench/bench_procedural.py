"""Benchmark the procedural character generator.

Usage (from the repo root): .venv/bin/python bench/bench_procedural.py [--count 400]

Generates ``--count`` characters (seeds 0..count-1, every kind) and prints
the median, 95th percentile and slowest time per character, and the vertex
count range.
"""

import argparse
import statistics
import sys
import time

import numpy as np

from autorig_addon.core.procedural import generate_character


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--count", type=int, default=400)
    args = parser.parse_args(argv)
    generate_character(0)  # warm-up
    seconds, vertices = [], []
    for seed in range(args.count):
        start = time.perf_counter()
        character = generate_character(seed)
        seconds.append(time.perf_counter() - start)
        vertices.append(character.mesh.vertex_count)
    ms = 1000 * np.asarray(seconds)
    print(f"{args.count} characters: median {statistics.median(ms):.1f} ms, 95th percentile "
          f"{np.percentile(ms, 95):.1f} ms, slowest {ms.max():.1f} ms; vertices {min(vertices)} to {max(vertices)} "
          f"(median {int(statistics.median(vertices))})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
