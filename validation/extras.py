"""Optional parts of the install (``pip install "contactlab[fem]"``) and the check that they are there.

The core install (numpy, scipy, tqdm, meshio, tomli-w) runs BEM scenes, the command line and
writes JSON, TOML and ``.vtu`` files. The extras add:

========  ==========================  ============================================
extra     packages (import names)     needed by
========  ==========================  ============================================
fem       gmsh, scikit-fem (skfem)    a scene with ``[fem]``, the studies, the paper report
report    matplotlib, pillow (PIL)    ``contactlab report``, :mod:`validation.report`
3d        pyvista                     the reports' 3-D views, rendered off-screen
                                      (optional: matplotlib draws them without it)
dask      dask[distributed]           ``contactlab sweep --scheduler ADDRESS``
                (dask.distributed)
rough     SurfaceTopography           :mod:`bem.rough`: instrument files, self-affine surfaces,
                                      scenes with a rough gap (:mod:`validation.scene.rough`)
gpu       cupy-cuda12x (cupy),        ``device="cuda"`` of :func:`bem.solve`, :func:`bem.solve_periodic`,
                array-api-compat            :func:`bem.subsurface_stress` (:mod:`bem.backend`)
                (array_api_compat)
========  ==========================  ============================================

:func:`require` is called where a command or scene is checked, before any work: a missing
package raises :class:`MissingExtraError`, a :class:`bem.InputError` (the command line exits
with status 2) whose message says ``install contactlab[fem]``.
"""

from __future__ import annotations

import importlib
import warnings

from bem.errors import InputError

__all__ = ["EXTRAS", "MissingExtraError", "require", "missing"]

#: extra -> import names of the packages it installs
EXTRAS = {"fem": ("gmsh", "skfem"), "report": ("matplotlib", "PIL"), "3d": ("pyvista",),
          "dask": ("dask.distributed",), "rough": ("SurfaceTopography",), "gpu": ("cupy", "array_api_compat")}
_DIST = {"skfem": "scikit-fem", "PIL": "pillow", "dask.distributed": "dask[distributed]", "cupy": "cupy-cuda12x",
         "array_api_compat": "array-api-compat"}
_SYSTEM_LIBS = ("On Debian/Ubuntu: apt-get install libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1 "
                "libgomp1 (see the README's set-up).")


class MissingExtraError(InputError):
    """A scene or command needs an optional part of the install that is not there."""

    def __init__(self, message, extra, modules):
        super().__init__(message)
        self.extra = extra
        self.modules = tuple(modules)


def missing(extra):
    """Packages of ``extra`` that cannot be imported: ``[(import name, reason)]``.

    Importing is the only test that also catches a package whose shared libraries are
    missing (gmsh needs the system's libGLU and X libraries); a module already imported
    costs nothing.
    """
    out = []
    for module in EXTRAS[extra]:
        parts = module.split(".")
        chain = [".".join(parts[:i]) for i in range(1, len(parts) + 1)]  # "dask", "dask.distributed"
        try:
            with warnings.catch_warnings():  # SurfaceTopography warns that it runs without MPI, as wanted
                warnings.simplefilter("ignore", ImportWarning)
                for name in chain:  # the parents too: a cached submodule would hide a missing parent
                    importlib.import_module(name)
        except ImportError as exc:
            out.append((module, "not installed" if getattr(exc, "name", None) in chain else str(exc)))
        except OSError as exc:  # the package is there, a shared library it loads is not
            out.append((module, f"installed, but cannot load a system library ({exc})"))
    return out


def require(extra, what):
    """Raise :class:`MissingExtraError` unless every package of ``extra`` imports.

    Parameters
    ----------
    extra : str
        A key of :data:`EXTRAS`.
    what : str
        What needs it, for the message (e.g. ``"[fem] of scene 'hertz'"``).

    Raises
    ------
    MissingExtraError
        Message: ``<what> needs the optional packages ...: install contactlab[<extra>]``.
    """
    absent = missing(extra)
    if not absent:
        return
    names = ", ".join(f"{_DIST.get(m, m)} ({why})" for m, why in absent)
    hint = f' (pip install "contactlab[{extra}]")'
    if any("system library" in why for _, why in absent):
        hint += ". " + _SYSTEM_LIBS
    raise MissingExtraError(f"{what} needs the optional packages {names}: install contactlab[{extra}]{hint}.",
                            extra, [m for m, _ in absent])
