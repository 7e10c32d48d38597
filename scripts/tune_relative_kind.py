"""How far a body's nearest known body may lie to give it its kind (``rig_library.RELATIVE_KIND_DISTANCE``).

Usage: .venv/bin/python scripts/tune_relative_kind.py [SAMPLE_DIR]

On the cached training characters alone (never a validation one): each is
measured against every training character of another family (``data_split.json``'s
families: near-duplicates and shared rigs go together), by the symmetric
Chamfer distance between 2,000 points on its surface (``nearest_character.surface_points``)
and the other's points as the library stores them (``rig_library.library_points``,
``as_stored``); the 12 nearest by a one-way screen on 300 points measured in full. Prints, per
limit, how many bodies that are not humanoids have a humanoid nearest within it
(a body the rule would wrongly make a biped) and how many humanoids do, then
the same for quadrupeds, and every wrong nearest with its distance.
"""

import json
import sys

import numpy as np
from scipy.spatial import cKDTree

from autorig_addon.core.dataset.cache import default_cache_dir, training_samples
from autorig_addon.core.dataset.split import DEFAULT_SPLIT_FILE, PURPOSE_SKELETON
from autorig_addon.core.evaluation.skeleton_metrics import symmetric_chamfer
from autorig_addon.core.rigging.nearest_character import SURFACE_POINTS, surface_points
from autorig_addon.core.rigging.rig_library import as_stored, library_points
from autorig_addon.training.runs import character_families

LIMITS = (0.03, 0.035, 0.04, 0.045, 0.046, 0.05, 0.055, 0.06)
SCREEN, MEASURED = 300, 12


def main(sample_dir) -> int:
    with open(DEFAULT_SPLIT_FILE) as stream:
        categories = {path.rsplit(".", 1)[0]: category
                      for category, paths in json.load(stream)["categories"].items() for path in paths}
    pool = training_samples(sample_dir, purpose=PURPOSE_SKELETON)
    names = [sample.name for sample in pool]
    families = character_families(names)
    points = [surface_points(sample.vertices, sample.triangles, SURFACE_POINTS) for sample in pool]
    trees = [cKDTree(each) for each in points]
    stored = [as_stored(library_points(sample.vertices, sample.triangles),
                        np.array([sample.vertices.min(axis=0), sample.vertices.max(axis=0)])) for sample in pool]
    stored_trees = [cKDTree(each) for each in stored]
    nearest = []  # (name, category, nearest's category, distance)
    for index, name in enumerate(names):
        others = [other for other in range(len(names)) if families[names[other]] != families[name]]
        screen = [stored_trees[other].query(points[index][:SCREEN])[0].mean() for other in others]
        measured = [others[rank] for rank in np.argsort(screen)[:MEASURED]]
        distances = [symmetric_chamfer(points[index], stored[other], trees[index]) for other in measured]
        best = int(np.argmin(distances))
        nearest.append((name, categories.get(name), categories.get(names[measured[best]]), float(distances[best])))
    for kind in ("humanoid", "quadruped"):
        print(f"nearest body a {kind}:")
        for limit in LIMITS:
            wrong = sum(1 for _, own, near, distance in nearest if own != kind and near == kind and distance <= limit)
            right = sum(1 for _, own, near, distance in nearest if own == kind and near == kind and distance <= limit)
            total = sum(own == kind for _, own, _, _ in nearest)
            print(f"  within {limit}: {wrong} of other kinds, {right} of {total} {kind}s")
        print("  " + ", ".join(f"{name} ({own}) {distance:.3f}" for name, own, near, distance in sorted(
            nearest, key=lambda row: row[3]) if own != kind and near == kind))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else default_cache_dir()))
