"""Array back ends: the array namespace and the FFTs of one device.

The solvers are written once against the Python array API standard; a :class:`Backend`
supplies the namespace ``xp`` of the arrays, the FFTs of that device and the few
operations the standard leaves out (gathers and scatters at a set of nodes, the
``errstate`` of NumPy, transfers to the host).

Devices
    ``"cpu"`` (default): NumPy, FFTs by ``scipy.fft`` (pocketfft) on :func:`bem.fft.threads`
    threads. ``"cuda"``: CuPy on the current CUDA device through ``array_api_compat.cupy``, FFTs
    by ``cupy.fft`` (cuFFT); needs the ``gpu`` extra (``pip install contactlab[gpu]``) and a
    CUDA driver. Any other module
    that implements the array API standard with its ``fft`` extension (e.g.
    ``array_api_strict``) may be passed as ``device``; its own ``xp.fft`` is used. Arrays
    stay in the device's namespace through the iterations; results come back to the host
    as NumPy arrays.

Node selections
    :meth:`Backend.select` returns an opaque selection of the nodes where a boolean brick
    array is true: flat indices on NumPy and CuPy (fast gathers through flat views), the
    boolean array itself on other namespaces (the standard has no integer-array
    assignment). Selections are used only through :meth:`take`, :meth:`put`,
    :meth:`spread`, :meth:`count` and :meth:`subset`; either kind visits the nodes in C order.
"""

from __future__ import annotations


import numpy as np

from . import fft as _cpu_fft
from . import pruned_fft as _pruned

__all__ = ["Backend", "get_backend", "backend_of", "operator_backend", "to_host"]


class Backend:
    """Array namespace, FFTs and node selections of one device.

    Parameters
    ----------
    xp : module
        Array namespace (``numpy``, ``cupy`` or an array API standard namespace).
    name : str
        ``"cpu"``, ``"cuda"`` or the namespace's module name.
    flat_indices : bool, optional
        Node selections as flat integer indices (needs integer-array assignment and
        ``reshape`` views, as NumPy and CuPy have); default: for NumPy and ``"cuda"``.
    """

    def __init__(self, xp, name, flat_indices=None):
        self.xp = xp
        self.name = name
        self.is_numpy = xp is np
        self._flat = (self.is_numpy or name == "cuda") if flat_indices is None else bool(flat_indices)
        self.float64 = xp.float64

    def __repr__(self):
        return f"Backend({self.name!r})"

    # -- transfers -------------------------------------------------------------------------------

    def asarray(self, x, dtype=None):
        """``x`` as an array of this device (float64 unless ``dtype``); a host array is copied over."""
        dtype = self.float64 if dtype is None else dtype
        if self.is_numpy:
            return np.asarray(x, dtype=dtype)
        if isinstance(x, np.ndarray) and self.name != "cuda":
            x = x.tolist() if x.ndim == 0 else x  # the standard's asarray takes buffers, not NumPy 0-d arrays
        return self.xp.asarray(x, dtype=dtype)

    def to_host(self, x):
        """A NumPy copy (or view, on the CPU) of a device array; ``None`` passes through."""
        return to_host(x)

    def errstate(self, **kw):
        """``numpy.errstate``: it covers NumPy and the namespaces that compute with NumPy (such as
        ``array_api_strict``); CuPy does not warn on floating-point events."""
        return np.errstate(**kw)

    # -- FFTs ---------------------------------------------------------------------------------------

    def forward(self, x, shape):
        """Spectrum of a batch of real arrays zero-padded to ``shape`` (:func:`bem.pruned_fft.forward`)."""
        if self.is_numpy:
            return _pruned.forward(x, shape)
        f = self.xp.fft
        return f.fft(f.rfft(x, n=shape[1], axis=-1), n=shape[0], axis=-2)

    def inverse(self, spectrum, shape, keep):
        """Inverse of :meth:`forward` without the ``1 / (Lk Lq)``, cropped (:func:`bem.pruned_fft.inverse`)."""
        if self.is_numpy:
            return _pruned.inverse(spectrum, shape, keep)
        f = self.xp.fft
        cols = f.ifft(spectrum, axis=-2, norm="forward")
        return f.irfft(cols[..., : keep[0], :], n=shape[1], axis=-1, norm="forward")[..., : keep[1]]

    def rfft(self, x, axis=-1):
        if self.is_numpy:
            import scipy.fft as sfft

            return sfft.rfft(x, axis=axis, workers=_cpu_fft.threads())
        return self.xp.fft.rfft(x, axis=axis)

    def cfft(self, x, axis, inverse=False):
        """Complex FFT (``inverse``: unnormalised-forward convention of ``norm="backward"``)."""
        if self.is_numpy:
            import scipy.fft as sfft

            return (sfft.ifft if inverse else sfft.fft)(x, axis=axis, overwrite_x=inverse, workers=_cpu_fft.threads())
        return (self.xp.fft.ifft if inverse else self.xp.fft.fft)(x, axis=axis)

    def irfft(self, x, n, axis=-1):
        if self.is_numpy:
            import scipy.fft as sfft

            return sfft.irfft(x, n=n, axis=axis, overwrite_x=True, workers=_cpu_fft.threads())
        return self.xp.fft.irfft(x, n=n, axis=axis)

    # -- reductions the standard spells differently -----------------------------------------------

    def max0(self, x):
        """``max(x)`` with the value 0.0 for an empty array, as a Python float (NaN propagates)."""
        if self.is_numpy:
            return float(x.max(initial=0.0))
        return float(self.xp.max(x)) if x.size else 0.0

    def min0(self, x):
        """``min(x)`` with the value 0.0 for an empty array, as a Python float."""
        if self.is_numpy:
            return float(x.min(initial=0.0))
        return float(self.xp.min(x)) if x.size else 0.0

    def dot(self, a, b):
        """``a.b`` of two 1-D arrays as a Python float (NumPy: ``einsum``, which calls no threaded BLAS)."""
        if self.is_numpy:
            return float(np.einsum("i,i->", a, b))
        return float(self.xp.sum(a * b))

    def norm(self, x):
        """Euclidean norm of an array as a Python float."""
        if self.is_numpy:
            return float(np.linalg.norm(x))
        return float(self.xp.sqrt(self.xp.sum(x * x)))

    def median(self, values, *, overwrite=False):
        """``numpy.median`` of a non-empty 1-D array, as a Python float (``overwrite``: ``values`` may be reordered,
        a copy fewer on NumPy)."""
        if self.is_numpy:
            return float(np.median(values, overwrite_input=overwrite))
        v = self.xp.sort(values)
        n = v.shape[0]
        return float(v[n // 2]) if n % 2 else float(self.xp.mean(v[n // 2 - 1 : n // 2 + 1]))

    def copy(self, x):
        return x.copy() if self._flat else self.xp.asarray(x, copy=True)

    # -- node selections ---------------------------------------------------------------------------

    def select(self, where):
        """Selection of the nodes where the boolean brick array ``where`` is true."""
        if self._flat:
            return self.xp.flatnonzero(where)
        return where

    def count(self, sel):
        """Number of selected nodes."""
        if self._flat:
            return int(sel.size)
        return int(self.xp.count_nonzero(sel))

    def take(self, x, sel):
        """Values of the brick array ``x`` at the selected nodes (1-D, C order)."""
        if self.is_numpy:  # np.take: faster than an index array on a flat view, the same values
            return np.take(x.reshape(-1), sel)
        if self._flat:
            return x.reshape(-1)[sel]
        return x[sel]

    def put(self, x, sel, values):
        """``x[sel] = values`` in place; returns ``x``."""
        if self._flat:
            x.reshape(-1)[sel] = values
        else:
            x[sel] = values
        return x

    def add_at(self, x, sel, values):
        """``x[sel] += values`` in place (each node once), rounded to ``x``'s precision; returns ``x``."""
        return self.put(x, sel, self.xp.astype(self.take(x, sel) + values, x.dtype, copy=False))

    def spread(self, shape, sel, values):
        """A brick array of ``shape`` holding ``values`` at the selected nodes, 0 elsewhere."""
        return self.put(self.xp.zeros(shape, dtype=self.float64), sel, values)

    def subset(self, sel, keep):
        """The selected nodes for which the boolean 1-D array ``keep`` (one entry per node) is true."""
        if self._flat:
            return sel[keep]
        out = self.xp.zeros(sel.shape, dtype=self.xp.bool)
        out[sel] = keep
        return out


_CPU = Backend(np, "cpu")
_CUDA = []


def _cuda():
    """The CuPy backend, through ``array_api_compat.cupy`` (the standard's names on CuPy's functions)."""
    if not _CUDA:
        import array_api_compat.cupy as xp

        _CUDA.append(Backend(xp, "cuda"))
    return _CUDA[0]


def get_backend(device="cpu"):
    """The :class:`Backend` of ``device``.

    Parameters
    ----------
    device : {"cpu", "cuda"} or module or Backend
        ``"cpu"``: NumPy; ``"cuda"``: CuPy (the ``gpu`` extra); a module: an array API
        standard namespace with the ``fft`` extension.

    Raises
    ------
    bem.InputError
        Unknown device, CuPy not installed or no CUDA device.
    """
    from .checks import fail
    from .errors import InputError

    if isinstance(device, Backend):
        return device
    if device is None or (isinstance(device, str) and device == "cpu") or device is np:
        return _CPU
    if isinstance(device, str):
        if device != "cuda":
            fail("device", device, "'cpu', 'cuda' or an array API namespace")
        try:
            import cupy
        except ImportError:
            raise InputError("device = 'cuda' is not allowed: CuPy is not installed "
                             "(pip install \"contactlab[gpu]\"); use device='cpu'.") from None
        try:
            n = cupy.cuda.runtime.getDeviceCount()
        except cupy.cuda.runtime.CUDARuntimeError:
            n = 0
        if n < 1:
            raise InputError("device = 'cuda' is not allowed: CuPy sees no CUDA device; use device='cpu'.")
        return _cuda()
    if not (hasattr(device, "asarray") and hasattr(device, "fft") and hasattr(device, "float64")):
        fail("device", device, "'cpu', 'cuda' or an array API namespace with the fft extension")
    return Backend(device, getattr(device, "__name__", "array_api"))


def backend_of(x):
    """The :class:`Backend` of an array (the CPU one for NumPy arrays, Python scalars and sequences)."""
    if isinstance(x, (np.ndarray, np.generic)) or not hasattr(x, "shape"):  # NumPy, scalars, lists
        return _CPU
    mod = type(x).__module__.split(".")[0]
    if mod == "cupy":
        return _cuda()
    if hasattr(x, "__array_namespace__"):
        return Backend(x.__array_namespace__(), mod)
    import array_api_compat

    return Backend(array_api_compat.array_namespace(x), mod)


def to_host(x):
    """A NumPy array of ``x`` (NumPy arrays pass through; ``None`` stays ``None``)."""
    if x is None or isinstance(x, (np.ndarray, np.generic, float, int)):
        return x
    if type(x).__module__.split(".")[0] == "cupy":
        return x.get()
    return np.array(np.from_dlpack(x), copy=True)  # an array API namespace's array (DLPack)


def operator_backend(op):
    """The backend and the device candidate mask of an operator (the CPU and ``lattice.mask`` by default)."""
    bk = getattr(op, "backend", _CPU)
    return bk, getattr(op, "mask", op.lattice.mask)


class _Dispatch:
    """NumPy-named functions that run in the namespace of their first device-array argument.

    ``anp.sqrt(x)`` is ``numpy.sqrt(x)`` for NumPy arrays and scalars and ``xp.sqrt(x)`` for an
    array of another namespace; ``anp.where`` also takes two scalars there. For the vectorised
    layer laws, whose methods take arrays of any device.
    """

    def __getattr__(self, name):
        np_f = getattr(np, name)

        def f(*args, **kw):
            for a in args:
                if hasattr(a, "shape") and not isinstance(a, (np.ndarray, np.generic)):
                    xp = backend_of(a).xp
                    break
            else:
                return np_f(*args, **kw)
            if name == "where":
                cond, x1, x2 = args
                if not hasattr(x1, "shape") and not hasattr(x2, "shape"):
                    x1 = xp.full(cond.shape, float(x1), dtype=xp.float64)
                return xp.where(cond, x1, x2)
            return getattr(xp, name)(*args, **kw)

        return f


anp = _Dispatch()
