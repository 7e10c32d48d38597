"""Markdown tables of the key-joint score of rig evaluation reports (from ``eval rig --out``), side by side.

Usage: .venv/bin/python scripts/key_joint_table.py out/rignet.json out/rignet_free_form.json out/nearest_character.json

The score (``core/evaluation/key_joint_metrics.py``): the share of the
artist's key joints (hips, neck, head, per side shoulder, elbow, wrist, hip,
knee, ankle; quadrupeds' front legs take the arm roles) that a method names
for their role and places within 0.05 of the character's largest side. Only
characters whose artist bone names say their key joints are scored. Prints
the mean per kind (humanoid, quadruped) with the share of key joints each
method has at all and how many characters get every key joint present, the
per-role shares, then one row per character.
"""

import json
import sys

import numpy as np

from autorig_addon.core.skeleton.key_joints import KEY_JOINTS

KINDS = ("humanoid", "quadruped")


def scored(report):
    return {entry["name"]: entry for entry in report["characters"]
            if entry.get("category") in KINDS and "key_joints" in entry}


def main(paths) -> int:
    reports = [json.load(open(path)) for path in paths]
    methods = [report["method"] for report in reports]
    entries = [scored(report) for report in reports]
    names = sorted(set.intersection(*[set(entry) for entry in entries]))
    print("| kind | characters | " + " | ".join(f"{m}: right / present / all present" for m in methods) + " |")
    print("|---|---|" + "---|" * len(methods))
    for kind in KINDS:
        kind_names = [name for name in names if entries[0][name]["category"] == kind]
        cells = []
        for entry in entries:
            right = np.mean([entry[name]["key_joints"] for name in kind_names])
            present = np.mean([entry[name]["key_joints_present"] for name in kind_names])
            complete = sum(entry[name]["key_joints_present"] == 1.0 for name in kind_names)
            cells.append(f"{right:.1%} / {present:.1%} / {complete}")
        print(f"| {kind} | {len(kind_names)} | " + " | ".join(cells) + " |")
    print("\nPer role (share right over the characters whose artist rig has the role):\n")
    print("| role | " + " | ".join(f"{kind}: " + " / ".join(methods) for kind in KINDS) + " |")
    print("|---|" + "---|" * len(KINDS))
    for role in KEY_JOINTS:
        cells = []
        for kind in KINDS:
            shares = []
            for entry in entries:
                errors = [entry[name]["key_joint_errors"].get(role, "missing") for name in names
                          if entry[name]["category"] == kind]
                errors = [error for error in errors if error != "missing"]
                shares.append(f"{np.mean([e is not None and e <= 0.05 for e in errors]):.0%}" if errors else "-")
            cells.append(" / ".join(shares))
        print(f"| {role} | " + " | ".join(cells) + " |")
    print("\nPer character (share right, " + " / ".join(methods) + "):\n")
    print("| character | kind | key joints scored | " + " | ".join(methods) + " |")
    print("|---|---|---|" + "---|" * len(methods))
    for name in names:
        first = entries[0][name]
        print(f"| {name} | {first['category']} | {first['key_joint_count']} | "
              + " | ".join(f"{entry[name]['key_joints']:.2f}" for entry in entries) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
