"""The report of an evaluation: summary statistics and markdown tables.

An evaluation report is a dict (written as JSON by ``eval --out``)::

    {"task": "skin", "method": "boneheat",
     "characters": [{"name", "category", "path", "l1", ..., "seconds", "unweighted"} |
                    {"name", "category", "path", "error"}],
     "summary": {"categories": {CATEGORY: {"count", "failed", "mean": {...}, "median": {...}}},
                 "overall": {...}}}

:func:`summarise` computes ``summary`` from ``characters``;
:func:`markdown_report` prints the whole as tables.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np

#: Metric keys of each task, in table order.
METRIC_KEYS = {
    "skin": ("l1", "precision", "recall", "deform_mean", "deform_max"),
    "rig": ("cd_j2j", "cd_j2b", "cd_b2b", "iou", "precision", "recall", "tree_edit", "key_joints",
            "key_joints_present"),
    "transfer": ("stretch_p99", "stretch_max", "deform_mean", "deform_max"),
}
#: Extra per-character keys shown in the tables and summarised.
EXTRA_KEYS = {"skin": ("unweighted", "seconds"), "rig": ("seconds",), "transfer": ("seconds",)}
#: Significant digits of metric values in the markdown tables.
TABLE_DIGITS = 4


def summarise(task: str, characters: list[dict]) -> dict:
    """Mean and median of every metric per category and over all characters.

    Returns
    -------
    dict: ``categories`` maps each category to ``{"count", "failed",
    "mean": {key: value}, "median": {key: value}}``; ``overall`` is the same
    over every character. Failed characters only count in ``failed``; a
    metric no character has (e.g. ``deform_mean`` of garments) is left out.
    """
    keys = METRIC_KEYS[task] + EXTRA_KEYS[task]
    groups: dict[str, list[dict]] = {}
    for entry in characters:
        groups.setdefault(entry["category"], []).append(entry)

    def statistics(entries: list[dict]) -> dict:
        done = [entry for entry in entries if "error" not in entry]
        result = {"count": len(done), "failed": len(entries) - len(done), "mean": {}, "median": {}}
        for key in keys:
            values = [float(entry[key]) for entry in done if key in entry]
            if values:
                result["mean"][key] = float(np.mean(values))
                result["median"][key] = float(np.median(values))
        return result

    return {
        "categories": {category: statistics(entries) for category, entries in sorted(groups.items())},
        "overall": statistics(characters),
    }


def _cell(value) -> str:
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        return str(int(value))
    if isinstance(value, float):
        return f"{value:.{TABLE_DIGITS}g}"
    return str(value)


def markdown_report(report: dict, baseline: Optional[dict] = None) -> str:
    """The report as markdown: one table per category, then the summary.

    With a ``baseline`` report (same task, e.g. ``boneheat``), each metric
    cell reads ``ours / baseline`` where the baseline scored that character,
    and the summary compares the means.
    """
    task = report["task"]
    keys = METRIC_KEYS[task] + EXTRA_KEYS[task]
    base_entries = _matching_entries(report, baseline) if baseline else {}
    title = f"## {task}: {report['method']}" + (f" (/ {baseline['method']})" if baseline else "")
    lines = [title, ""]
    by_category: dict[str, list[dict]] = {}
    for entry in report["characters"]:
        by_category.setdefault(entry["category"], []).append(entry)
    for category, entries in sorted(by_category.items()):
        shown = [key for key in keys if any(key in entry for entry in entries)] or list(METRIC_KEYS[task])
        lines += [f"### {category}", "", "| character | " + " | ".join(shown) + " |", "|---" * (len(shown) + 1) + "|"]
        for entry in entries:
            if "error" in entry:
                message = entry["error"].replace("|", "/").replace("\n", " ")
                lines.append(f"| {entry['name']} | failed: {message} |" + " |" * (len(shown) - 1))
                continue
            base = base_entries.get(entry["path"], {})
            cells = [_cell(entry.get(key, "")) + (f" / {_cell(base[key])}" if key in base else "") for key in shown]
            lines.append(f"| {entry['name']} | " + " | ".join(cells) + " |")
        lines.append("")
    summary = report["summary"]
    # The baseline is summarised over the characters both reports scored, so the means compare like with like.
    base_summary = summarise(task, list(base_entries.values())) if baseline else {}
    base_rows = dict(base_summary.get("categories", {}),
                     **({"**overall**": base_summary["overall"]} if base_summary else {}))
    shown = [key for key in keys if key in summary["overall"]["mean"]]
    heading = ("### Summary (mean / median)" if not baseline
               else f"### Summary (mean: {report['method']} / {baseline['method']})")
    lines += [heading, "", "| category | n | failed | " + " | ".join(shown) + " |", "|---" * (len(shown) + 3) + "|"]
    rows = list(summary["categories"].items()) + [("**overall**", summary["overall"])]
    for category, statistics in rows:
        other = base_rows.get(category, {}).get("mean", {}) if baseline else None
        cells = []
        for key in shown:
            if key not in statistics["mean"]:
                cells.append("")
            elif baseline:
                cells.append(_cell(statistics["mean"][key]) + (f" / {_cell(other[key])}" if key in other else ""))
            else:
                cells.append(f"{_cell(statistics['mean'][key])} / {_cell(statistics['median'][key])}")
        lines.append(f"| {category} | {statistics['count']} | {statistics['failed']} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _matching_entries(report: dict, baseline: dict) -> dict:
    """Baseline entries scored for the same files as ``report``'s, by path."""
    scored = {str(Path(entry["path"]).resolve()): entry for entry in baseline["characters"] if "error" not in entry}
    matched = {}
    for entry in report["characters"]:
        other = scored.get(str(Path(entry["path"]).resolve()))
        if other is not None:
            matched[entry["path"]] = {**other, "category": entry["category"]}
    return matched
