"""A slow, ``bpy``-free computation run by a worker thread while a modal
operator keeps Blender responsive (Skin Weights, Predict Skeleton, Auto-Rig).

The worker writes its progress and outcome to the :class:`WorkerJob`; the
operator (``operators.modal_job``) reads them on each timer tick and sets
``cancel`` (Esc) to stop it: the worker's next progress report then raises
:class:`Cancelled`.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import ClassVar

from ...core.errors import Cancelled
from ...core.progress import ProgressCallback


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
