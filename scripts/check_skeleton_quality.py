"""What the skeleton checks (core/rigging/quality.py) flag on the artists' own skeletons of the cached samples.

Usage: .venv/bin/python scripts/check_skeleton_quality.py [SAMPLE_DIR]

Each sample's deform skeleton (joints closer than the evaluation's merge
tolerance merged, as ``eval rig`` scores them), all checks but the one-tree check, is checked against its
mesh's voxel solid and, for a point the solid leaves out, the winding number of its surface (as Auto-Rig
checks); prints each flagged character with its problems, then
how many of how many were flagged. A check that flags many artists' rigs
would refuse sound predictions.
"""

import sys
from pathlib import Path

from autorig_addon.core.dataset.cache import default_cache_dir
from autorig_addon.core.dataset.sample import CharacterSample
from autorig_addon.core.errors import InputError
from autorig_addon.core.evaluation.skeleton_metrics import COINCIDENT_JOINT_FRACTION, merge_coincident_joints
from autorig_addon.core.rigging.joint_features import solid_depth
from autorig_addon.core.rigging.quality import enclosed_by, skeleton_problems


def main(folder: str) -> int:
    flagged = total = 0
    for path in sorted(Path(folder).glob("*.npz")):
        try:
            sample = CharacterSample.load(path)
        except InputError:
            continue
        skeleton = merge_coincident_joints(sample.skeleton.deform_subset(), COINCIDENT_JOINT_FRACTION)
        # An artist's deform bones alone are often several trees once the helpers between them go: that check
        # is for predictions, which are one tree by construction.
        problems = [problem for problem in skeleton_problems(skeleton, solid_depth(sample.mesh).at, sample.mesh,
                                                             enclosed_by(sample.mesh))
                    if "separate trees" not in problem]
        total += 1
        if problems:
            flagged += 1
            print(f"{sample.name}: {'; '.join(problems)}")
    print(f"\n{flagged} of {total} artists' skeletons flagged")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else str(default_cache_dir())))
