"""A solve that loads a tabulated layer law beyond its last pressure says so (a logged warning with
the law's range and the peak pressure) and keeps its answer; within the table it says nothing."""

import logging
import re

import numpy as np
import pytest

import bem
from bem import layers

from .conftest import C_NN, E_STAR, EXTENT, FORCE, P0_HERTZ, R, STEP


def _table(p_last):
    """``w = lam p`` sampled on ``0 .. p_last`` (a linear law as a table)."""
    p = np.linspace(0.0, p_last, 6)
    return layers.Tabulated(p, 3 * C_NN * p)


def _solve(layer):
    return bem.solve(bem.gaps.Paraboloid(R), E_star=E_STAR, step=STEP, extent=EXTENT, force=FORCE, layer=layer)


def _warnings(caplog):
    return [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]


def test_a_peak_pressure_beyond_the_table_is_reported_with_the_range(caplog):
    short = _table(0.5 * P0_HERTZ)
    with caplog.at_level(logging.WARNING):
        res = _solve(short)
    assert res.converged and res.p_max > 0.5 * P0_HERTZ
    (message,) = _warnings(caplog)
    m = re.search(r"peak pressure p_max = (\S+) exceeds the tabulated layer law's range 0 <= p <= (\S+) ", message)
    assert m is not None, message
    assert float(m.group(1)) == pytest.approx(res.p_max, rel=1e-5)
    assert float(m.group(2)) == pytest.approx(0.5 * P0_HERTZ, rel=1e-5)


def test_the_answer_beyond_the_table_is_the_linear_continuation_unchanged(caplog):
    """The warning changes nothing: the short table continued linearly is the linear law itself."""
    with caplog.at_level(logging.WARNING):
        short, full = _solve(_table(0.5 * P0_HERTZ)), _solve(layers.Linear(3 * C_NN))
    assert short.approach == pytest.approx(full.approach, rel=1e-6)
    assert short.p_max == pytest.approx(full.p_max, rel=1e-6)


def test_a_table_that_covers_the_peak_pressure_logs_no_warning(caplog):
    with caplog.at_level(logging.WARNING):
        res = _solve(_table(3 * P0_HERTZ))
    assert res.converged and res.p_max < 3 * P0_HERTZ
    assert _warnings(caplog) == []


def test_a_tabulated_part_of_a_series_is_looked_at():
    short = _table(0.5 * P0_HERTZ)
    assert layers.beyond_table(layers.Linear(C_NN) + short, P0_HERTZ) is not None
    assert layers.beyond_table(layers.Linear(C_NN) + short, 0.4 * P0_HERTZ) is None
    assert layers.beyond_table(layers.Linear(C_NN), 1e9 * P0_HERTZ) is None
    assert layers.beyond_table(None, P0_HERTZ) is None
