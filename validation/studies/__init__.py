"""Studies over the solvers: error against run time, and stability on stiff and extreme cases.

- :mod:`validation.studies.error_time`: pressure error against wall time over a ladder of
  resolutions for every BEM method and the FEM reference (:class:`ErrorTimeStudy`).
- :mod:`validation.studies.stability`: every method on stiff and extreme cases, each outcome
  classified ``converged`` / ``reported failure`` / ``wrong`` (:class:`StabilityStudy`);
  a wrong answer or a NaN raises :class:`StabilityFailure`.
- :mod:`validation.studies.problems`: the problems both studies run.

Each module has ``main(args)`` for the command line (``contactlab study error-time`` and
``contactlab study stability``).
"""

from __future__ import annotations

import json
import math
import statistics
import time

from bem.files import write_text

__all__ = ["write_text", "write_json", "markdown_table", "fmt", "timed"]


def write_json(path, data):
    """Write ``data`` as indented JSON, whole or not at all (``NaN``/``inf`` refused: JSON has none)."""
    return write_text(path, json.dumps(data, indent=2, allow_nan=False) + "\n")


def fmt(value, spec=".2e"):
    """A table cell: ``-`` for ``None``, ``yes``/``no`` for booleans, numbers with ``spec``."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return format(value, spec) if math.isfinite(value) else str(value)
    return str(value)


def markdown_table(headers, rows):
    """A GitHub-flavoured markdown table of already formatted cells (``|`` escaped)."""
    def line(cells):
        return "| " + " | ".join(str(c).replace("|", "\\|").replace("\n", " ") for c in cells) + " |"

    return "\n".join([line(headers), "|" + "|".join("---" for _ in headers) + "|"] + [line(r) for r in rows])


def timed(fn, *, repeats=3, slow_s=2.0):
    """Run ``fn()`` and time it: ``(result, median wall time [s], wall times of every run [s])``.

    The first run decides: if it takes longer than ``slow_s`` or its result says
    ``converged = False``, it is the only run; otherwise ``repeats`` runs in all and the
    median of their times is returned (with the last result; the solvers are deterministic).
    """
    times, result = [], None
    for k in range(max(1, repeats)):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
        if k == 0 and (times[0] > slow_s or not getattr(result, "converged", True)):
            break
    return result, statistics.median(times), times
