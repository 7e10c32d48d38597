"""Evaluation reports (autorig_addon.core.evaluation.report): summary and markdown."""

import pytest

from autorig_addon.core.evaluation.report import markdown_report, summarise


def skin_entry(name, category, l1, unweighted=0, path=None):
    return {"name": name, "category": category, "path": path or f"/data/{name}.glb", "l1": l1, "precision": 1.0,
            "recall": 0.5, "deform_mean": 0.01, "deform_max": 0.1, "unweighted": unweighted, "seconds": 2.0}


def skin_report(method="geometric"):
    characters = [
        skin_entry("a", "biped", 0.1), skin_entry("b", "biped", 0.2, unweighted=3), skin_entry("c", "biped", 0.6),
        {"name": "rock", "category": "animal", "path": "/data/rock.glb", "error": "No armature | in 'rock'\nat all"},
    ]
    return {"task": "skin", "method": method, "characters": characters, "summary": summarise("skin", characters)}


def test_summary_per_category_and_overall():
    # biped l1 0.1, 0.2, 0.6: mean 0.3, median 0.2; unweighted 0, 3, 0: mean 1.
    # The failed rock counts only in "failed"; animal has no metric at all.
    summary = skin_report()["summary"]
    biped = summary["categories"]["biped"]
    assert (biped["count"], biped["failed"]) == (3, 0)
    assert biped["mean"]["l1"] == pytest.approx(0.3) and biped["median"]["l1"] == pytest.approx(0.2)
    assert biped["mean"]["unweighted"] == pytest.approx(1.0) and biped["median"]["unweighted"] == 0.0
    assert summary["categories"]["animal"] == {"count": 0, "failed": 1, "mean": {}, "median": {}}
    overall = summary["overall"]
    assert (overall["count"], overall["failed"]) == (3, 1) and overall["mean"]["recall"] == 0.5
    assert list(summary["categories"]) == ["animal", "biped"]


def test_markdown_tables():
    text = markdown_report(skin_report())
    lines = text.splitlines()
    assert lines[0] == "## skin: geometric"
    assert "### animal" in lines and "### biped" in lines
    # A failed character's message keeps the table intact: no "|" or newline.
    assert "| rock | failed: No armature / in 'rock' at all |" + " |" * 4 in lines
    assert "| character | l1 | precision | recall | deform_mean | deform_max | unweighted | seconds |" in lines
    assert "| b | 0.2 | 1 | 0.5 | 0.01 | 0.1 | 3 | 2 |" in lines
    assert "### Summary (mean / median)" in lines
    assert "| biped | 3 | 0 | 0.3 / 0.2 | 1 / 1 | 0.5 / 0.5 | 0.01 / 0.01 | 0.1 / 0.1 | 1 / 0 | 2 / 2 |" in lines
    assert lines[-1].startswith("| **overall** | 3 | 1 | 0.3 / 0.2 |")
    assert text.endswith("\n")


def test_markdown_beside_a_baseline_matches_characters_by_file():
    # The baseline scored a and b (under other names), not c: cells of c
    # carry no baseline value, and the baseline's means cover a and b only.
    baseline = skin_report("boneheat")
    baseline["characters"] = [skin_entry("A", "other", 0.5, path="/data/a.glb"),
                              skin_entry("B", "other", 0.7, path="/data/b.glb")]
    text = markdown_report(skin_report(), baseline)
    lines = text.splitlines()
    assert lines[0] == "## skin: geometric (/ boneheat)"
    assert "| a | 0.1 / 0.5 | 1 / 1 | 0.5 / 0.5 | 0.01 / 0.01 | 0.1 / 0.1 | 0 / 0 | 2 / 2 |" in lines
    assert "| c | 0.6 | 1 | 0.5 | 0.01 | 0.1 | 0 | 2 |" in lines
    assert "### Summary (mean: geometric / boneheat)" in lines
    # Baseline mean l1 over a and b: (0.5 + 0.7) / 2 = 0.6, in the category of our report.
    assert "| biped | 3 | 0 | 0.3 / 0.6 | 1 / 1 | 0.5 / 0.5 | 0.01 / 0.01 | 0.1 / 0.1 | 1 / 0 | 2 / 2 |" in lines
