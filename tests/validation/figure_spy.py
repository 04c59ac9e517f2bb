"""What a figure shows: the matplotlib figures the report's plot functions save, and their lines."""

import numpy as np
import pytest


@pytest.fixture
def drawn(monkeypatch):
    """The matplotlib figures the plot functions save, in order (they are still written)."""
    from validation.report.figures import fields, iterations, precision, profiles, surfaces, sweeps

    figures = []
    for module in (profiles, iterations, precision, surfaces, sweeps, fields):
        def spy(fig, path, *args, _save=module.save_figure, **kwargs):
            figures.append(fig)
            return _save(fig, path, *args, **kwargs)

        monkeypatch.setattr(module, "save_figure", spy)
    return figures


def lines_of(ax):
    """``{label: (x, y)}`` of the labelled lines of ``ax``, in drawing order."""
    return {ln.get_label(): (np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float))
            for ln in ax.get_lines() if not ln.get_label().startswith("_")}


def vertical_at(ax, value):
    """Whether ``ax`` has a vertical line at ``x = value``."""
    return any(np.allclose(ln.get_xdata(), value) for ln in ax.get_lines())


def horizontal_at(ax, value):
    """Whether ``ax`` has a horizontal line at ``y = value``."""
    return any(np.allclose(ln.get_ydata(), value) for ln in ax.get_lines())
