"""The operator's side of a slow computation run by a worker thread
(:class:`~..jobs.worker_job.WorkerJob`): what the modal operators Skin
Weights, Predict Skeleton and Auto-Rig share.

* :class:`ModalJobOperator`: a mix-in: the timer, the progress display and
  the status text begin with :meth:`~ModalJobOperator._begin_modal` and
  end, whatever happens, with :meth:`~ModalJobOperator._end_modal`.
* :func:`show_job_event`: one event of the modal run (Esc, or a timer tick
  showing the job's progress).

What each operator does with a finished job (the report, the write) stays
with it.
"""

from __future__ import annotations

from ..jobs.worker_job import WorkerJob
from ..progress import PROGRESS_STEPS, progress_step, progress_text

#: Seconds between progress refreshes of a running modal operator.
MODAL_TIMER_SECONDS = 0.1


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
