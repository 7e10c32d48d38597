"""Markdown comparison of rig evaluation reports (from ``eval rig --out``).

Usage: .venv/bin/python scripts/rig_comparison_table.py out/eval_rig_predicted.json out/eval_rig_nearest_character.json

Prints a summary with one row per method (each metric as ``mean / median``
over the characters it scored, RigNet's metrics: Chamfer distances in units
of the largest side of the character's bounding box), then one row per
character with each metric as ``first / second / ...`` in the order given
(the table of scripts/skin_comparison_table.py), after the same per kind
and per skeleton family of ``data_split.json``.
"""

import json
import sys

import numpy as np

from autorig_addon.core.evaluation.report import METRIC_KEYS
from skin_comparison_table import character_table, family_groups, format_cell, group_tables, kind_groups

METRICS = METRIC_KEYS["rig"]
#: Metrics where higher is better; lower is better for the others.
HIGHER_IS_BETTER = ("iou", "precision", "recall", "key_joints", "key_joints_present")


def main(paths) -> int:
    reports = [json.load(open(path)) for path in paths]
    methods = [report["method"] for report in reports]
    print("### Summary (mean / median over the characters each method scored)\n")
    print("| method | scored | failed | " + " | ".join(METRICS) + " |")
    print("|---|---|---|" + "---|" * len(METRICS))
    for method, report in zip(methods, reports):
        scored = [entry for entry in report["characters"] if "error" not in entry]
        cells = []
        for metric in METRICS:
            values = [entry[metric] for entry in scored if metric in entry]
            cells.append(f"{format_cell(np.mean(values))} / {format_cell(np.median(values))}" if values else "-")
        failed = len(report["characters"]) - len(scored)
        print(f"| {method} | {len(scored)} | {failed} | " + " | ".join(cells) + " |")
    print("\n### Per kind\n")
    print("\n".join(group_tables(reports, METRICS, kind_groups(reports[0]), "kind")))
    print("### Per skeleton family\n")
    print("\n".join(group_tables(reports, METRICS, family_groups(reports[0]), "family")))
    print(f"\n### Per character\n\nEach cell: {' / '.join(methods)}. Lower is better except "
          f"{', '.join(HIGHER_IS_BETTER)}.\n")
    print("\n".join(character_table(reports, METRICS)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
