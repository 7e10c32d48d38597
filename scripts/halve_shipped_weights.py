"""Rewrite the shipped network weights at half precision, as training now writes them.

Training (``python -m autorig_addon train rig|skin``) saves every network at
half precision (``core/nn/weights_io.py``); this rewrites the weights trained
before that change the same way, metadata kept, so the shipped files need no
retraining to shrink. It prints each file's size before and after and the
largest rounding error relative to each array's largest value. A file
already at half precision keeps its values (its vectors, halved before
2026-12-07's evening, are then stored at full precision as training now
writes them: the same numbers, a few kilobytes more).

    .venv/bin/python scripts/halve_shipped_weights.py
"""

from __future__ import annotations

import numpy as np

from autorig_addon.core.nn.weights_io import load_weights, save_weights
from autorig_addon.core.rigging.networks import RIG_NETWORKS
from autorig_addon.core.skinning.learned.networks import SKIN_NETWORKS


def main() -> None:
    for spec in [*RIG_NETWORKS.values(), *SKIN_NETWORKS.values()]:
        path = spec.weights_file
        before = path.stat().st_size
        loaded = load_weights(str(path))
        save_weights(str(path), loaded.weights, loaded.metadata, half_precision=True)
        halved = load_weights(str(path)).weights
        worst = max((np.abs(halved[name] - array).max() / max(np.abs(array).max(), 1e-30)
                     for name, array in loaded.weights.items() if array.dtype.kind == "f" and array.size), default=0.0)
        print(f"{spec.name:14s} {before / 1e6:6.3f} MB -> {path.stat().st_size / 1e6:6.3f} MB, "
              f"largest relative rounding {worst:.2e}")


if __name__ == "__main__":
    main()
