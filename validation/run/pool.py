"""Local worker processes that end with the process that started them.

:func:`worker_pool` is a :class:`concurrent.futures.ProcessPoolExecutor` whose workers

- ignore ``SIGINT`` and take the default action on ``SIGTERM`` (the parent handles Ctrl-C and
  ``SIGTERM`` and stops them; a worker never prints a traceback of its own);
- are killed by the kernel when the parent dies, even by ``SIGKILL`` (Linux: ``prctl``
  ``PR_SET_PDEATHSIG``; elsewhere only the next point applies);
- are terminated when the block using the pool ends with an exception (an interrupt
  included), instead of finishing their running jobs.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from concurrent.futures import ProcessPoolExecutor

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
        yield pool
    except BaseException:
        _terminate(pool)
        raise
    pool.shutdown(wait=True)
