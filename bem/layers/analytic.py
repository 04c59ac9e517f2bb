"""Closed-form layer laws: linear (eq. 12), power (eq. 16), root, bilinear, elastic-rigid.

The root, elastic-rigid and bilinear laws are those of the paper's test problems (section 6,
Fig. 4 b-d). Every method is vectorised, clips ``p < 0`` to 0 and returns the right derivative
at kinks (``dw`` is the tangent compliance of the branch that starts at ``p``).
"""

from __future__ import annotations

import numpy as np

from ..backend import anp
from ..checks import check_nonnegative, check_positive, check_range
from ._common import LawBase, as_closure, as_pressure, out

__all__ = ["Linear", "Power", "Root", "Bilinear", "ElasticRigid"]


class Linear(LawBase):
    """Winkler layer ``w = lam * p`` (paper eq. 12).

    Parameters
    ----------
    lam : float
        Compliance [length/pressure], ``> 0``.

    Notes
    -----
    ``dw = secant = lam``, ``W = lam p**2 / 2``, ``inverse(c) = c / lam``. The only law with
    ``is_linear = True``: the Kalker QP adds ``lam`` to the diagonal (eq. 13).
    """

    law = "linear"
    _required = ("lam",)
    is_linear = True
    array_api = True

    def __init__(self, lam):
        self.lam = check_positive("lam", lam)

    def _params(self):
        return {"lam": self.lam}

    def w(self, p):
        with np.errstate(over="ignore"):
            return out(self.lam * as_pressure(p))

    def dw(self, p):
        p = as_pressure(p)
        return out(anp.where(anp.isnan(p), np.nan, self.lam))

    def energy(self, p):
        with np.errstate(over="ignore"):
            return out(0.5 * self.lam * as_pressure(p) ** 2)

    def inverse(self, closure):
        c = as_closure(closure)
        return out(anp.where(c <= 0, 0.0, c) / self.lam)

    def secant(self, p):
        return self.dw(p)


class Power(LawBase):
    """Power law ``w = lam * p**s`` (paper eq. 16).

    Parameters
    ----------
    lam : float
        Coefficient [length/pressure**s], ``> 0``.
    s : float
        Exponent [-], in ``(0, MAX_EXPONENT]`` (``s < 1``: stiffening, typical of roughness).

    Notes
    -----
    ``dw = lam s p**(s-1)``: ``+inf`` at ``p = 0`` for ``s < 1``, ``lam`` for ``s = 1``, 0 for
    ``s > 1``; ``W = lam p**(s+1) / (s+1)``; ``inverse(c) = (c / lam)**(1/s)``.
    Overflow gives ``inf`` silently.
    """

    law = "power"
    _required = ("lam", "s")
    array_api = True
    #: largest exponent ``s``: larger ones describe no interface layer, and ``p**s`` overflows
    #: for pressures in Pa once ``s`` exceeds about 34
    MAX_EXPONENT = 10.0

    def __init__(self, lam, s):
        self.lam = check_positive("lam", lam)
        self.s = check_range("s", s, 0.0, self.MAX_EXPONENT, low_open=True)

    def _params(self):
        return {"lam": self.lam, "s": self.s}

    def w(self, p):
        with np.errstate(over="ignore"):
            return out(self.lam * as_pressure(p) ** self.s)

    def dw(self, p):
        with np.errstate(divide="ignore", over="ignore"):
            return out(self.lam * self.s * as_pressure(p) ** (self.s - 1.0))

    def energy(self, p):
        with np.errstate(over="ignore"):
            return out(self.lam * as_pressure(p) ** (self.s + 1.0) / (self.s + 1.0))

    def inverse(self, closure):
        c = as_closure(closure)
        with np.errstate(over="ignore"):
            return out((anp.where(c <= 0, 0.0, c) / self.lam) ** (1.0 / self.s))

    def secant(self, p):
        """``lam p**(s-1)``; at ``p = 0`` the limit (``inf``, ``lam`` or 0 as for ``dw``)."""
        with np.errstate(divide="ignore", over="ignore"):
            return out(self.lam * as_pressure(p) ** (self.s - 1.0))


class Root(Power):
    """Root law ``w = lam * sqrt(p)`` (paper Fig. 4 c): :class:`Power` with ``s = 1/2``.

    Parameters
    ----------
    lam : float
        Coefficient [length/pressure**0.5], ``> 0``.

    Notes
    -----
    ``dw = lam / (2 sqrt p)`` (``+inf`` at 0), ``W = 2 lam p**1.5 / 3``, ``inverse = (c/lam)**2``.
    """

    law = "root"
    _required = ("lam",)

    def __init__(self, lam):
        super().__init__(lam, 0.5)

    def _params(self):
        return {"lam": self.lam}

    # Square roots instead of the general power: np.power with exponent -0.5 or 1.5 costs
    # 10x np.sqrt (measured: 1,048,703 nodes, dw 29 ms against 3 ms). Each works in the new array
    # of as_pressure (or of the square root) where it has one: the same numbers, fewer arrays.
    def w(self, p):
        r = _sqrt_of_new(as_pressure(p))
        r *= self.lam
        return out(r)

    def dw(self, p):
        with np.errstate(divide="ignore", over="ignore"):
            return out(_divided(0.5 * self.lam, _sqrt_of_new(as_pressure(p))))

    def energy(self, p):
        p = as_pressure(p)
        with np.errstate(over="ignore"):
            r = anp.sqrt(p)  # (2 lam / 3) (p sqrt(p)), the products in the new array of the root
            r *= p
            r *= 2.0 / 3.0 * self.lam
            return out(r)

    def secant(self, p):
        """``lam / sqrt(p)``; ``inf`` at ``p = 0``."""
        with np.errstate(divide="ignore", over="ignore"):
            return out(_divided(self.lam, _sqrt_of_new(as_pressure(p))))


def _sqrt_of_new(x):
    """``sqrt(x)`` of a new array ``x`` (as_pressure's), in its buffer where it is a NumPy array."""
    return np.sqrt(x, out=x) if isinstance(x, np.ndarray) else anp.sqrt(x)


def _divided(c, x):
    """``c / x`` of a new array ``x``, in its buffer where it is a NumPy array."""
    return np.divide(c, x, out=x) if isinstance(x, np.ndarray) else c / x


class Bilinear(LawBase):
    """Bilinear law: slope ``lam1`` up to ``p_star``, slope ``lam2`` beyond (paper Fig. 4 d).

    ``w = lam1 min(p, p_star) + lam2 max(p - p_star, 0)``.

    Parameters
    ----------
    lam1 : float
        Compliance below ``p_star`` [length/pressure], ``> 0``.
    lam2 : float
        Compliance above ``p_star`` [length/pressure], ``>= 0`` (0: elastic-rigid).
    p_star : float
        Pressure of the kink [pressure], ``> 0``.

    Notes
    -----
    ``dw`` is the right derivative: ``lam1`` for ``p < p_star``, ``lam2`` for ``p >= p_star``.
    ``inverse(c)`` is ``c / lam1`` up to ``w* = lam1 p_star``, ``p_star + (c - w*) / lam2``
    beyond; with ``lam2 = 0`` it is ``+inf`` for ``c > w*`` (the rigid branch cannot close
    further) and ``p_star`` (the smallest pressure reaching it) at ``c = w*``.
    """

    law = "bilinear"
    _required = ("lam1", "lam2", "p_star")
    array_api = True

    def __init__(self, lam1, lam2, p_star):
        self.lam1 = check_positive("lam1", lam1)
        self.lam2 = check_nonnegative("lam2", lam2)
        self.p_star = check_positive("p_star", p_star)

    def _params(self):
        return {"lam1": self.lam1, "lam2": self.lam2, "p_star": self.p_star}

    @property
    def p_scale(self):
        return self.p_star

    def w(self, p):
        p = as_pressure(p)
        w = self.lam1 * anp.minimum(p, self.p_star)
        if self.lam2 > 0:  # skip 0 * inf
            with np.errstate(over="ignore"):
                w = w + self.lam2 * anp.maximum(p - self.p_star, 0.0)
        return out(w)

    def dw(self, p):
        p = as_pressure(p)
        return out(anp.where(p < self.p_star, self.lam1, anp.where(anp.isnan(p), np.nan, self.lam2)))

    def energy(self, p):
        p = as_pressure(p)
        ps, l1 = self.p_star, self.lam1
        q = anp.minimum(p, ps)
        beyond = anp.maximum(p - ps, 0.0)
        with np.errstate(over="ignore"):
            energy = 0.5 * l1 * q**2 + l1 * ps * beyond
            if self.lam2 > 0:  # skip 0 * inf
                energy = energy + 0.5 * self.lam2 * beyond**2
        return out(energy)

    def inverse(self, closure):
        c = as_closure(closure)
        w_star = self.lam1 * self.p_star
        elastic = anp.where(c <= 0, 0.0, anp.minimum(c, w_star)) / self.lam1
        elastic = anp.where(c == w_star, self.p_star, elastic)
        beyond = np.inf  # lam2 = 0: the rigid branch cannot close further
        if self.lam2 > 0:
            with np.errstate(over="ignore"):
                beyond = self.p_star + anp.maximum(c - w_star, 0.0) / self.lam2
        return out(anp.where(c > w_star, beyond, elastic))


class ElasticRigid(Bilinear):
    """Elastic-rigid law ``w = lam * min(p, p_cr)`` (paper Fig. 4 b).

    Parameters
    ----------
    lam : float
        Compliance of the elastic branch [length/pressure], ``> 0``.
    p_cr : float
        Pressure at which the layer turns rigid [pressure], ``> 0``.

    Notes
    -----
    :class:`Bilinear` with ``lam2 = 0``: ``dw`` is ``lam`` below ``p_cr`` and 0 from ``p_cr``
    on; ``inverse(c) = +inf`` for ``c > lam p_cr``, ``p_cr`` at ``c = lam p_cr``.
    """

    law = "elastic_rigid"
    _required = ("lam", "p_cr")

    def __init__(self, lam, p_cr):
        super().__init__(check_positive("lam", lam), 0.0, check_positive("p_cr", p_cr))

    @property
    def lam(self):
        return self.lam1

    @property
    def p_cr(self):
        return self.p_star

    def _params(self):
        return {"lam": self.lam, "p_cr": self.p_cr}
