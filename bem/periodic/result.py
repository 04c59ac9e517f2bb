"""The result of a periodic cell, :class:`PeriodicContactResult`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..result import ContactResult

__all__ = ["PeriodicContactResult"]


@dataclass
class PeriodicContactResult(ContactResult):
    """:class:`bem.ContactResult` of a periodic cell (``lattice`` is the :class:`PeriodicCell`).

    ``force`` is the force on one cell and ``displacement`` has zero mean over the cell;
    ``gap`` is the deformed gap ``C p + w(p) + h - delta``.
    """

    @property
    def mean_pressure(self):
        """Mean pressure over the cell, ``force / (Lx Ly)`` [pressure]."""
        return self.force / self.lattice.area

    @property
    def contact_fraction(self):
        """Fraction of the nodes in contact (``p > 0``): the relative contact area."""
        return float(np.count_nonzero(self.p > 0)) / self.p.size

    @property
    def plastic_fraction(self):
        """Fraction of the nodes at the hardness (``p = H``): the relative plastic area; 0 without a hardness."""
        if self.hardness is None:
            return 0.0
        return float(np.count_nonzero(self.p >= self.hardness)) / self.p.size

    @property
    def mean_gap(self):
        """Mean deformed gap over the cell, ``mean(h + w(p)) - delta`` [length] (the mean-plane separation)."""
        return float(np.mean(self.gap))

    def summary(self):
        out = super().summary()
        del out["contact_radius"]
        out.update(mean_pressure=float(self.mean_pressure), contact_fraction=self.contact_fraction,
                   mean_gap=self.mean_gap, plastic_fraction=self.plastic_fraction, cell=[int(self.lattice.n_cols), int(self.lattice.n_rows)])
        return out
