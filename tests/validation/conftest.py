"""Shared helpers of the validation-harness tests: small settings and one CLI run per built-in scene."""

import contextlib
import io
import math

import pytest

from validation.cli import main
from validation.run.record import RunResult

#: --set overrides that keep every built-in scene fast (BEM < 0.2 s, FEM < 1 s here).
SMALL = {
    "hertz": ["bem.nodes_across=24", "fem.n_contact_elements=8"],
    "paper_smooth": ["bem.nodes_across=24", "fem.n_contact_elements=8"],
    "paper_linear": ["bem.nodes_across=24", "fem.n_contact_elements=8"],
    "paper_elastic_rigid": ["bem.nodes_across=24", "fem.n_contact_elements=8"],
    "paper_bilinear": ["bem.nodes_across=24", "fem.n_contact_elements=8"],
    "paper_root": ["bem.nodes_across=24", "fem.n_contact_elements=8"],
    "rough_sphere": ["bem.nodes_across=24", "fem.n_contact_elements=8"],
    "punch": ["bem.nodes_across=48", "fem.n_contact_elements=16"],  # the edge peak needs a finer FEM mesh
    "roller": ["bem.nodes_across=16"],
    "elliptic": ["bem.nodes_across=24"],
}

STEEL_E, STEEL_NU = 210e9, 0.3


def e_star(E1, nu1, E2, nu2):
    """Johnson's effective modulus, written out independently of the code under test."""
    return 1.0 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)


def hertz(force, R, Es):
    """Hertz sphere: contact radius, peak pressure, approach (Johnson 1985, sec. 4.2)."""
    a = (3.0 * force * R / (4.0 * Es)) ** (1.0 / 3.0)
    return a, 3.0 * force / (2.0 * math.pi * a * a), a * a / R


def cli(*argv):
    """Run ``contactlab argv`` in this process: ``(exit code, stdout, stderr)``."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["--no-progress", *map(str, argv)])
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="session")
def builtin_runs(tmp_path_factory):
    """Every built-in scene run once from the CLI with SMALL settings: name -> dict."""
    root = tmp_path_factory.mktemp("builtin")
    runs = {}
    for name, small in SMALL.items():
        out = root / name
        args = ["run", name, "--out", out]
        for s in small:
            args += ["--set", s]
        code, stdout, stderr = cli(*args)
        result = RunResult.read(out / "result.json") if (out / "result.json").exists() else None
        runs[name] = {"code": code, "stdout": stdout, "stderr": stderr, "result": result, "dir": out}
    return runs
