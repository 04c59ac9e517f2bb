"""Starting gmsh without losing the process's signal handlers."""

from __future__ import annotations

import signal
import threading

__all__ = ["start_gmsh"]


def start_gmsh(gmsh):
    """``gmsh.initialize``, keeping the process's ``SIGINT`` and ``SIGTERM`` handlers.

    The gmsh library installs handlers of its own when it starts (its ``SIGTERM`` handler ends the
    process at once, with no clean-up); the Python handlers are put back, the two signals blocked
    meanwhile so that one arriving then reaches them (main thread; another cannot set handlers).
    """
    if threading.current_thread() is not threading.main_thread():
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        return
    signums = {signal.SIGINT, signal.SIGTERM}
    handlers = {signum: signal.getsignal(signum) for signum in signums}
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, signums) if hasattr(signal, "pthread_sigmask") else None
    try:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    finally:
        for signum, handler in handlers.items():
            if handler is not None:  # None: a handler not installed from Python, left as it is
                signal.signal(signum, handler)
        if blocked is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
