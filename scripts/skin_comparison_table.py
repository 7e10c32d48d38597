"""Markdown comparison of skin evaluation reports (from ``eval skin --out``).

Usage::

    .venv/bin/python scripts/skin_comparison_table.py out/eval_skin_geometric.json \\
        out/eval_skin_boneheat.json out/eval_skin_nearest_bone.json

Prints, per kind of character (the split's categories) and per skeleton
family of ``data_split.json``, each method's mean and median of every
metric; then one row per character with each metric as ``first / second /
...`` in the order given, and the mean and median over all characters.
"""

import json
import os
import sys
from pathlib import Path

import numpy as np

#: The split whose families group the characters.
SPLIT_FILE = Path(__file__).resolve().parents[1] / "data_split.json"

METRICS = ("l1", "precision", "recall", "deform_mean", "deform_max", "unweighted")


def main(paths) -> int:
    reports = [json.load(open(path)) for path in paths]
    methods = [report["method"] for report in reports]
    print("\n".join(group_tables(reports, METRICS, kind_groups(reports[0]), "kind")))
    print("\n".join(group_tables(reports, METRICS, family_groups(reports[0]), "family")))
    print(f"Each cell: {' / '.join(methods)}. Lower is better except precision and recall.\n")
    print("\n".join(character_table(reports, METRICS)))
    return 0


def kind_groups(report) -> dict:
    """``{kind: [names]}`` of a report's characters, in the split's kind order, then ``all``."""
    groups = {}
    for entry in report["characters"]:
        groups.setdefault(entry.get("category", ""), []).append(entry["name"])
    order = ("humanoid", "quadruped", "bird", "fish", "other")
    ordered = {kind: groups[kind] for kind in order if kind in groups}
    ordered.update({kind: names for kind, names in groups.items() if kind not in ordered})
    ordered["all"] = [entry["name"] for entry in report["characters"]]
    return ordered


def family_groups(report) -> dict:
    """``{label: [names]}`` of a report's characters by the split's skeleton
    family, labelled by the family's first member and its size here."""
    document = json.loads(SPLIT_FILE.read_text(encoding="utf-8"))
    family_of = {os.path.splitext(member)[0]: index for index, family in enumerate(document["families"])
                 for member in family["members"]}
    grouped = {}
    for entry in report["characters"]:
        grouped.setdefault(family_of.get(entry["name"], -1), []).append(entry["name"])
    labels = {}
    for family, names in sorted(grouped.items(), key=lambda item: (-len(item[1]), sorted(item[1])[0])):
        first = sorted(names)[0]
        labels[f"{first}{f' +{len(names) - 1}' if len(names) > 1 else ''}"] = names
    return labels


def group_tables(reports, metrics, groups: dict, heading: str) -> list:
    """Markdown lines: per metric, one row per group (its size) and one
    column per report, each cell ``mean / median`` over the group's
    characters the report scored (``-`` where it scored none)."""
    by_name = [{c["name"]: c for c in report["characters"]} for report in reports]
    methods = [report["method"] for report in reports]
    lines = [f"Per {heading}: each cell mean / median over the characters the method scored.", ""]
    lines += [f"| {heading} | n | " + " | ".join(methods) + " |", "|---|---|" + "---|" * len(methods)]
    for metric in metrics:
        lines.append(f"| **{metric}** | |" + " |" * len(methods))
        for label, names in groups.items():
            cells = []
            for table in by_name:
                values = [table[n][metric] for n in names if metric in table.get(n, {})]
                cells.append(f"{format_cell(np.mean(values))} / {format_cell(np.median(values))}" if values else "-")
            lines.append(f"| {label} | {len(names)} | " + " | ".join(cells) + " |")
    return lines + [""]


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
