"""The transforms' library in a test (bem.fft's back end)."""

import pytest

from bem import fft


def use_library(monkeypatch, library):
    """The transforms of bem.fft through ``library``: "pocketfft" (SciPy's entry points), "scipy.fft" (its public
    functions) or "ducc0" (where :func:`bem.fft._library` takes it; skipped where ducc0 is not installed)."""
    if library == "ducc0":
        if fft._ducc0 is None:
            pytest.skip("ducc0 is not installed")
        return
    monkeypatch.setattr(fft, "_ducc0", None)
    if library == "scipy.fft":
        monkeypatch.setattr(fft, "_pocketfft", None)
