"""Markdown comparison of skin evaluation reports (from ``eval skin --out``).

Usage::

    .venv/bin/python scripts/skin_comparison_table.py out/eval_skin_geometric.json \\
        out/eval_skin_boneheat.json out/eval_skin_nearest_bone.json

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
    print(f"Each cell: {' / '.join(methods)}. Lower is better except precision and recall.\n")
    print("\n".join(character_table(reports, METRICS)))
    return 0


def character_table(reports, metrics) -> list:
    """Markdown lines: one row per character of the first report, each
    metric as ``first / second / ...`` (``-`` where a report did not score
    it), then the mean and median of each report over the characters it scored."""
    by_name = [{c["name"]: c for c in report["characters"]} for report in reports]
    names = [c["name"] for c in reports[0]["characters"]]
    lines = ["| character | category | " + " | ".join(metrics) + " |", "|---|---|" + "---|" * len(metrics)]
    for name in names:
        cells = [" / ".join(format_cell(table.get(name, {}).get(metric)) for table in by_name) for metric in metrics]
        lines.append(f"| {name} | {by_name[0][name].get('category', '')} | " + " | ".join(cells) + " |")
    for label, reduce in (("mean", np.mean), ("median", np.median)):
        cells = []
        for metric in metrics:
            values = [[table[n][metric] for n in names if metric in table.get(n, {})] for table in by_name]
            cells.append(" / ".join(format_cell(reduce(v) if v else None) for v in values))
        lines.append(f"| **{label}** | | " + " | ".join(cells) + " |")
    return lines


def format_cell(value) -> str:
    if value is None:
        return "-"
    value = float(value)
    if value == int(value) and abs(value) >= 1:
        return str(int(value))
    return f"{value:.3g}"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
