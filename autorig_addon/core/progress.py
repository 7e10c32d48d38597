"""Progress reporting shared by long-running core functions.

A core function takes ``progress: ProgressCallback | None`` and calls it with
a fraction in [0, 1] and a short message. The callback may raise
:class:`~autorig_addon.core.errors.Cancelled` to stop the work; core functions
never write partial results, so cancelling is always safe.
"""

from typing import Callable, Optional

ProgressCallback = Callable[[float, str], None]


def report(progress: Optional[ProgressCallback], fraction: float, message: str) -> None:
    if progress is not None:
        progress(min(max(float(fraction), 0.0), 1.0), message)


def sub_progress(progress: Optional[ProgressCallback], start: float, end: float) -> Optional[ProgressCallback]:
    """A callback that maps [0, 1] onto [start, end] of ``progress``."""
    if progress is None:
        return None

    def scaled(fraction: float, message: str) -> None:
        progress(start + (end - start) * min(max(fraction, 0.0), 1.0), message)

    return scaled


def labelled_progress(progress: Optional[ProgressCallback], label: str) -> Optional[ProgressCallback]:
    """A callback that passes on the fraction and puts ``label: `` before each message
    of ``progress`` (a step that runs the same work as a later one says which it is)."""
    if progress is None:
        return None

    def labelled(fraction: float, message: str) -> None:
        progress(fraction, f"{label}: {message}")

    return labelled
