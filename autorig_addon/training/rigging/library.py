"""Writing the rig library (``train library``) of the training characters' key joints and surfaces.

The entries are :func:`...core.rigging.rig_library.build_rig_library`'s. No
validation character ever enters it: :func:`...core.dataset.cache.training_samples`
reads the split's training side alone.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

from ...core.dataset.cache import training_samples
from ...core.dataset.split import PURPOSE_SKELETON
from ...core.rigging.rig_library import LIBRARY_FILE, RigLibrary, build_rig_library


def write_rig_library(sample_dir: Path, output: Optional[Path] = None) -> RigLibrary:
    """Build the library from the cached training samples in ``sample_dir`` and write it (default: the shipped file)."""
    library = build_rig_library(training_samples(sample_dir, purpose=PURPOSE_SKELETON))
    library.save(Path(output or LIBRARY_FILE))
    return library
