"""Paired benchmark of the leaky ReLU kernel (``core.nn.numpy_kernels.leaky_relu``).

Usage (from the repo root)::

    .venv/bin/python bench/bench_activation.py [--rounds 7]

On ``bench_skinning.py``'s 5k character (the synthetic humanoid, 5,060
vertices), times ``predict_skeleton`` (default template) and the default
skin method on its predicted skeleton, with the networks' leaky ReLU written
as ``np.where(x > 0, x, slope * x)`` (*before*) and as the kernel ships
(*after*: the larger of ``x`` and ``slope * x``, one temporary), swapped in
the kernels' table in turn within one process, after one untimed call of
each; prints the median seconds of each and their ratio, and the median
seconds spent inside the kernel itself per call of the step (the whole
step's time is noisy on a shared machine; the kernel's share is not).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from autorig_addon.core.nn import numpy_kernels
from autorig_addon.core.rigging import predict
from autorig_addon.core.skinning.methods import DEFAULT_SKIN_METHOD, skin_weights
from autorig_addon.core.skinning.options import SkinningOptions
from bench_skinning import character


def leaky_relu_with_where(x: np.ndarray, slope: float = numpy_kernels.LEAKY_RELU_SLOPE) -> np.ndarray:
    """The kernel as it was: three temporaries (the mask, ``slope * x``, the result)."""
    return np.where(x > 0, x, x * np.asarray(slope, dtype=x.dtype))


KERNELS = {"before": leaky_relu_with_where, "after": numpy_kernels.leaky_relu}


def timed(kernel, spent: list):
    """``kernel`` adding the seconds each call takes to ``spent[0]``."""
    def run(x, *args):
        start = time.perf_counter()
        result = kernel(x, *args)
        spent[0] += time.perf_counter() - start
        return result
    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    args = parser.parse_args()
    mesh = character(None, "5k")[0]
    skeleton = predict.predict_skeleton(mesh)
    jobs = {"predict_skeleton": lambda: predict.predict_skeleton(mesh),
            "skin_weights " + DEFAULT_SKIN_METHOD:
                lambda: skin_weights(mesh, skeleton, SkinningOptions(method=DEFAULT_SKIN_METHOD))}
    times = {(job, kernel): [] for job in jobs for kernel in KERNELS}
    inside = {(job, kernel): [] for job in jobs for kernel in KERNELS}
    try:
        for job, run in jobs.items():
            run()  # untimed: reads the weights files
            for round_ in range(args.rounds):
                # Alternate which goes first, so a drift of the machine's speed favours neither.
                for kernel in (("before", "after") if round_ % 2 == 0 else ("after", "before")):
                    spent = [0.0]
                    numpy_kernels.ACTIVATIONS["leaky_relu"] = timed(KERNELS[kernel], spent)
                    start = time.perf_counter()
                    run()
                    times[(job, kernel)].append(time.perf_counter() - start)
                    inside[(job, kernel)].append(spent[0])
    finally:
        numpy_kernels.ACTIVATIONS["leaky_relu"] = KERNELS["after"]
    print("| step | before: median s (in the kernel) | after: median s (in the kernel) | after / before |")
    print("|---|---|---|---|")
    for job in jobs:
        (before, after), (before_in, after_in) = ([statistics.median(table[(job, kernel)]) for kernel in KERNELS]
                                                  for table in (times, inside))
        print(f"| {job} | {before:.3f} ({before_in:.3f}) | {after:.3f} ({after_in:.3f}) | {after / before:.3f} |")


if __name__ == "__main__":
    main()
