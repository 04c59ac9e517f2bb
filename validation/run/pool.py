"""Local worker processes that end with the process that started them.

:func:`worker_pool` is a :class:`concurrent.futures.ProcessPoolExecutor` whose workers

- ignore ``SIGINT`` and take the default action on ``SIGTERM`` (the parent handles Ctrl-C and
  ``SIGTERM`` and stops them; a worker never prints a traceback of its own);
- are killed by the kernel when the parent dies, even by ``SIGKILL`` (Linux: ``prctl``
  ``PR_SET_PDEATHSIG``; elsewhere only the next point applies);
- are terminated when the block using the pool ends with an exception (an interrupt
  included), instead of finishing their running jobs;
- are forked (the start method ``fork``) before the block, with ``SIGINT`` and ``SIGTERM`` held back
  (:func:`validation.signals.signals_deferred`): Python ignores an exception raised in its fork handlers, so that an
  interrupt there would be lost and the sweep run on.

When the workers are terminated the pool's manager thread is waited for, so that the interpreter's exit finds it
ended (its exit hook wakes the manager threads still running, and a wakeup that raced the thread's own close of
its pipe printed an ``OSError`` traceback).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from concurrent.futures import ProcessPoolExecutor

from ..signals import signals_deferred

__all__ = ["worker_pool"]

_PR_SET_PDEATHSIG = 1  # linux/prctl.h


def _init_worker(parent):
    """Worker initializer: default signal handling, and die with ``parent`` (its pid)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        import ctypes

        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)


def _terminate(pool, timeout=5.0):
    processes = list((getattr(pool, "_processes", None) or {}).values())
    manager = getattr(pool, "_executor_manager_thread", None)  # shutdown() lets go of it
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in processes:
        with contextlib.suppress(OSError, ValueError):
            proc.terminate()
    for proc in processes:
        with contextlib.suppress(OSError, ValueError, AssertionError):
            proc.join(timeout)
            if proc.is_alive():
                proc.kill()
                proc.join(timeout)
    if manager is not None:  # it ends once its workers are gone (module docstring)
        manager.join(timeout)


@contextlib.contextmanager
def worker_pool(workers):
    """A process pool of ``workers`` processes that never outlives its parent.

    Parameters
    ----------
    workers : int
        Number of worker processes.

    Yields
    ------
    concurrent.futures.ProcessPoolExecutor
        On normal exit it is shut down after its jobs finish; on any exception
        (``KeyboardInterrupt`` included) its pending jobs are cancelled and its workers
        terminated at once.
    """
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_init_worker, initargs=(os.getpid(),))
    try:
        with signals_deferred():  # the first job starts the workers (all of them where they are forked)
            pool.submit(int)
        yield pool
    except BaseException:
        _terminate(pool)
        raise
    pool.shutdown(wait=True)
