"""The threads of :func:`bem.fft.in_parts`: each part handed to a pool thread and collected through two locks.

A pool thread waits on one lock for its part; the caller, having run its own part, waits on the other for the
thread's end. A :class:`concurrent.futures.ThreadPoolExecutor`'s ``submit`` and ``result`` pass a queue and a
condition variable a part, which cost the caller more (``benchmarks/handover.py``; ``docs/performance.md``, "Parts on
threads through two locks"). The pool serves one caller at a time: a second caller (another thread, or a call inside
a part) runs its parts one after another in its own thread. A forked child makes its own pool; a caller interrupted
while it waits (``KeyboardInterrupt``) leaves the threads still running out of the pool.
"""

from __future__ import annotations

import os
import threading

__all__ = ["run_parts"]


class _Worker:
    """A pool thread: one part at a time, handed over by :meth:`start` and collected by :meth:`join`."""

    def __init__(self, name):
        self._go, self._done = threading.Lock(), threading.Lock()
        self._go.acquire()
        self._done.acquire()
        self._task = self._error = None
        threading.Thread(target=self._loop, name=name, daemon=True).start()

    def _loop(self):
        while True:
            self._go.acquire()
            kernel, part = self._task
            self._task = None
            try:
                kernel(part)
            except BaseException as error:  # handed to the caller by join  # noqa: BLE001
                self._error = error
            kernel = part = None  # the kernel's arrays not held past the call
            self._done.release()

    def start(self, kernel, part):
        self._task = (kernel, part)
        self._go.release()

    def join(self):
        """Wait for the part; its exception, or None."""
        self._done.acquire()
        error, self._error = self._error, None
        return error


_workers = []  # the pool, grown to the parts asked for
_busy = threading.Lock()  # held while the pool runs one caller's parts


def _after_fork():  # a forked child has none of its parent's threads
    global _workers, _busy
    _workers, _busy = [], threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork)


def run_parts(kernel, parts):
    """``kernel(part)`` for each of ``parts`` at once: the last in the calling thread, the others on the pool.

    Parameters
    ----------
    kernel : callable
        ``kernel(part)``; the calls must touch disjoint data.
    parts : list
        Two or more parts.

    Raises
    ------
    Exception
        The first part's exception (the caller's first), after every part has ended; an interruption of the wait
        (``KeyboardInterrupt``) at once, the pool's threads still running then left out of the pool.
    """
    if not _busy.acquire(blocking=False):
        for part in parts:
            kernel(part)
        return
    try:
        while len(_workers) < len(parts) - 1:
            _workers.append(_Worker(f"contactlab_{len(_workers)}"))
        started = []
        try:
            for worker, part in zip(_workers, parts[:-1]):
                worker.start(kernel, part)
                started.append(worker)
            kernel(parts[-1])
        finally:  # the other parts end before the caller goes on (or raises), as they touch its arrays
            errors = _joined(started)
        if errors:
            raise errors[0]
    finally:
        _busy.release()


def _joined(started):
    """The exceptions of the started workers' parts, after each part has ended. Where a wait is interrupted, the
    workers not yet joined leave the pool (each ends its part on its own and is never handed another) and the
    interruption is raised."""
    errors = []
    for i, worker in enumerate(started):
        try:
            error = worker.join()
        except BaseException:
            for other in started[i:]:
                _workers.remove(other)
            raise
        if error is not None:
            errors.append(error)
    return errors
