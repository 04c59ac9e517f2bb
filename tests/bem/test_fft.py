"""The FFT back end: thread count rule and the padded transform pair."""

import os

import numpy as np
import pytest

from bem import fft
from bem.checks import InputError


def test_threads_follow_affinity_then_env_then_setter(monkeypatch):
    monkeypatch.delenv("CONTACTLAB_THREADS", raising=False)
    expected = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    assert fft.threads() == expected
    monkeypatch.setenv("CONTACTLAB_THREADS", "3")
    assert fft.threads() == 3
    monkeypatch.setenv("CONTACTLAB_THREADS", "zero")  # unusable: back to the affinity rule
    assert fft.threads() == expected
    previous = fft.set_threads(1)
    try:
        assert fft.threads() == 1
    finally:
        fft.set_threads(previous)
    assert fft.threads() == expected


@pytest.mark.parametrize("bad", [0, -1, 2.0, True, "2"])
def test_set_threads_refuses_bad_values(bad):
    with pytest.raises(InputError, match="n = "):
        fft.set_threads(bad)


def test_forward_inverse_is_a_zero_padded_circular_pair():
    rng = np.random.default_rng(0)
    x = rng.random((2, 5, 7))
    shape = (fft.fast_length(11, real=False), fft.fast_length(15, real=True))
    back = fft.inverse(fft.forward(x, shape), shape, (5, 7)) / (shape[0] * shape[1])
    np.testing.assert_allclose(back, x, rtol=0, atol=1e-14)
