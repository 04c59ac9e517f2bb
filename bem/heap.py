"""The C library's free heap memory returned to the system before the largest products.

On Linux with glibc a block of memory above a threshold is mapped alone and unmapped when freed; below it the block
comes from the process's heap, and a freed block stays there for reuse. The threshold rises with the blocks freed, up
to 32 MB, so on a lattice of millions of nodes the arrays of a few MB to 32 MB that an iteration makes and frees (the
contact's flags, the nodes that may enter, the bands of the transforms) leave free blocks in the heap, resident
beside the large arrays of the next product. :func:`release` asks glibc (``malloc_trim(0)``) to return the whole free
pages of its heaps to the system before such a product; elsewhere (no glibc, another platform) it does nothing.
Measured in ``docs/performance.md``, "The C library's free heap before the largest products".
"""

from __future__ import annotations

import ctypes
import functools
import sys

__all__ = ["RELEASE_ABOVE", "above", "release"]

#: bytes of a product's work array above which :func:`release` is asked for before it is made
RELEASE_ABOVE = 128 << 20


@functools.cache
def _malloc_trim():
    """glibc's ``malloc_trim`` of this process, or ``None`` where there is none."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        trim = ctypes.CDLL(None).malloc_trim
    except (OSError, AttributeError):  # musl and other C libraries have no malloc_trim
        return None
    trim.argtypes, trim.restype = [ctypes.c_size_t], ctypes.c_int
    return trim


def above(nbytes):
    """Whether ``nbytes`` bytes [bytes] are above :data:`RELEASE_ABOVE`: arrays at which the solvers give memory the
    precedence over time (this module's release; :mod:`bem.newton`'s product held by a cell's model QP; the coarser
    cells' symbols let go in nested iteration, :meth:`bem.periodic.PeriodicCell.refine`)."""
    return nbytes > RELEASE_ABOVE


def release(nbytes):
    """Return the free heap memory of the C library to the system where an array of ``nbytes`` bytes is about to be
    made and ``nbytes`` is above :data:`RELEASE_ABOVE`.

    Parameters
    ----------
    nbytes : int
        Bytes of the array that follows [bytes].

    Returns
    -------
    bool
        Whether the C library was asked (glibc's ``malloc_trim(0)``).
    """
    trim = _malloc_trim() if above(nbytes) else None
    if trim is None:
        return False
    trim(0)
    return True
