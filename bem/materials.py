"""Elastic constants of the two contacting bodies.

The half-space kernel (paper eq. 2-3, docs/method.md section 1) depends on the two
bodies only through Johnson's effective (contact) modulus ``E*``::

    1 / E* = (1 - nu1**2) / E1 + (1 - nu2**2) / E2

(K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985,
ISBN 978-0-521-34796-9, sec. 4.2).
"""

from __future__ import annotations

import math

from bem.checks import check_range, check_scale, fail

__all__ = ["NU_MIN", "NU_MAX", "compliance", "effective_modulus"]

#: Poisson's ratio must lie in ``(NU_MIN, NU_MAX]``: ``-1`` is excluded (the
#: bulk modulus would vanish), ``0.5`` (incompressible) is allowed.
NU_MIN = -1.0
NU_MAX = 0.5


def compliance(E, nu, *, name="E", nu_name="nu"):
    """Plane-strain surface compliance ``(1 - nu**2) / E`` of one body [1/pressure].

    Parameters
    ----------
    E : float
        Young's modulus [pressure], ``> 0``. ``math.inf`` stands for a rigid
        body and gives compliance 0.
    nu : float
        Poisson's ratio [-], in ``(-1, 0.5]``.
    name, nu_name : str, keyword-only
        Argument names used in error messages.

    Returns
    -------
    float
        ``(1 - nu**2) / E``; 0 for a rigid body.

    Raises
    ------
    bem.InputError
        If ``E`` is not a positive real (``inf`` allowed) or ``nu`` is outside
        ``(-1, 0.5]``.
    """
    nu = check_range(nu_name, nu, NU_MIN, NU_MAX, low_open=True)
    if isinstance(E, (int, float)) and not isinstance(E, bool) and E == math.inf:
        return 0.0
    E = check_scale(name, E)
    return (1.0 - nu * nu) / E


def effective_modulus(E1, nu1, E2, nu2):
    """Johnson's effective modulus ``E*`` of two bodies [pressure].

    ``1/E* = (1 - nu1**2)/E1 + (1 - nu2**2)/E2`` (Johnson 1985, ISBN
    978-0-521-34796-9, sec. 4.2). For two identical bodies
    ``E* = E / (2 (1 - nu**2))``; against a rigid counterpart
    ``E* = E / (1 - nu**2)``.

    Parameters
    ----------
    E1, E2 : float
        Young's moduli [pressure], ``> 0``; pass ``math.inf`` for a rigid body
        (at most one of the two).
    nu1, nu2 : float
        Poisson's ratios [-], each in ``(-1, 0.5]`` (``0.5`` incompressible
        allowed, ``-1`` excluded).

    Returns
    -------
    float
        ``E*`` in the units of ``E1`` and ``E2``.

    Raises
    ------
    bem.InputError
        Names the offending argument; also raised when both bodies are rigid.
    """
    total = compliance(E1, nu1, name="E1", nu_name="nu1") + compliance(
        E2, nu2, name="E2", nu_name="nu2"
    )
    if total == 0.0:
        fail("(E1, E2)", (E1, E2), "not both infinite (two rigid bodies have no contact modulus)")
    return 1.0 / total
