"""Show a core ``ProgressCallback`` in Blender's UI.

The window manager's progress (the cursor counter / status bar) and the
workspace status text are updated; both are optional in background mode,
where there may be no window or workspace. :func:`blender_progress` shows
a job that runs on the main thread; the modal operators, whose jobs run in
a worker thread, show it with :func:`progress_step` and
:func:`progress_text` on each timer tick (:mod:`.operators.modal_job`).
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Iterator

from ..core.progress import ProgressCallback

#: Resolution of the window manager's progress counter (steps from 0 to 1).
PROGRESS_STEPS = 1000


def progress_step(fraction: float) -> int:
    """The window manager's progress value, 0 to :data:`PROGRESS_STEPS`, of a fraction in [0, 1]."""
    return int(round(fraction * PROGRESS_STEPS))


def progress_text(title: str, fraction: float, message: str) -> str:
    """Status-bar text of a running job, e.g. ``"Skin weights: Voxelizing (40%)"``."""
    return f"{title}: {message} ({100.0 * fraction:.0f}%)"


@contextmanager
def blender_progress(context, title: str, echo=None) -> Iterator[ProgressCallback]:
    """Context manager yielding a callback ``(fraction, message) -> None``.

    Parameters
    ----------
    context : bpy.types.Context or None
        Where to show progress; None (or missing window manager / workspace)
        just skips that part.
    title : str
        Prefix of the status text, e.g. "Transfer weights".
    echo : callable (fraction, message) -> None, optional
        Also called on every update (the CLI prints a text progress bar).

    The progress display and status text are always cleared on exit, even
    when the body raises (including ``core.errors.Cancelled``).
    """
    window_manager = getattr(context, "window_manager", None) if context is not None else None
    workspace = getattr(context, "workspace", None) if context is not None else None
    started = False
    if window_manager is not None:
        try:
            window_manager.progress_begin(0, PROGRESS_STEPS)
            started = True
        except (RuntimeError, AttributeError):
            started = False

    def update(fraction: float, message: str) -> None:
        if started:
            window_manager.progress_update(progress_step(fraction))
        if workspace is not None:
            workspace.status_text_set(progress_text(title, fraction, message))
        if echo is not None:
            echo(fraction, message)

    try:
        yield update
    finally:
        if started:
            window_manager.progress_end()
        if workspace is not None:
            workspace.status_text_set(None)
