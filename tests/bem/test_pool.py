"""The pool of :func:`bem.fft.in_parts` (:mod:`bem.pool`): parts handed over through locks, one caller at a time, errors,
interruptions and forks."""

import os
import signal
import threading
import time
import warnings

import numpy as np
import pytest

from bem import fft


def _covered(n, parts):
    hits = np.zeros(n, dtype=int)
    for part in parts:
        hits[part] += 1
    return bool(np.all(hits == 1))


def test_a_second_caller_runs_its_parts_in_its_own_thread_while_the_pool_is_held(monkeypatch):
    monkeypatch.setattr(fft, "_override", 2)
    first, second, inside = {}, {}, threading.Event()

    def slow(part):  # the first caller's parts, on the pool and in its thread
        inside.set()
        time.sleep(0.2)
        first[part.start] = (part, threading.get_ident())

    def quick(part):
        second[part.start] = (part, threading.get_ident())

    holder = threading.Thread(target=fft.in_parts, args=(slow, 400, 1 << 20))
    holder.start()
    assert inside.wait(5)
    fft.in_parts(quick, 400, 1 << 20)  # while the holder's parts run
    holder.join(5)
    assert not holder.is_alive()
    me = threading.get_ident()
    assert sorted(second) == [0, 200] and all(ident == me for _, ident in second.values())
    assert _covered(400, [part for part, _ in second.values()])
    assert sorted(first) == [0, 200] and first[0][1] != first[200][1]  # the holder's parts on two threads
    assert _covered(400, [part for part, _ in first.values()])


def test_a_call_inside_a_part_runs_in_that_part_s_thread(monkeypatch):
    monkeypatch.setattr(fft, "_override", 2)
    inner, lock = [], threading.Lock()

    def outer(part):
        def kernel(sub):
            with lock:
                inner.append((part.start, sub, threading.get_ident()))

        fft.in_parts(kernel, 100, 1 << 20)
        with lock:
            inner.append((part.start, None, threading.get_ident()))

    fft.in_parts(outer, 300, 1 << 20)
    for start in (0, 150):
        rows = [(sub, ident) for s, sub, ident in inner if s == start]
        idents = {ident for _, ident in rows}
        assert len(idents) == 1  # every inner part in the thread of the outer part
        assert _covered(100, [sub for sub, _ in rows if sub is not None])


def test_a_part_s_error_reaches_the_caller_after_every_part_and_the_pool_goes_on(monkeypatch):
    monkeypatch.setattr(fft, "_override", 3)
    ended = {}

    def failing(part):
        if part.start == 0:
            raise ValueError("a pool part failed")
        time.sleep(0.05)
        ended[part.start] = True

    with pytest.raises(ValueError, match="a pool part failed"):
        fft.in_parts(failing, 300, 1 << 20)
    assert ended == {100: True, 200: True}
    seen = []
    fft.in_parts(lambda part: seen.append(part), 300, 1 << 20)  # the pool serves the next call
    assert _covered(300, seen) and len(seen) == 3


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork on this platform")
def test_a_forked_child_makes_its_own_pool(monkeypatch):
    monkeypatch.setattr(fft, "_override", 2)
    fft.in_parts(lambda part: None, 300, 1 << 20)  # the parent's pool exists
    read, write = os.pipe()
    with warnings.catch_warnings():  # Python 3.12+ warns that a threaded process forks: the point of this test
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid == 0:  # the child: its parent's workers are gone
        try:
            seen = []
            fft.in_parts(lambda part: seen.append(threading.get_ident()), 300, 1 << 20)
            os.write(write, b"ok" if len(set(seen)) == 2 else b"no")
        finally:
            os._exit(0)
    os.close(write)
    deadline = time.monotonic() + 20
    while os.waitpid(pid, os.WNOHANG) == (0, 0):  # a child that hangs is killed
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            break
        time.sleep(0.01)
    answer = os.read(read, 2)
    os.close(read)
    assert answer == b"ok"


def test_the_pool_holds_no_kernel_after_the_call(monkeypatch):
    """A kernel's arrays are freed when the caller lets them go (a closure held by a pool thread would keep them)."""
    import weakref

    monkeypatch.setattr(fft, "_override", 3)

    class Kernel:
        def __call__(self, part):
            pass

    kernel = Kernel()
    gone = weakref.ref(kernel)
    fft.in_parts(kernel, 300, 1 << 20)
    del kernel
    assert gone() is None


class _Interrupted(Exception):
    pass


def test_a_wait_interrupted_leaves_no_busy_worker_in_the_pool(monkeypatch):
    """A caller interrupted while its pool part runs (Ctrl-C): the next call's parts all end before it returns."""
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signal handlers are set in the main thread only")
    monkeypatch.setattr(fft, "_override", 2)

    def interrupt(signum, frame):
        raise _Interrupted

    previous = signal.signal(signal.SIGINT, interrupt)
    began, ended = threading.Event(), threading.Event()
    try:
        def slow(part):
            if part.start == 0:  # the pool's part
                began.set()
                time.sleep(0.5)
                ended.set()

        threading.Timer(0.1, os.kill, (os.getpid(), signal.SIGINT)).start()
        with pytest.raises(_Interrupted):
            fft.in_parts(slow, 300, 1 << 20)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert began.is_set() and not ended.is_set()  # interrupted while the pool's part ran
    hits = np.zeros(300, dtype=int)

    def quick(part):
        if part.start == 0:
            time.sleep(0.05)
        hits[part] += 1

    fft.in_parts(quick, 300, 1 << 20)  # while the interrupted part may still run
    assert np.all(hits == 1)  # every part ended before the call returned
    time.sleep(0.6)  # the interrupted part ends meanwhile: nothing more is written
    assert np.all(hits == 1)
