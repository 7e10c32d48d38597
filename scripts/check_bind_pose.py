"""Check that every rigged character deforms to itself at rest.

For each file under the characters folder (default ``../shared/data/characters``
next to the repository) it runs ``blender.bind_pose.check_bind_pose`` and
prints a markdown table: the largest vertex movement in REST position and in
the file's default pose (share of the character size), the verdict and the
reasons found. Importer messages go to stderr.

For ``.glb`` files it also reports how far Blender's rest skeleton lies from
the bind pose stored in the file's inverse bind matrices (largest joint
distance in armature space, share of the skeleton's extent). Where the two
differ, the glTF importer has re-posed the mesh into its rest skeleton
(``skin_into_bind_pose``), so mesh and skeleton still agree inside Blender,
but the rest pose is not the one the file was bound in.

Usage (from the repo root)::

    .venv/bin/python scripts/check_bind_pose.py [FOLDER] [--json FILE]
"""

import argparse
import json
import struct
import sys
from pathlib import Path

import bpy  # noqa: F401  (Blender before the add-on's Blender modules)
import numpy as np

from autorig_addon.blender.bind_pose import BIND_POSE_TOLERANCE, check_bind_pose
from autorig_addon.cli.batch import stdout_to_stderr
from autorig_addon.core.io.scene_formats import scene_files

REPO = Path(__file__).resolve().parent.parent

DEFAULT_FOLDER = REPO.parent / "shared" / "data" / "characters"


def _number(value) -> str:
    return "n/a" if value is None or value != value else f"{value:.2e}"


def inverse_bind_offset(path: Path):
    """Largest distance between a joint's head in Blender's rest pose and its
    position in the file's inverse bind matrices, as a share of the rest
    skeleton's extent (armature space); None for anything but ``.glb``.
    Call it with ``path`` loaded (it reads the scene's armature)."""
    if path.suffix.lower() != ".glb":
        return None
    from autorig_addon.blender.characters import choose_armature

    data = path.read_bytes()
    json_length = struct.unpack_from("<I", data, 12)[0]
    document = json.loads(data[20:20 + json_length])
    binary_start = 20 + json_length + 8
    armature, _, _ = choose_armature()
    heads = {bone.name: np.array(bone.head_local) for bone in armature.data.bones}
    extent = np.linalg.norm(np.ptp(np.array(list(heads.values())), axis=0))
    largest = 0.0
    for skin in document.get("skins", []):
        if "inverseBindMatrices" not in skin:
            continue
        accessor = document["accessors"][skin["inverseBindMatrices"]]
        view = document["bufferViews"][accessor["bufferView"]]
        start = binary_start + view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
        columns = np.frombuffer(data, dtype="<f4", count=16 * accessor["count"], offset=start).reshape(-1, 4, 4)
        for joint, inverse_bind in zip(skin["joints"], columns):
            name = document["nodes"][joint].get("name")
            if name in heads:
                x, y, z = np.linalg.inv(inverse_bind.T.astype(np.float64))[:3, 3]
                # glTF is y-up; the importer maps (x, y, z) to Blender's (x, -z, y).
                largest = max(largest, float(np.linalg.norm(np.array([x, -z, y]) - heads[name])))
    return largest / extent if extent > 0 else 0.0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", nargs="?", default=str(DEFAULT_FOLDER), help="Folder of rigged characters")
    parser.add_argument("--json", metavar="FILE", help="Also write the results as JSON")
    args = parser.parse_args(argv)
    root = Path(args.folder)
    files = scene_files(root)
    rows, results = [], []
    for path in files:
        name = path.relative_to(root).as_posix()
        try:
            with stdout_to_stderr():
                check = check_bind_pose(path)
                offset = inverse_bind_offset(path)
        except Exception as error:  # noqa: BLE001 - report and go on with the next file
            rows.append(f"| {name} | | | | | failed | {error} |")
            results.append({"file": name, "error": str(error)})
            continue
        verdict = "yes" if check.deforms_to_itself else "**no**"
        rows.append(f"| {name} | {check.vertex_count} | {_number(check.rest_error)} | {_number(check.pose_error)} "
                    f"| {_number(offset)} | {verdict} | {'; '.join(check.reasons)} |")
        results.append({"file": name, "vertices": check.vertex_count, "rest_error": check.rest_error,
                        "pose_error": None if check.pose_error != check.pose_error else check.pose_error,
                        "inverse_bind_offset": offset, "deforms_to_itself": check.deforms_to_itself,
                        "reasons": list(check.reasons)})
    print(f"Tolerance: {BIND_POSE_TOLERANCE:g} of the character size (bounding-box diagonal).\n")
    print("| file | vertices | rest error | default-pose error | rest vs inverse bind | deforms to itself | reasons |")
    print("|---|---|---|---|---|---|---|")
    print("\n".join(rows))
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
