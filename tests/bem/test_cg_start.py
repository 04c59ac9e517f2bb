"""The start of the constrained CG (bem.plastic.clipped_start): clipped in place only where allowed."""

import numpy as np
import pytest

from bem.backend import get_backend
from bem.plastic import clipped_start, in_place

BK = get_backend("cpu")


def _start():
    x0 = np.array([[-1.0, 0.5, 3.0], [2.0, -0.0, 7.0]])
    mask = np.array([[True, True, True], [False, True, True]])
    return x0, mask


@pytest.mark.parametrize("hardness", [None, 2.5])
def test_clipped_start_clips_at_zero_and_the_hardness_and_zeroes_off_the_mask(hardness):
    x0, mask = _start()
    top = np.inf if hardness is None else hardness
    expected = np.where(mask, np.clip(x0, 0.0, top), 0.0)
    copy = clipped_start(BK, x0.copy(), mask, hardness)
    own = x0.copy()
    inside = clipped_start(BK, own, mask, hardness, overwrite_x0=True)
    np.testing.assert_array_equal(copy, expected)
    np.testing.assert_array_equal(inside, expected)
    assert inside is own  # clipped where it is


def test_clipped_start_leaves_x0_alone_unless_allowed_and_able():
    x0, mask = _start()
    before = x0.copy()
    assert clipped_start(BK, x0, mask) is not x0
    np.testing.assert_array_equal(x0, before)
    read_only = x0.copy()
    read_only.flags.writeable = False
    for other in (x0.astype(np.float32), np.asfortranarray(x0), read_only):  # single precision, F order, read-only
        kept = other.copy()
        assert not in_place(BK, other)
        assert clipped_start(BK, other, mask, overwrite_x0=True) is not other
        np.testing.assert_array_equal(other, kept)
    assert not in_place(BK, [1.0, 2.0]) and in_place(BK, np.zeros(3))
