"""Periodic contact: a cell of the triangular lattice repeated in the plane (a rough surface patch).

:class:`PeriodicCell` (the cell and its nodes), :class:`PeriodicOperator` (the exact periodic
influence operator of the pyramid basis, :mod:`bem.periodic.kernel`; of coated bodies,
:mod:`bem.periodic.coated`) and
:func:`solve_periodic` (every method of :func:`bem.solve` on the cell). docs/method.md,
section "Periodic contact".
"""

from .cell import PeriodicCell
from .influence import PeriodicOperator
from .kernel import periodic_template
from .solve import PeriodicContactResult, solve_periodic

__all__ = ["PeriodicCell", "PeriodicOperator", "PeriodicContactResult", "periodic_template", "solve_periodic"]
