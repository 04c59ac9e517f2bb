"""The install: core dependencies and extras, a core-only run, and the stop on a missing extra.

The core-only tests run ``contactlab`` in a subprocess in which matplotlib, gmsh, scikit-fem,
vtk, pyvista, Pillow, dask, CuPy, SurfaceTopography, numba and ducc0 cannot be imported (a finder at the front of
``sys.meta_path`` raises ``ModuleNotFoundError`` for them, as if they were not installed).
"""

import ast
import json
import os
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

from validation import extras

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
PROJECT = PYPROJECT["project"]
#: what a core install lacks (import names)
NOT_CORE = ("matplotlib", "gmsh", "skfem", "vtk", "pyvista", "PIL", "dask", "distributed", "cupy",
            "SurfaceTopography", "numba", "ducc0")
#: import name -> distribution name, for the packages the code may import
DISTRIBUTIONS = {"numpy": "numpy", "scipy": "scipy", "tqdm": "tqdm", "meshio": "meshio", "tomli_w": "tomli-w",
                 "gmsh": "gmsh", "skfem": "scikit-fem", "matplotlib": "matplotlib", "PIL": "pillow",
                 "dask": "dask", "distributed": "dask", "cupy": "cupy-cuda12x", "pytest": "pytest",
                 "html5lib": "html5lib", "yaml": "pyyaml", "SurfaceTopography": "surfacetopography",
                 "pyvista": "pyvista", "array_api_compat": "array-api-compat",
                 "array_api_strict": "array-api-strict", "sphinx": "sphinx", "numba": "numba", "ducc0": "ducc0"}
OWN = ("bem", "fem_reference", "validation", "tests")


def _name(requirement):
    """Distribution name of a requirement string (``"dask[distributed]>=2024.1"`` -> ``dask``)."""
    for stop in "[<>=!~; ":
        requirement = requirement.split(stop)[0]
    return requirement.strip().lower()


def _extra(name):
    """Distributions an extra installs, self-references (``contactlab[fem,report]``) expanded."""
    out = set()
    for req in PROJECT["optional-dependencies"][name]:
        if _name(req) == "contactlab":
            for sub in req.split("[", 1)[1].split("]")[0].split(","):
                out |= _extra(sub.strip())
        else:
            out.add(_name(req))
    return out


def _imports(directory):
    """Top-level third-party module names imported anywhere under ``directory`` (a folder or a file)."""
    found = set()
    for path in [directory] if directory.is_file() else directory.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                found |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                found.add(node.module.split(".")[0])
    return {m for m in found if m not in sys.stdlib_module_names and m not in OWN}


def test_core_dependencies_are_the_bem_ones():
    assert {_name(r) for r in PROJECT["dependencies"]} == {"numpy", "scipy", "tqdm", "meshio", "tomli-w"}


def test_extras_layout():
    assert _extra("fem") == {"gmsh", "scikit-fem"}
    assert _extra("report") == {"matplotlib", "pillow"}
    assert _extra("dask") == {"dask"}
    assert _extra("gpu") == {"cupy-cuda12x", "array-api-compat"}
    assert _extra("3d") == {"pyvista"}
    assert _extra("rough") == {"surfacetopography"}
    assert _extra("docs") == {"sphinx", "numpydoc", "myst-parser"}
    assert _extra("peers") == {"aspher", "tamaas", "contactmechanics"}
    assert _extra("fast") == {"numba", "ducc0"}
    assert _extra("all") == _extra("fem") | _extra("report") | _extra("dask") | _extra("rough") | _extra("fast")
    assert _extra("test") == _extra("all") | _extra("3d") | _extra("docs") | {
        "pytest", "pytest-xdist", "html5lib", "pyyaml", "array-api-strict", "array-api-compat"}


def test_every_import_is_declared():
    """Each third-party import of the packages is core or an extra; each of the tests is in [test]."""
    declared = {_name(r) for r in PROJECT["dependencies"]}
    extra = {d for e in PROJECT["optional-dependencies"] for d in _extra(e)}
    for package in ("bem", "fem_reference", "validation"):
        for module in _imports(ROOT / package):
            assert module in DISTRIBUTIONS, f"{package} imports {module!r}: declare it in pyproject.toml"
            assert DISTRIBUTIONS[module] in declared | extra, f"{package} imports undeclared {module!r}"
    test_needs = declared | _extra("test")
    for module in _imports(ROOT / "tests") | _imports(ROOT / "docs"):
        assert DISTRIBUTIONS.get(module) in test_needs, f"tests or docs import {module!r}, not in [test]"


def test_extras_module_matches_pyproject():
    for extra, modules in extras.EXTRAS.items():
        dists = {DISTRIBUTIONS[m.split(".")[0]] for m in modules}
        assert dists == _extra(extra), extra


def test_every_extra_has_code_behind_it():
    """Each package an extra installs is imported by the product's code (gpu: bem.backend's CuPy)."""
    imported = set().union(*(_imports(ROOT / package) for package in ("bem", "fem_reference", "validation")))
    for extra, modules in extras.EXTRAS.items():
        assert {m.split(".")[0] for m in modules} <= imported, extra


BLOCKER = textwrap.dedent("""
    import sys

    BLOCKED = {blocked!r}

    class NotInstalled:
        @staticmethod
        def find_spec(name, path=None, target=None):
            if name.split(".")[0] in BLOCKED:
                raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
            return None

    sys.meta_path.insert(0, NotInstalled)
    from validation.cli import main
    code = main(["--no-progress", *sys.argv[1:]])
    loaded = sorted(m for m in BLOCKED if m in sys.modules)
    print("LOADED", loaded, file=sys.stderr)
    sys.exit(code)
""")


def _core_only(tmp_path, *argv):
    """Run ``contactlab argv`` with the non-core packages unimportable; (code, stdout, stderr)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, "-c", BLOCKER.format(blocked=NOT_CORE), *map(str, argv)],
                          capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
    assert "LOADED []" in proc.stderr, proc.stderr
    return proc.returncode, proc.stdout, proc.stderr


def test_core_install_runs_a_bem_scene_and_writes_its_files(tmp_path):
    code, out, err = _core_only(tmp_path, "run", "elliptic", "--out", "res", "--set", "bem.nodes_across=16")
    assert code == 0, err
    res = tmp_path / "res"
    assert sorted(p.name for p in res.iterdir()) == [".contactlab", "bem_field.vtu", "result.json", "scene.toml"]
    result = json.loads((res / "result.json").read_text())
    assert result["converged"] and result["analytic"]["kind"] == "hertz_elliptic"
    assert set(result["provenance"]["packages"]) == {"numpy", "scipy", "meshio"}
    assert (res / "bem_field.vtu").read_bytes().startswith(b"<?xml")
    assert "p_max" in out


@pytest.mark.parametrize("argv, extra", [
    (["run", "hertz", "--out", "res"], "fem"),
    (["check", "hertz"], "fem"),
    (["sweep", "paper_root", "--out", "res"], "fem"),
    (["report", "hertz", "--out", "res"], "report"),
    (["study", "stability", "--quick", "--out", "res"], "fem"),
    (["layer-law", "--synthetic", "hurst=0.8,size=1e-4,grid=16,rms_height=1e-6", "--E-star", "1e11", "--out", "res"],
     "rough"),
    (["run", "rough_flat", "--out", "res"], "rough"),
    (["sweep", "rough_flat", "--param", "load.mean_pressure", "--values", "1e8,2e8", "--out", "res"], "rough"),
])
def test_missing_extra_stops_before_any_work(tmp_path, argv, extra):
    code, out, err = _core_only(tmp_path, *argv)
    assert code == 2, err
    assert f"install contactlab[{extra}]" in err
    assert "Traceback" not in err
    assert list(tmp_path.iterdir()) == []  # nothing written, nothing run


def test_extra_with_a_missing_system_library_names_the_packages(monkeypatch):
    real = extras.importlib.import_module

    def broken(name):
        if name == "gmsh":
            raise OSError("libGLU.so.1: cannot open shared object file: No such file or directory")
        return real(name)

    monkeypatch.setattr(extras.importlib, "import_module", broken)
    with pytest.raises(extras.MissingExtraError, match=r"install contactlab\[fem\]") as info:
        extras.require("fem", "[fem] of scene 'x'")
    message = str(info.value)
    assert "libGLU.so.1" in message and "apt-get install libglu1-mesa" in message
    assert info.value.extra == "fem" and info.value.modules == ("gmsh",)
    assert isinstance(info.value, extras.InputError)


def test_present_extras_pass():
    for extra in ("fem", "report", "dask"):
        extras.require(extra, "this test")  # [test] installs them all


def test_ci_runs_the_readme_commands():
    ci = (ROOT / ".ci" / "run").read_text()
    readme = (ROOT / "README.md").read_text()
    install = 'python -m pip install -e ".[test]"'
    assert install in ci and install in readme
    assert "python -m pytest -q -n auto" in ci and "python -m pytest -n auto" in readme
    packages = "libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1 libgomp1"
    assert packages in ci and packages in readme
    assert ci.index("apt-get install") < ci.index(install) < ci.index("python -m pytest")
