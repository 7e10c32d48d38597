"""A slow, ``bpy``-free computation run by a worker thread while a modal
operator keeps Blender responsive: what Skin Weights, Predict Skeleton and
Auto-Rig share.

* :class:`WorkerJob`: the worker writes its progress and outcome there; the
  operator reads them on each timer tick and sets ``cancel`` (Esc) to stop
  it: the worker's next progress report then raises :class:`Cancelled`.
* :class:`ModalJobOperator`: the operator's side, a mix-in: the timer, the
  progress display and the status text begin with :meth:`~ModalJobOperator._begin_modal`
  and end, whatever happens, with :meth:`~ModalJobOperator._end_modal`.
* :func:`show_job_event`: one event of the modal run (Esc, or a timer tick
  showing the job's progress).

What each operator does with a finished job (the report, the write) stays
with it.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import ClassVar

from ...core.errors import Cancelled
from ...core.progress import ProgressCallback
from ..progress import PROGRESS_STEPS, progress_step, progress_text

#: Seconds between progress refreshes of a running modal operator.
MODAL_TIMER_SECONDS = 0.1


@dataclass(kw_only=True)
class WorkerJob:
    """A computation run by a worker thread for a modal operator.

    A subclass gives :meth:`compute` and :attr:`cancelled_message`. The job
    never touches the operator or ``bpy``, so Blender may free the operator
    (its ``cancel``) while the worker runs.

    Attributes
    ----------
    fraction : float in [0, 1], the last progress reported
    message : str, what the worker is doing
    result : what :meth:`compute` returned (None until it finishes)
    error : BaseException or None, what it raised instead
    cancel : bool, set by the operator to stop the worker
    thread : threading.Thread or None, the worker (:meth:`start`)
    """

    fraction: float = 0.0
    message: str = "Starting"
    result: object = None
    error: BaseException | None = None
    cancel: bool = False
    thread: threading.Thread | None = field(default=None, repr=False)

    #: Message of the :class:`Cancelled` the worker raises once ``cancel`` is set.
    cancelled_message: ClassVar[str] = "Cancelled."

    def compute(self, progress: ProgressCallback):
        """The work, reporting through ``progress``; runs in the worker thread."""
        raise NotImplementedError

    def progress(self, fraction: float, message: str) -> None:
        """The worker's progress callback: records the progress, or raises
        :class:`Cancelled` once ``cancel`` is set."""
        if self.cancel:
            raise Cancelled(self.cancelled_message)
        self.fraction, self.message = fraction, message

    def run(self) -> None:
        """Compute into ``result``, or the exception into ``error`` (the main
        thread reports it or hands it on)."""
        try:
            self.result = self.compute(self.progress)
        except BaseException as error:  # reported from the main thread
            self.error = error

    def start(self):
        """Run the job in a new daemon thread (``thread``); returns the job."""
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()
        return self


def show_job_event(context, event, job: WorkerJob, title: str) -> bool:
    """Handle one event of a modal run: Esc asks ``job`` to stop; a timer
    tick shows its progress (the window manager's counter and the status
    text ``"<title>: <message> (<percent>%), Esc to cancel"``).

    Returns
    -------
    bool, whether the event was a timer tick (the operator then looks
    whether the worker has finished).
    """
    if event.type == "ESC":
        job.cancel = True
    if event.type != "TIMER":
        return False
    context.window_manager.progress_update(progress_step(job.fraction))
    if context.workspace is not None:
        text = progress_text(title, job.fraction, job.message)
        context.workspace.status_text_set(f"{text}, Esc to cancel")
    return True


class ModalJobOperator:
    """Mix-in of an operator running :class:`WorkerJob` s modally: the
    timer that drives its ``modal``, the progress display and the status
    text."""

    _job = None
    _timer = None

    def _begin_modal(self, context) -> None:
        """Add the timer, begin the progress display and hand Blender the
        operator's modal handler (``invoke`` then returns ``RUNNING_MODAL``)."""
        window_manager = context.window_manager
        self._timer = window_manager.event_timer_add(MODAL_TIMER_SECONDS, window=context.window)
        window_manager.progress_begin(0, PROGRESS_STEPS)
        window_manager.modal_handler_add(self)

    def _end_modal(self, context) -> None:
        """Remove the timer, end the progress display and clear the status
        text; the finished run and the operator's ``cancel`` both end here,
        and a second call does nothing."""
        if self._timer is None:
            return
        context.window_manager.event_timer_remove(self._timer)
        self._timer = None
        context.window_manager.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
