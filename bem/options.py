"""The solver contract: the methods, the options each solver takes, and their check.

:func:`bem.solve` takes the options common to every method (``rtol``, ``maxiter``, ``x0``,
``nested``, ``precondition``, ``callback``) and, as keyword arguments, the options of one solver
(:data:`OPTIONS`); :func:`check_options` refuses an unknown option or one the solver that runs
does not take. Scenes check their ``[bem]`` options with the same function.
"""

from __future__ import annotations

from .checks import check_bool, check_int, check_positive, check_range
from .errors import InputError

__all__ = ["METHODS", "OPTIONS", "solver_for", "check_options"]

#: The methods of :func:`bem.solve`.
METHODS = ("newton", "augmented_gap", "variable_compliance", "kalker")

#: Options each solver takes besides the common ones (``rtol``, ``maxiter``, ``x0``,
#: ``nested``, ``precondition``, ``callback``). "kalker" is the QP, which also solves
#: every problem without a layer and, for ``"newton"``, a linear layer.
OPTIONS = {
    "newton": ("record", "inner_maxiter"),
    "augmented_gap": ("relaxation", "eps_h", "eps_p", "record"),
    "variable_compliance": ("eps_p", "record"),
    "kalker": (),
}


def solver_for(method, layer):
    """The solver that runs for ``method`` and ``layer``: ``"kalker"`` where the problem is a QP.

    Without a layer the functional is quadratic whatever the method, and so it is for
    ``"newton"`` with a linear layer: Kalker's QP solves it directly.

    Parameters
    ----------
    method : str
        One of :data:`METHODS`.
    layer : bem.layers.Layer or {None, "linear", "nonlinear"}
        The layer, or only its kind (a scene checks its options before building it).
    """
    kind = layer if layer is None or isinstance(layer, str) else ("linear" if layer.is_linear else "nonlinear")
    if kind is None or (kind == "linear" and method in ("kalker", "newton")):
        return "kalker"
    return method


def check_options(method, solver, options):
    """Checked solver ``options`` (a dict); refuse an unknown one, or one the solver does not take.

    Raises :class:`bem.InputError` naming the option, its value and the rule.
    """
    known = {k for keys in OPTIONS.values() for k in keys}
    for key, value in options.items():
        if key not in known:
            raise InputError(f"{key} = {value!r} is not allowed: it is not an option of bem.solve "
                             f"(options: {', '.join(sorted(known))}).")
        if key not in OPTIONS[solver]:
            why = (f"method = {method!r} is solved by Kalker's QP here (no layer, or a linear layer)"
                   if solver != method else f"method = {method!r} does not take it")
            users = [m for m, keys in OPTIONS.items() if key in keys]
            raise InputError(f"{key} = {value!r} is not allowed: {why}; it applies to "
                             f"{' and '.join(repr(m) for m in users)} with a nonlinear layer.")
    checked = {}
    for key, value in options.items():
        if key == "relaxation":
            checked[key] = check_range(key, value, 0.0, 1.0, low_open=True)
        elif key in ("eps_h", "eps_p"):
            checked[key] = check_positive(key, value)
        elif key == "record":
            checked[key] = check_bool(key, value)
        else:  # inner_maxiter
            checked[key] = check_int(key, value)
    return checked
