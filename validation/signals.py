"""Ctrl-C (``SIGINT``) and ``SIGTERM`` held back while a block that must not be cut runs.

:func:`signals_deferred` is used where an interrupt would leave something broken or be lost: the swap of an output
folder into place (:mod:`validation.io`), and the fork of a sweep's workers (:mod:`validation.run.pool`), where
Python runs the parent's fork handlers (logging's release of its lock among them) and ignores an exception raised
in them, so that a ``KeyboardInterrupt`` there would be printed and lost.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading

__all__ = ["signals_deferred"]


@contextlib.contextmanager
def signals_deferred():
    """Hold ``SIGINT`` and ``SIGTERM`` back while the block runs (main thread); handle them after it.

    A signal received meanwhile goes, when the block ends, to the handler that was in place before it (a callable:
    called, ``KeyboardInterrupt`` for Ctrl-C by default; the default action: the signal sent again); off the main
    thread, where no handler can be set, the block runs as it is.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received = []
    saved = {signum: signal.signal(signum, lambda n, frame: received.append((n, frame)))
             for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for signum, handler in saved.items():
            signal.signal(signum, handler)
        for signum, frame in received:
            handler = saved[signum]
            if callable(handler):
                handler(signum, frame)
            elif handler == signal.SIG_DFL:
                os.kill(os.getpid(), signum)
