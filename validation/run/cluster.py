"""The Dask scheduler of a sweep: the address form, a probe of the server, the client.

An address is ``host:port`` or ``tcp://host:port`` (``host`` a name, an IPv4 address or an
IPv6 address in brackets, ``port`` 1..65535). Before the address goes to ``dask.distributed``
the server is probed with a plain socket under a timeout: a Dask scheduler opens every
connection by sending its handshake, one message framed as an 8-byte length followed by the
frames, whose content is a small table (``compression``, ``python``, ``pickle-protocol``). The
probe reads at most :data:`HANDSHAKE_LIMIT` bytes of it and decodes it; a server that is
silent, closes the connection, announces a longer message (a server of another protocol whose
first bytes read as a length of exbibytes) or sends something that does not decode is refused
with :class:`SchedulerError` before Dask would allocate or wait on it. (A scheduler logs the
probe as a connection closed before its handshake completed, at level INFO.)
"""

from __future__ import annotations

import re
import socket
import struct

from bem.checks import check_positive
from bem.errors import InputError

from ..extras import require as require_extra

__all__ = ["SchedulerError", "scheduler_address", "probe_scheduler", "dask_client", "DEFAULT_TIMEOUT",
           "HANDSHAKE_LIMIT"]

#: seconds allowed to connect to the scheduler and to read its handshake
DEFAULT_TIMEOUT = 10.0
#: the longest first message (bytes) accepted as a Dask handshake (a real one has about 60)
HANDSHAKE_LIMIT = 1 << 16
_RULE = "host:port or tcp://host:port (e.g. tcp://10.0.0.5:8786)"
_HOST = re.compile(r"^(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9]([A-Za-z0-9.-]*[A-Za-z0-9])?)$")
_PORT = re.compile(r"^[0-9]{1,5}$")
_LENGTH = struct.Struct("Q")  # the frame length of distributed.comm.tcp


class SchedulerError(InputError):
    """A ``--scheduler`` address that cannot be used: malformed, unreachable, or not a Dask scheduler."""


def _refuse(address, rule):
    raise SchedulerError(f"--scheduler = {address!r} is not allowed: {rule}.")


def scheduler_address(address):
    """Check the form of a scheduler address; returns ``("tcp://host:port", host, port)``.

    Raises
    ------
    SchedulerError
        Not a string of the form ``host:port`` or ``tcp://host:port``.
    """
    if not isinstance(address, str):
        _refuse(address, f"it must be {_RULE}")
    text = address.strip()
    rest = text[len("tcp://"):] if text.startswith("tcp://") else text
    if "://" in rest:
        _refuse(address, f"it must be {_RULE}; other protocols are not supported")
    host, sep, port = rest.rpartition(":")
    if not sep or not _HOST.match(host) or not _PORT.match(port) or not 1 <= int(port) <= 65535:
        _refuse(address, f"it must be {_RULE}, port 1..65535")
    return f"tcp://{host}:{int(port)}", host.strip("[]"), int(port)


def _read(sock, n, address):
    """Exactly ``n`` bytes from ``sock`` (the socket's timeout applies to each read)."""
    chunks, got = [], 0
    while got < n:
        chunk = sock.recv(min(n - got, 1 << 16))
        if not chunk:
            _refuse(address, "the server there closed the connection without a Dask handshake (is it a Dask "
                             "scheduler?)")
        chunks.append(chunk)
        got += len(chunk)
    return b"".join(chunks)


def _decode_handshake(body):
    """The handshake table of a Dask scheduler from the bytes after its length, or None."""
    from distributed.protocol import loads
    from distributed.protocol.utils import unpack_frames

    try:
        frames, missing = unpack_frames(body, partial=True)
        message = None if missing else loads(frames)
    except Exception:  # noqa: BLE001 - any failure to decode means: not a Dask handshake
        return None
    return message if isinstance(message, dict) and "python" in message else None


def probe_scheduler(address, timeout=DEFAULT_TIMEOUT):
    """Connect to ``address`` and read the scheduler's handshake, at most :data:`HANDSHAKE_LIMIT` bytes.

    Parameters
    ----------
    address : str
        ``host:port`` or ``tcp://host:port``.
    timeout : float
        Seconds allowed to connect and to wait for each read.

    Raises
    ------
    SchedulerError
        Malformed address, no connection (refused, unknown host, timeout), or a server whose
        first message is not a Dask handshake.
    """
    _url, host, port = scheduler_address(address)
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            (length,) = _LENGTH.unpack(_read(sock, _LENGTH.size, address))
            if length > HANDSHAKE_LIMIT:
                _refuse(address, f"the server there is not a Dask scheduler: its first message announces "
                                 f"{length} bytes, a Dask handshake has at most {HANDSHAKE_LIMIT}")
            body = _read(sock, length, address)
    except TimeoutError:
        _refuse(address, f"no Dask scheduler answered there within {timeout:g} s (--scheduler-timeout)")
    except OSError as exc:
        _refuse(address, f"cannot connect to it ({exc.strerror or exc})")
    if _decode_handshake(body) is None:
        _refuse(address, "the server there is not a Dask scheduler: its first message is not a Dask handshake")


def dask_client(scheduler, timeout=DEFAULT_TIMEOUT):
    """A ``dask.distributed.Client`` for an address (or a Client or cluster object) and an owned flag.

    An address is checked (:func:`scheduler_address`), the ``dask`` extra required and the server
    probed (:func:`probe_scheduler`) before the client connects with ``timeout``.

    Raises
    ------
    SchedulerError
        See :func:`probe_scheduler`; also when the client cannot connect within ``timeout``.
    validation.extras.MissingExtraError
        ``dask.distributed`` is not installed.
    """
    timeout = check_positive("--scheduler-timeout", timeout)
    if isinstance(scheduler, str):
        url = scheduler_address(scheduler)[0]
        require_extra("dask", f"--scheduler {scheduler!r} (a Dask cluster; without it the sweep runs on local cores)")
        probe_scheduler(scheduler, timeout)
    from dask import distributed

    if isinstance(scheduler, distributed.Client):
        return scheduler, False
    if not isinstance(scheduler, str):
        return distributed.Client(scheduler), True
    try:
        return distributed.Client(url, timeout=timeout), True
    except (OSError, TimeoutError) as exc:
        raise SchedulerError(f"--scheduler = {scheduler!r} is not allowed: the Dask client could not connect "
                             f"within {timeout:g} s ({exc}).") from None
