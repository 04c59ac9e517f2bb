"""Running scenes: the runner, the typed result, the stresses and sweeps.

- :mod:`validation.run.runner`: :func:`run_scene` / :func:`execute_scene`, the one place that
  solves a scene (BEM always; FEM, closed form, comparison, stresses when named); the scene's
  domain says what :func:`bem.solve` solves and makes the parts of the result that are its own: a
  region of the half-space (:mod:`validation.run.region`) or a periodic cell
  (:mod:`validation.run.periodic`);
- :mod:`validation.run.record`: :class:`RunResult`, the typed content of ``result.json`` (its
  JSON reading and writing, the schema version), its parts in :mod:`validation.run.parts`;
  :mod:`validation.run.result` makes it;
- :mod:`validation.run.stress`: the ``[stress]`` part of a run (a coated body's: :mod:`validation.run.stress_coated`);
- :mod:`validation.run.sweep`: one scene over a list of values of a parameter.
"""

from .record import ResultFileError, RunResult
from .runner import FILES, RunOutcome, check_result_dir, execute_scene, planned_stages, run_scene, write_outputs

__all__ = ["run_scene", "execute_scene", "write_outputs", "check_result_dir", "planned_stages", "RunOutcome",
           "RunResult", "ResultFileError", "FILES"]
