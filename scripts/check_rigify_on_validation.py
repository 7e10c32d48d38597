"""Auto-Rig with Rigify's control rig on every validation biped and quadruped (issue 16: Rigify generation
succeeds on each, or refuses with a reason).

Usage (from the repo root, with bpy in the venv)::

    .venv/bin/python scripts/check_rigify_on_validation.py [CHARACTERS_FOLDER] [--out FOLDER]

Runs ``python -m autorig_addon rig FILES --rigify --replace`` (the artist's rig replaced, the default
template and skin) on the validation characters ``data_split.json`` calls humanoid or quadruped, writes the
command's JSON summary beside the rigged files, and prints how each ended: Rigify's control rig built, the
plain skeleton kept with the reason there is none, or refused with the reason.
"""

from __future__ import annotations

import argparse
import collections
import json
import tempfile
from pathlib import Path

from autorig_addon.cli.main import main as cli_main
from autorig_addon.core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split

DEFAULT_CHARACTERS = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "characters"
#: The split's kinds offered to Rigify.
KINDS = ("humanoid", "quadruped")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("characters", nargs="?", type=Path, default=DEFAULT_CHARACTERS)
    parser.add_argument("--out", type=Path, default=None, help="Folder for the rigged files (default: a temporary one)")
    args = parser.parse_args()
    split = read_data_split(DEFAULT_SPLIT_FILE)
    files = [str(args.characters / path) for path in split.validation if split.categories.get(path) in KINDS]
    out = args.out or Path(tempfile.mkdtemp(prefix="rigify_validation_"))
    summary = out / "summary.json"
    cli_main(["rig", *files, "--rigify", "--replace", "--out", str(out), "--summary", str(summary), "--quiet"])
    report = json.loads(summary.read_text())
    outcomes = collections.Counter()
    for result in report["succeeded"]:
        name = Path(result["input"]).relative_to(args.characters).as_posix()
        if result["rigify"]:
            outcomes[f"Rigify control rig ({result['template']})"] += 1
            continue
        outcomes[f"plain skeleton kept ({result['template']})"] += 1
        reasons = [note for note in result["notes"] if note.startswith("no Rigify control rig")]
        print(f"{name}: {result['template']}, {reasons[0] if reasons else 'no reason given'}")
    for failure in report["failed"]:
        outcomes["refused"] += 1
        print(f"{Path(failure['input']).relative_to(args.characters).as_posix()}: refused: {failure['error']}")
    seconds = sorted(result["seconds"] for result in report["succeeded"])
    print(f"{len(files)} characters: " + ", ".join(f"{count} {outcome}" for outcome, count in outcomes.items()))
    if seconds:
        print(f"seconds per character: median {seconds[len(seconds) // 2]:.2f}, at most {seconds[-1]:.2f}")
    print(f"summary: {summary}")


if __name__ == "__main__":
    main()
