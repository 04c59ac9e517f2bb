"""Killed and terminated commands: no leftovers, the previous result kept or restored, no orphan workers.

Each command runs as ``python -m validation.cli`` in a subprocess. A ``sitecustomize`` module on
its ``PYTHONPATH`` sends the signal at a chosen point of the write (through ``os.fsync``,
``os.replace`` or ``shutil.rmtree``), so the signal arrives there every time.
"""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from validation.io import MARKER, recover_output_dir

from .conftest import cli

ROOT = Path(__file__).resolve().parents[2]
RUN = ("run", "elliptic", "--set", "bem.nodes_across=16")

#: when to send the signal: (function patched, condition on its arguments, before or after the real call)
POINTS = {
    # assembling the new folder (scene.toml is written with fsync), the previous one untouched
    "assembling": ("os", "fsync", "True", "before"),
    # the previous folder moved aside, the new one not yet in place
    "between renames": ("os", "replace", "str(args[1]).endswith('previous')", "after"),
    # the new folder in place, the previous one half deleted
    "deleting the previous": ("shutil", "rmtree", "'.contactlab-old-' in str(args[0])", "half"),
}


#: the FEM stage, once gmsh has meshed: its library installs signal handlers of its own when it starts
MESHED = ("gmsh", "model.mesh.generate", "True", "after")
#: a run with the FEM reference (gmsh), small
RUN_FEM = ("run", "hertz", "--set", "bem.nodes_across=16", "--set", "fem.n_contact_elements=8")
TERMINATED = ["contactlab: terminated (no partial output was left)"]
INTERRUPTED = ["contactlab: interrupted (no partial output was left)"]


@pytest.fixture(autouse=True)
def _sigint_as_from_a_terminal():
    """The commands start with Ctrl-C's default action, as from a terminal, also where this test process was
    started with ``SIGINT`` ignored (a background job of a non-interactive shell), which a child inherits."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def _hook(tmp_path, point, signum):
    """A sitecustomize folder sending ``signum`` at ``point``: a key of :data:`POINTS` or such a tuple."""
    module, name, condition, when = POINTS.get(point, point)
    hook = tmp_path / "hook"
    hook.mkdir(exist_ok=True)
    (hook / "sitecustomize.py").write_text(textwrap.dedent(f"""
        import os, pathlib, shutil
        import {module}
        _real = {module}.{name}

        def _patched(*args, **kwargs):
            if not ({condition}):
                return _real(*args, **kwargs)
            if {when!r} == "after":
                done = _real(*args, **kwargs)
                os.kill(os.getpid(), {int(signum)})
                return done
            if {when!r} == "half":
                for path in sorted(p for p in pathlib.Path(args[0]).rglob("*") if p.is_file())[:2]:
                    path.unlink()
            os.kill(os.getpid(), {int(signum)})
            return _real(*args, **kwargs)

        {module}.{name} = _patched
    """))
    return hook


#: a sitecustomize that makes every sweep point take a minute (the workers are busy when the sweep ends)
SLOW_POINTS = textwrap.dedent("""
    import time
    import validation.run.sweep as sweep

    def _solve_point(*args):
        time.sleep(60)

    _solve_point.__module__, _solve_point.__qualname__ = sweep.__name__, "_solve_point"
    sweep._solve_point = _solve_point
""")


def _contactlab(tmp_path, *argv, hook=None, popen=False):
    path = [str(ROOT)] if hook is None else [str(hook), str(ROOT)]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(path))
    cmd = [sys.executable, "-m", "validation.cli", "--no-progress", *map(str, argv)]
    if popen:
        return subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
    return subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)


def _hidden(parent):
    return sorted(p.name for p in parent.iterdir() if p.name.startswith("."))


def _tree(folder):
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _complete(folder):
    result = json.loads((folder / "result.json").read_text())
    names = {p.name for p in folder.iterdir()}
    return names == {MARKER, *result["files"].values()} and result["converged"]


@pytest.mark.parametrize("point", list(POINTS))
def test_a_run_killed_while_writing_is_recovered_by_the_next_run(tmp_path, point):
    out = tmp_path / "runs" / "r"
    assert _contactlab(tmp_path, *RUN, "--out", out).returncode == 0
    previous = _tree(out)
    killed = _contactlab(tmp_path, *RUN, "--set", "load.force=50.0", "--out", out,
                         hook=_hook(tmp_path, point, signal.SIGKILL))
    assert killed.returncode == -signal.SIGKILL
    assert _hidden(out.parent)  # the kill left hidden folders behind
    restored = recover_output_dir(out)
    assert _hidden(out.parent) == []
    assert restored == (point == "between renames")
    if point == "deleting the previous":  # the new folder was complete and in place
        assert json.loads((out / "result.json").read_text())["force"] == pytest.approx(50.0)
    else:  # the previous result, whole
        assert _tree(out) == previous
    rerun = _contactlab(tmp_path, *RUN, "--set", "load.force=50.0", "--out", out)
    assert rerun.returncode == 0, rerun.stderr
    assert _hidden(out.parent) == [] and _complete(out)


def test_the_next_run_cleans_up_after_a_kill_by_itself(tmp_path):
    out = tmp_path / "r"
    assert _contactlab(tmp_path, *RUN, "--out", out).returncode == 0
    hook = _hook(tmp_path, "between renames", signal.SIGKILL)
    assert _contactlab(tmp_path, *RUN, "--out", out, hook=hook).returncode == -signal.SIGKILL
    assert not out.exists()  # moved aside when the process died
    rerun = _contactlab(tmp_path, *RUN, "--set", "load.force=50.0", "--out", out)
    assert rerun.returncode == 0, rerun.stderr
    assert _hidden(tmp_path) == []
    assert _complete(out) and json.loads((out / "result.json").read_text())["force"] == pytest.approx(50.0)


@pytest.mark.parametrize("point", list(POINTS))
def test_sigterm_while_writing_exits_cleanly(tmp_path, point):
    out = tmp_path / "r"
    assert _contactlab(tmp_path, *RUN, "--out", out).returncode == 0
    previous = _tree(out)
    proc = _contactlab(tmp_path, *RUN, "--set", "load.force=50.0", "--out", out,
                       hook=_hook(tmp_path, point, signal.SIGTERM))
    assert proc.returncode == 128 + signal.SIGTERM
    assert "Traceback" not in proc.stderr and proc.stderr.strip().splitlines() == [
        "contactlab: terminated (no partial output was left)"]
    assert _hidden(tmp_path) == []
    assert _complete(out)
    if point == "assembling":
        assert _tree(out) == previous
    else:  # SIGTERM is held back until the replacement is over
        assert json.loads((out / "result.json").read_text())["force"] == pytest.approx(50.0)


def _children(pid):
    """The pids of the child processes of ``pid`` (Linux /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def _running(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _busy_sweep(tmp_path):
    """A sweep with 2 busy workers: ``(process, worker pids)``."""
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(SLOW_POINTS)
    proc = _contactlab(tmp_path, "sweep", "elliptic", "--param", "load.force", "--values", "50,100,150,200",
                       "--workers", "2", "--out", tmp_path / "s", hook=hook, popen=True)
    deadline = time.monotonic() + 60
    while len(workers := _children(proc.pid)) < 2 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    return proc, workers


def _gone_within(pids, seconds):
    deadline = time.monotonic() + seconds
    while any(_running(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    return not [pid for pid in pids if _running(pid)]


@pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="needs Linux /proc")
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT, signal.SIGKILL])
def test_stopping_a_sweep_stops_its_workers(tmp_path, signum):
    proc, workers = _busy_sweep(tmp_path)
    try:
        assert len(workers) == 2, proc.communicate()[1] if proc.poll() is not None else "no workers started"
        proc.send_signal(signum)
        _out, err = proc.communicate(timeout=20)
        assert proc.returncode == (-signum if signum == signal.SIGKILL else 128 + signum), err
        assert "Traceback" not in err
        assert _gone_within(workers, 5)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


@pytest.mark.parametrize("point", ["meshed", "assembling"])
def test_sigterm_after_gmsh_started_exits_cleanly(tmp_path, point):
    """gmsh's library replaces the process's SIGTERM handler when it starts: the FEM stage puts it
    back, so a SIGTERM in that stage, or while the result is assembled after it, still ends the run
    with exit code 143, one line, and no temporary folder left."""
    out = tmp_path / "r"
    proc = _contactlab(tmp_path, *RUN_FEM, "--out", out,
                       hook=_hook(tmp_path, MESHED if point == "meshed" else point, signal.SIGTERM))
    assert proc.returncode == 128 + signal.SIGTERM, proc.stderr
    assert proc.stderr.strip().splitlines() == TERMINATED
    assert not out.exists() and _hidden(tmp_path) == []


#: a sitecustomize that sends a signal while the command starts: when it first imports ``bem`` (the
#: packages take seconds to import), or when argparse parses the command line
STARTUP = textwrap.dedent("""
    import argparse, os, sys
    SIGNUM, WHEN = int(os.environ["SIGNUM"]), os.environ["WHEN"]
    _parse = argparse.ArgumentParser.parse_args

    def _parse_args(*args, **kwargs):
        if WHEN == "parsing":
            os.kill(os.getpid(), SIGNUM)
        return _parse(*args, **kwargs)

    class _OnImport:
        def find_spec(self, name, path=None, target=None):
            if WHEN == "importing" and name == "bem":
                sys.meta_path.remove(self)
                os.kill(os.getpid(), SIGNUM)

    argparse.ArgumentParser.parse_args = _parse_args
    sys.meta_path.insert(0, _OnImport())
""")


@pytest.mark.parametrize("when", ["importing", "parsing"])
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_command_starts_exits_with_one_line(tmp_path, monkeypatch, when, signum):
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(STARTUP)
    monkeypatch.setenv("SIGNUM", str(int(signum)))
    monkeypatch.setenv("WHEN", when)
    proc = _contactlab(tmp_path, *RUN, "--out", tmp_path / "r", hook=hook)
    assert proc.returncode == 128 + signum, proc.stderr
    assert proc.stderr.strip().splitlines() == (TERMINATED if signum == signal.SIGTERM else INTERRUPTED)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hook"]


@pytest.mark.parametrize("argv", [("scenes",), (*RUN, "--no-fem", "--out", "r")])
def test_a_closed_output_pipe_stops_the_command_quietly(tmp_path, argv):
    """``contactlab ... | head``: the reader of stdout is gone before the command prints. It stops as a
    process stopped by SIGPIPE (exit code 141), with nothing on stderr; what it wrote is whole."""
    read, write = os.pipe()
    os.close(read)  # the reader is gone: every write to the pipe fails
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    try:
        proc = subprocess.run([sys.executable, "-m", "validation.cli", "--no-progress", *argv], cwd=tmp_path,
                              env=env, stdout=write, stderr=subprocess.PIPE, text=True, timeout=300)
    finally:
        os.close(write)
    assert proc.returncode == 128 + signal.SIGPIPE, proc.stderr
    assert proc.stderr == ""
    if argv[0] == "run":
        assert _complete(tmp_path / "r") and _hidden(tmp_path) == []


def test_a_broken_pipe_that_is_not_the_output_is_not_hidden(monkeypatch):
    """Only a closed standard output stops quietly: a broken pipe to a worker is an error that shows."""
    from validation.cli import scenes

    def _lost_worker(args):
        raise BrokenPipeError("a worker's pipe")

    monkeypatch.setattr(scenes, "run", _lost_worker)
    with pytest.raises(BrokenPipeError, match="a worker's pipe"):
        cli("scenes")


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_process_forked_while_sigterm_is_handled_ends_by_sigterm_without_a_traceback():
    """A sweep's worker is forked with the command's SIGTERM handler and sets the default action in its
    initializer; a SIGTERM before that (the sweep stopped as it starts) ends it by the default action, not by an
    exception raised in it (its traceback on stderr)."""
    import warnings

    from validation.cli import _terminate_as_interrupt

    with _terminate_as_interrupt():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # fork with threads (Python >= 3.12)
            pid = os.fork()
        if pid == 0:  # the child: reaches os._exit only where the handler raised
            try:
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(10)
            finally:
                os._exit(3)
        _, status = os.waitpid(pid, 0)
    assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGTERM, status


INTERRUPT_AT_FORK = SLOW_POINTS + textwrap.dedent("""
    import os
    import signal

    _armed = [True]

    def _interrupt():  # Ctrl-C in the parent's fork handlers, once (the first fork: the sweep's workers)
        if _armed[0]:
            _armed[0] = False
            os.kill(os.getpid(), signal.SIGINT)

    os.register_at_fork(after_in_parent=_interrupt)
""")


@pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="needs Linux /proc")
def test_an_interrupt_while_the_workers_are_forked_stops_the_sweep(tmp_path):
    """Python ignores an exception raised in a fork handler: Ctrl-C there (logging's handler, say) was printed as
    ignored and lost, and the sweep ran on. The workers are forked with the signals held back, so it stops."""
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(INTERRUPT_AT_FORK)
    proc = _contactlab(tmp_path, "sweep", "elliptic", "--param", "load.force", "--values", "50,100,150,200",
                       "--workers", "2", "--out", tmp_path / "s", hook=hook, popen=True)
    try:
        _out, err = proc.communicate(timeout=30)
        assert proc.returncode == 128 + signal.SIGINT, err
        assert "Traceback" not in err and "Exception ignored" not in err, err
        assert "interrupted" in err
    finally:
        if proc.poll() is None:
            workers = _children(proc.pid)
            proc.kill()
            proc.wait()
            _gone_within(workers, 5)
