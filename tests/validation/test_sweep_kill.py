"""A sweep killed (SIGKILL) while it writes a point: the next sweep into the folder removes the
unfinished point file and computes that point again.

The sweep runs as ``python -m validation.cli`` in a subprocess; a ``sitecustomize`` module on its
``PYTHONPATH`` kills it inside ``os.fsync`` of the first point file it writes, so the kill falls
between the point's temporary file being written and its rename, every time.
"""

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ("sweep", "elliptic", "--param", "load.force", "--values", "50,100", "--workers", "1",
         "--set", "bem.nodes_across=16")

KILL_IN_POINT_WRITE = textwrap.dedent("""
    import os
    _real = os.fsync

    def _fsync(fd):
        if "/points/.point-" in os.readlink(f"/proc/self/fd/{fd}"):
            os.kill(os.getpid(), 9)
        return _real(fd)

    os.fsync = _fsync
""")


def _sweep(tmp_path, out, hook=None):
    path = [str(ROOT)] if hook is None else [str(hook), str(ROOT)]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(path))
    return subprocess.run([sys.executable, "-m", "validation.cli", "--no-progress", *SWEEP, "--out", str(out)],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)


def _hidden(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs Linux /proc")
def test_a_point_whose_write_was_killed_is_removed_and_computed_again(tmp_path):
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(KILL_IN_POINT_WRITE)
    out = tmp_path / "s"
    killed = _sweep(tmp_path, out, hook)
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    assert len(_hidden(out / "points")) == 1 and not list((out / "points").glob("point-*.json"))
    rerun = _sweep(tmp_path, out)
    assert rerun.returncode == 0, rerun.stderr
    assert "computed 2, reused 0" in rerun.stdout
    assert _hidden(out / "points") == [] and _hidden(out) == [".contactlab"]
    points = sorted(json.loads(p.read_text())["value"] for p in (out / "points").glob("point-*.json"))
    assert points == [50.0, 100.0]
