"""``python -m autorig_addon train``: train the skinning and skeleton networks.

Registered by :mod:`autorig_addon.cli.main` when this package is present
(a source checkout; the extension zip leaves it out).

``train samples`` builds the cached samples of the characters (needs the
``bpy`` module); ``train skin --model NAME`` and ``train rig --model NAME``
train one network from those samples alone (torch, no Blender: it also
runs on a machine without bpy) and write its weights where the extension
reads them. Fixed seed, so the same command gives the same weights on the
same device; see ``docs/models.md``. ``train library`` writes the rig
library of the training characters' key joints from the same samples
(:mod:`.rigging.library`; numpy alone).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from ..core.dataset.cache import default_cache_dir
from ..core.rigging.networks import NETWORK_NAMES as RIG_NETWORK_NAMES
from ..core.rigging.networks import RIG_NETWORKS
from ..core.skinning.learned.networks import NETWORK_NAMES, SKIN_NETWORKS
from .rigging.proportions import DEFAULT_PROPORTION_VARIANTS

NAME = "train"
HELP = "Train the skinning and skeleton networks from cached samples of the training characters"

#: Where the characters of ``data_split.json`` lie, relative to the repository.
DEFAULT_CHARACTERS = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "characters"
#: ``--device`` choices (``auto``: the GPU when torch sees one; :func:`.runs.pick_device`).
DEVICES = ("auto", "cpu", "cuda")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("what", choices=("skin", "rig", "library", "samples"),
                        help="skin: train one skinning network; rig: train one skeleton network; library: write the "
                             "rig library of the training characters' key joints; samples: build the cached "
                             "samples (needs bpy)")
    parser.add_argument("--model", choices=NETWORK_NAMES + RIG_NETWORK_NAMES,
                        help=f"The network to train: train skin {'|'.join(NETWORK_NAMES)}; "
                             f"train rig {'|'.join(RIG_NETWORK_NAMES)}")
    shipped = ", ".join(f"{name} {spec.training.epochs} epochs at {spec.training.learning_rate:g}"
                        for name, spec in {**SKIN_NETWORKS, **RIG_NETWORKS}.items())
    parser.add_argument("--epochs", type=int, default=None,
                        help=f"Epochs (default: the shipped weights' run: {shipped})")
    parser.add_argument("--learning-rate", type=float, default=None,
                        help="Adam's starting learning rate (default: the shipped weights' run, see --epochs)")
    parser.add_argument("--seed", type=int, default=0, help="Random seed (default 0)")
    parser.add_argument("--device", choices=DEVICES, default="auto",
                        help="auto: the GPU when torch sees one (default auto)")
    parser.add_argument("--samples", type=Path, default=None,
                        help="Folder of cached samples (default: the cache, ~/.cache/autorig_addon/samples)")
    parser.add_argument("--examples", type=Path, default=None,
                        help="Folder of built training examples (default: the cache)")
    parser.add_argument("--characters", type=Path, default=DEFAULT_CHARACTERS,
                        help="Folder of the rigged characters (train samples; default ../shared/data/characters)")
    parser.add_argument("--output", type=Path, default=None,
                        help="Weights file (or, train library, library file) to write (default: the extension's own, "
                             "core/skinning/learned/trained/ or core/rigging/trained/)")
    parser.add_argument("--no-augment", action="store_true", help="Train on the characters as they are (train skin)")
    parser.add_argument("--procedural", type=int, default=0,
                        help="Also train on this many procedural characters (seeds 0 to N-1, exact skeletons; "
                             "never held out; default 0)")
    parser.add_argument("--proportion-variants", type=int, default=DEFAULT_PROPORTION_VARIANTS,
                        help="train rig --model landmarks: reshaped copies (other leg, trunk and head lengths) of "
                             f"each training character with key joints (default {DEFAULT_PROPORTION_VARIANTS})")


def run(args: argparse.Namespace) -> int:
    # The command line imports this module while it starts, so its own
    # modules are imported when the command runs.
    from ..cli.exit_codes import EXIT_FAILED, EXIT_OK, UsageError

    samples = args.samples or default_cache_dir()
    if args.what == "samples":
        return EXIT_FAILED if _build_samples(args.characters, samples) else EXIT_OK
    if args.what == "library":
        from .rigging.library import write_rig_library

        library = write_rig_library(samples, args.output)
        counts = {kind: int((library.kinds == kind).sum()) for kind in ("biped", "quadruped", "other")}
        print(f"rig library: {len(library.names)} training characters ({counts['biped']} bipeds, "
              f"{counts['quadruped']} quadrupeds, {counts['other']} other), key joints of "
              f"{int(library.known.any(axis=1).sum())}", file=sys.stderr)
        return EXIT_OK
    names = NETWORK_NAMES if args.what == "skin" else RIG_NETWORK_NAMES
    if args.model not in names:
        raise UsageError(f"train {args.what} needs --model " + "|".join(names) + ".")
    if args.what == "skin":
        from .skinning.learned.train import run_training

        record = run_training(args.model, sample_dir=samples, examples_dir=args.examples, epochs=args.epochs,
                              seed=args.seed, device=args.device, output=args.output, augment=not args.no_augment,
                              learning_rate=args.learning_rate, procedural=args.procedural)
    else:
        from .rigging.train import run_rig_training

        record = run_rig_training(args.model, sample_dir=samples, examples_dir=args.examples, epochs=args.epochs,
                                  learning_rate=args.learning_rate, seed=args.seed, device=args.device,
                                  output=args.output, procedural=args.procedural,
                                  proportion_variants=args.proportion_variants)
    print(f"{record.network}: kept epoch {record.best_epoch} of {record.epochs}, held-out {record.score_name} "
          f"{record.best_score:.4f}, {record.seconds:.0f} s on {record.device}", file=sys.stderr)
    return EXIT_OK


def _build_samples(characters: Path, samples: Path, split_file: Path | None = None) -> int:
    """Build (or find cached) the sample of every character of the split, one
    file at a time so that one file that cannot be read does not stop the
    others; print a line per file and a summary on stderr.

    Returns
    -------
    int, the number of files that failed (each printed with its reason).
    """
    from ..blender.characters import build_character_samples
    from ..core.dataset.split import DEFAULT_SPLIT_FILE, read_data_split
    from ..core.errors import InputError

    if not characters.is_dir():
        raise InputError(f"The characters folder '{characters}' does not exist (--characters).")
    split = read_data_split(split_file or DEFAULT_SPLIT_FILE)
    paths = [characters / path for path in split.subset("all")]
    started, failed = time.perf_counter(), {}
    for index, path in enumerate(paths):
        try:
            sample = build_character_samples([path], cache_dir=samples, root=characters, split=split)[0]
            outcome = f"{len(sample.vertices)} vertices, {sample.facing}"
        except Exception as error:  # noqa: BLE001 - one unreadable file must not stop the others
            failed[path] = str(error) or type(error).__name__
            outcome = f"FAILED: {failed[path]}"
        print(f"[{index + 1}/{len(paths)}] {path.relative_to(characters).as_posix()}: {outcome}", file=sys.stderr,
              flush=True)
    print(f"{len(paths) - len(failed)} samples in {os.fspath(samples)} ({time.perf_counter() - started:.0f} s); "
          f"{len(failed)} failed; {len(split.excluded)} files left out by the split (data_split.json 'excluded')",
          file=sys.stderr)
    return len(failed)
