"""FFT back end of the influence operators: thread count, fast sizes, transforms in place and in parts.

Thread count
    :func:`threads` is the number of CPUs this process may run on, ``len(os.sched_getaffinity(0))``
    (``os.cpu_count()`` where the platform has no affinity call), so a job confined by ``taskset``, cgroups or a
    batch system does not oversubscribe its cores. Override it with the environment variable
    ``CONTACTLAB_THREADS`` (read at every call) or with :func:`set_threads` (takes precedence;
    ``set_threads(None)`` undoes it).

Back end
    ``scipy.fft`` (pocketfft), chosen by measurement against pyFFTW (``benchmarks/fft_floor.py``; the table is in
    ``docs/performance.md``). pyFFTW wins only with ``FFTW_MEASURE`` plans, whose planning takes longer than a
    whole solve, per shape (every support window has its own); with ``FFTW_ESTIMATE`` it is slower than
    pocketfft, which plans in microseconds and caches its plans. Where ducc0 is installed (``contactlab[fast]``),
    its transforms replace pocketfft's in double precision and the complex ones in single precision, where they
    are faster; pocketfft keeps the single-precision real transforms, where ducc0's are slower (:func:`_library`;
    measured by ``benchmarks/fft_floor.py --primitives``). The numbers then differ from pocketfft's by rounding.

Parts on threads
    :func:`in_parts` runs a kernel on :func:`threads` contiguous parts of an array at once (NumPy's ufuncs,
    numba's ``nogil`` kernels, pocketfft and ducc0 release the GIL): the calling thread takes the last part itself and a
    pool of ``threads() - 1`` threads the others (:mod:`bem.pool`: each handed its part through a pair of locks);
    arrays below ``2**17`` entries stay in the calling thread. The
    transforms of the solvers' iterations run so too (:func:`rfft_into`, :func:`cfft_in_place`,
    :func:`irfft_into`, and the pruned transforms of :mod:`bem.pruned_fft`), one single-threaded call of the
    transform's library per part, rather than with pocketfft's ``workers``, whose calling thread sleeps while its
    pool works and whose pool threads the scheduler may wake on one core, where they take turns (measured in
    ``docs/performance.md``, "Threads that share a core"). The numbers are the same either way, and on any number of
    threads: the parts of a transform begin at multiples of :data:`LINES` lines.

The pruned padded transforms of the half-space's convolutions are :mod:`bem.pruned_fft`.
"""

from __future__ import annotations

import os

import numpy as np
import scipy.fft as _sfft

from .pool import run_parts


def _checks_out(lib):
    """Whether ``lib``'s ``r2c``, ``c2c`` and ``c2r`` take the positional signatures used here, write into a given
    array and give NumPy's numbers on a small array."""
    try:
        x = np.arange(8.0).reshape(2, 4)
        s = lib.c2c(lib.r2c(x, (1,), True, 0, np.empty((2, 3), dtype=complex), 1), (0,), True, 0, None, 1)
        back = lib.c2r(lib.c2c(s, (0,), False, 2, None, 1), (1,), 4, False, 2, np.empty((2, 4)), 1)
        return bool(np.allclose(s, np.fft.rfft2(x), rtol=0, atol=1e-12) and np.allclose(back, x, rtol=0, atol=1e-12))
    except Exception:  # a changed signature or module falls back  # noqa: BLE001
        return False


def _entry_points():
    """pocketfft's own entry points in SciPy, which write into a given array (``scipy.fft``'s allocate their
    output), where they exist with the signatures used here and give NumPy's numbers on a small array; else
    ``None`` (the transforms then call ``scipy.fft``, one copy of each part more)."""
    try:
        from scipy.fft._pocketfft import pypocketfft as pp
    except ImportError:  # a private module: any SciPy that lacks it falls back
        return None
    return pp if _checks_out(pp) else None


def _ducc_entry_points():
    """``ducc0.fft`` (the same entry points as pocketfft's, :func:`_entry_points`), where installed and checking out
    as those do; else ``None``."""
    try:
        from ducc0 import fft as ducc
    except ImportError:
        return None
    return ducc if _checks_out(ducc) else None


_pocketfft = _entry_points()
_ducc0 = _ducc_entry_points()


def _library(kind, dtype):
    """The entry points of a transform (``kind``: ``"r2c"``, ``"c2c"`` or ``"c2r"``) of data of ``dtype``: ducc0's
    where installed, but for the real transforms in single precision (``r2c`` of float32, ``c2r`` of complex64),
    whose pocketfft forms are faster; else pocketfft's (``None``: through ``scipy.fft``)."""
    if _ducc0 is not None and (kind == "c2c" or np.dtype(dtype).char not in "fF"):
        return _ducc0
    return _pocketfft

__all__ = ["threads", "set_threads", "fast_length", "in_parts", "rfft_into", "cfft_in_place", "irfft_into",
           "half_spectrum_weights", "back_end", "BLOCK", "LINES"]

_ENV = "CONTACTLAB_THREADS"
_override = None
#: entries per block of the element-wise products of spectra that run in place (their buffers hold one
#: block, not a spectrum)
BLOCK = 1 << 15
_PARTS_MIN = 1 << 17  # entries below which in_parts runs in the calling thread
#: lines of a transform at which its parts begin (:func:`in_parts`' ``align``): ducc0 transforms the lines of a call
#: in groups of its vector length and the last few apart, rounded otherwise, so that parts beginning at multiples of
#: the group give the numbers of one call on the whole array
LINES = 64


def _available_cpus():
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # macOS, Windows: no affinity call
        return os.cpu_count() or 1


def threads():
    """Number of threads the FFTs use.

    Returns
    -------
    int
        :func:`set_threads` value if set, else ``CONTACTLAB_THREADS`` if set to
        a positive integer, else the number of CPUs in this process's affinity
        mask (``os.cpu_count()`` without one); at least 1.
    """
    if _override is not None:
        return _override
    env = os.environ.get(_ENV, "").strip()
    if env:
        try:
            value = int(env)
        except ValueError:
            value = 0
        if value > 0:
            return value
    return max(1, _available_cpus())


def set_threads(n):
    """Fix the FFT thread count for this process (``None``: back to the automatic rule).

    Parameters
    ----------
    n : int or None
        Threads, >= 1, or ``None``.

    Returns
    -------
    int or None
        The previous override, so that a caller can restore it.
    """
    global _override
    if n is not None:
        from .checks import fail

        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            fail("n", n, "an integer >= 1 or None")
    previous, _override = _override, n
    return previous


def in_parts(kernel, n, size, align=1):
    """Call ``kernel(part)`` on contiguous slices ``part`` of ``range(n)``, on :func:`threads` threads.

    The calling thread runs the last part, a pool of ``threads() - 1`` threads the others. Where another thread's
    call holds the pool, the parts run one after another in the calling thread (the same parts).

    Parameters
    ----------
    kernel : callable
        ``kernel(part)`` with ``part`` a ``slice``; the calls must touch disjoint data (a call of
        :func:`in_parts` inside one runs its parts in its own thread).
    n : int
        Length of the axis that is split.
    size : int
        Entries of the caller's arrays: below ``2**17``, or with one thread, ``kernel``
        runs once on the whole axis in the calling thread.
    align : int
        The parts begin at multiples of ``align`` (fewer parts where ``n`` is short of them).

    Raises
    ------
    Exception
        As :func:`bem.pool.run_parts`: the first part's exception after every part has ended.
    """
    k = min(threads(), n)
    bounds = sorted({0, n} | {n * i // k // align * align for i in range(1, k)}) if k > 1 else [0, n]
    k = len(bounds) - 1
    if k < 2 or size < _PARTS_MIN:
        kernel(slice(0, n))
        return
    run_parts(kernel, [slice(lo, hi) for lo, hi in zip(bounds[:-1], bounds[1:])])


def _by_parts(call, shape, split, size):
    """``call(index)`` with ``index`` selecting contiguous parts of the axis ``split`` of an array of ``shape``
    (:func:`in_parts`); ``split = None``: once on the whole array, in the calling thread."""
    if split is None:
        return call((Ellipsis,))
    lead = (slice(None),) * split
    in_parts(lambda part: call(lead + (part,)), shape[split], size, align=LINES)


def back_end():
    """The libraries of the transforms (:func:`_library`), as a benchmark records them.

    Returns
    -------
    str
        ``"pocketfft (SciPy <version>)"``, ``"scipy.fft (SciPy <version>)"`` where its entry points do not check
        out, or with ducc0 ``"ducc0 <version>; <that> for single-precision real transforms"``.
    """
    import scipy

    base = f"{'pocketfft' if _pocketfft is not None else 'scipy.fft'} (SciPy {scipy.__version__})"
    if _ducc0 is None:
        return base
    import ducc0

    return f"ducc0 {ducc0.__version__}; {base} for single-precision real transforms"


def _transform_parts(kind, dtype, fast, fallback, shape, split, size):
    """``fast(lib, index)`` with the entry points ``lib`` of :func:`_library` or, where there are none,
    ``fallback(index)`` (``scipy.fft``) on the parts of the axis ``split`` (:func:`_by_parts`)."""
    lib = _library(kind, dtype)
    _by_parts(fallback if lib is None else (lambda i: fast(lib, i)), shape, split, size)


def rfft_into(x, out, axis, split=0):
    """Real FFT of ``x`` along ``axis`` (unnormalised) written into ``out``, in parts of the axis ``split``.

    Parameters
    ----------
    x : ndarray
        Real data (float32 or float64; views allowed). Not modified.
    out : ndarray
        ``x``'s shape with ``axis`` of length ``x.shape[axis] // 2 + 1``, complex of ``x``'s precision.
    axis, split : int
        The transformed axis and the axis whose parts the :func:`in_parts` threads take (non-negative,
        different).

    Returns
    -------
    ndarray
        ``out``.
    """
    _transform_parts("r2c", x.dtype, lambda lib, i: lib.r2c(x[i], (axis,), True, 0, out[i], 1),
                     lambda i: out.__setitem__(i, _sfft.rfft(x[i], axis=axis, workers=1)), x.shape, split, x.size)
    return out


def cfft_in_place(x, axis, split, inverse=False, normalise=True):
    """Complex FFT of ``x`` along ``axis``, in place, in parts of the axis ``split``.

    Parameters
    ----------
    x : ndarray
        Complex data (complex64 or complex128; views allowed), overwritten by its transform.
    axis, split : int
        As for :func:`rfft_into`; ``split = None``: in the calling thread (one of :func:`in_parts`'s, say).
    inverse : bool
        The inverse transform (a positive exponent).
    normalise : bool
        With ``inverse``: divided by the length of ``axis`` (``scipy.fft.ifft``'s ``norm="backward"``);
        without, not (``norm="forward"``). The forward transform is never scaled.

    Returns
    -------
    ndarray
        ``x``.
    """
    norm = "forward" if inverse and not normalise else "backward"
    fallback = _sfft.ifft if inverse else _sfft.fft
    _transform_parts("c2c", x.dtype,
                     lambda lib, i: lib.c2c(x[i], (axis,), not inverse, 2 if inverse and normalise else 0, x[i], 1),
                     lambda i: x.__setitem__(i, fallback(x[i], axis=axis, norm=norm, overwrite_x=True, workers=1)),
                     x.shape, split, x.size)
    return x


def irfft_into(x, out, n, axis, split=0, normalise=True):
    """Inverse real FFT of ``x`` along ``axis`` written into ``out``, in parts of the axis ``split``.

    Parameters
    ----------
    x : ndarray
        A half spectrum (complex64 or complex128; views allowed). Not modified.
    out : ndarray
        ``x``'s shape with ``axis`` of length ``n``, real of ``x``'s precision.
    n : int
        Points of the real transform along ``axis``.
    axis, split : int
        As for :func:`rfft_into`.
    normalise : bool
        Divided by ``n`` (``scipy.fft.irfft``'s ``norm="backward"``) or not (``norm="forward"``).

    Returns
    -------
    ndarray
        ``out``.
    """
    norm = "backward" if normalise else "forward"
    _transform_parts("c2r", x.dtype, lambda lib, i: lib.c2r(x[i], (axis,), n, False, 2 if normalise else 0, out[i], 1),
                     lambda i: out.__setitem__(i, _sfft.irfft(x[i], n=n, axis=axis, norm=norm, workers=1)),
                     out.shape, split, out.size)
    return out


def half_spectrum_weights(n_cols, xp=np):
    """Weights of the columns of a real FFT's half spectrum (last axis of ``n_cols`` points, ``n_cols // 2 + 1``
    columns) in a sum over the whole spectrum: 2, as a column stands for two conjugate frequencies, but 1 for
    column 0 and, ``n_cols`` even, the Nyquist column ``n_cols / 2`` (float64, in the namespace ``xp``)."""
    weight = xp.full((n_cols // 2 + 1,), 2.0, dtype=xp.float64)
    weight[0] = 1.0
    if n_cols % 2 == 0:
        weight[-1] = 1.0
    return weight


def fast_length(n, real):
    """Smallest length ``>= n`` that the back end transforms fast.

    Parameters
    ----------
    n : int
        Minimum length (no wrap-around of the padded convolution).
    real : bool
        ``True`` for the axis of the real-to-complex transform (pocketfft's real
        transforms take 2-3-5 factors), ``False`` for a complex one (up to 11).
    """
    return _sfft.next_fast_len(int(n), real=real)
