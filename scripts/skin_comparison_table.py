"""Markdown comparison of skin evaluation reports (from ``eval skin --out``).

Usage: .venv/bin/python scripts/skin_comparison_table.py out/eval_skin_geometric.json out/eval_skin_boneheat.json out/eval_skin_nearest_bone.json

Prints one row per character with each metric as ``first / second / ...``
in the order given, then the mean and median over all characters.
"""

import json
import sys

import numpy as np

METRICS = ("l1", "precision", "recall", "deform_mean", "deform_max", "unweighted")


def main(paths) -> int:
    reports = [json.load(open(path)) for path in paths]
    methods = [report["method"] for report in reports]
    by_name = [{c["name"]: c for c in report["characters"]} for report in reports]
    names = [c["name"] for c in reports[0]["characters"]]
    print(f"Each cell: {' / '.join(methods)}. Lower is better except precision and recall.\n")
    print("| character | category | " + " | ".join(METRICS) + " |")
    print("|---|---|" + "---|" * len(METRICS))
    for name in names:
        cells = [" / ".join(_format(table[name].get(metric)) for table in by_name) for metric in METRICS]
        print(f"| {name} | {by_name[0][name].get('category', '')} | " + " | ".join(cells) + " |")
    for label, reduce in (("mean", np.mean), ("median", np.median)):
        cells = []
        for metric in METRICS:
            values = [reduce([table[n][metric] for n in names if metric in table[n]]) for table in by_name]
            cells.append(" / ".join(_format(v) for v in values))
        print(f"| **{label}** | | " + " | ".join(cells) + " |")
    return 0


def _format(value) -> str:
    if value is None:
        return "-"
    value = float(value)
    if value == int(value) and abs(value) >= 1:
        return str(int(value))
    return f"{value:.3g}"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
