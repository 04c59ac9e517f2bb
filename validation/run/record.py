"""The typed result of a scene run, :class:`RunResult`: the content of ``result.json``.

A run makes one :class:`RunResult` (:func:`validation.run.result.build_result`); the report,
the studies and the CLI read it back through :meth:`RunResult.read`. Every part is a field:
a part that did not run (the FEM, the closed form, the comparison, the stresses, the
periodic summary) is ``None``, never an absent key. Numbers are in the scene's units
(``units``, ``unit_symbols``); a non-finite number is written as ``null`` and read as ``None``.

``result.json`` holds :meth:`RunResult.to_json` with ``"schema": SCHEMA`` first. Reading
checks the schema string and refuses another one (an older run: run the scene again), a
missing field and a field the schema does not have (:class:`ResultFileError`). Every field
and its unit: docs/results.md.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

# the parts a RunResult's annotations name (resolved in this module when a file is read)
from .parts import (SCHEMA, AxialProfile, BemPart, ClosedForm, Comparison, FemPart, FemProfile, PeriodicPart,
                    ResultFileError, Scales, StressPart, _Part)

__all__ = ["SCHEMA", "FILE_NAME", "ResultFileError", "RunResult"]

#: The file name of a run's result in its result directory.
FILE_NAME = "result.json"


@dataclass
class RunResult(_Part):
    """The result of one scene run (module docstring; every field: docs/results.md).

    The scalars at the top are the BEM's (the product); ``contact_radius`` (``sqrt(A / pi)``)
    is ``None`` for a scene that is not axisymmetric, ``contact_extent`` (farthest loaded node
    along x and y) ``None`` for a periodic cell. ``converged`` is true only when every part that
    ran converged. ``wall_time_s_by_part``: seconds per part (``bem``, ``fem``,
    ``layer_reference``, ``stress``, ``total``; ``None``: the part did not run).
    """

    scene: str
    title: str
    units: str
    unit_symbols: dict
    source: str | None
    overrides: list
    method: str
    p_max: float | None
    force: float | None
    approach: float | None
    contact_area: float | None
    contact_radius: float | None
    contact_extent: dict | None
    iterations: int
    converged: bool
    kkt_residual: float | None
    message: str
    messages: list
    wall_time_s_by_part: dict
    bem: BemPart
    layer: dict
    alpha_b: float | None
    fem: FemPart | None
    fem_profile: FemProfile | None
    analytic: ClosedForm | None
    comparison: Comparison | None
    scales: Scales | None
    profile: AxialProfile | None
    stress: StressPart | None
    periodic: PeriodicPart | None
    report: dict | None
    provenance: dict
    files: dict | None = None

    @property
    def axisymmetric(self):
        """Whether the run recorded an axisymmetric contact radius."""
        return self.contact_radius is not None

    def to_json(self):
        """The content of ``result.json``: ``{"schema": SCHEMA, ...fields}``."""
        return {"schema": SCHEMA, **super().to_json()}

    @classmethod
    def from_json(cls, data, *, where="result", source="result.json"):
        """The :class:`RunResult` of a ``result.json`` content; checks its ``schema`` first.

        Raises
        ------
        ResultFileError
            Not an object, another schema (the message shows the one found and the one
            expected), a missing or unknown field (named).
        """
        if not isinstance(data, dict):
            raise ResultFileError(f"{source} is not allowed: it must hold a JSON object, not {type(data).__name__}.")
        found = data.get("schema")
        if found != SCHEMA:
            raise ResultFileError(
                f"schema = {found!r} in {source} is not allowed: contactlab reads results of schema {SCHEMA!r} only; "
                "run the scene again (contactlab run SCENE --out DIR) to write it.")
        return super().from_json({k: v for k, v in data.items() if k != "schema"}, where=where, source=source)

    @classmethod
    def read(cls, path):
        """Read ``path`` (a ``result.json``).

        Raises
        ------
        ResultFileError
            The file cannot be read, is not JSON, or is not a result of :data:`SCHEMA` (:meth:`from_json`).
        """
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError) as exc:  # RecursionError: nested too deep
            raise ResultFileError(f"{path} is not allowed: it must be a readable JSON file ({exc}).") from None
        return cls.from_json(data, source=str(path))

    def write(self, folder, name=FILE_NAME):
        """Write :meth:`to_json` as ``folder / name`` atomically (whole or not at all,
        :func:`validation.io.atomic_write_json`); returns its path."""
        from ..io import atomic_write_json

        path = Path(folder) / name
        atomic_write_json(path, self.to_json())
        return path
