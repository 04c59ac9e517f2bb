"""--scheduler of a sweep: the address form is checked first, an unreachable or non-Dask server is a
one-line error within the timeout, a real Dask scheduler runs the points. Loopback addresses only."""

import contextlib
import socket
import struct
import threading
import time

import pytest

from validation.run.cluster import SchedulerError, scheduler_address
from validation.run.sweep import run_sweep

from .conftest import cli

FAST = ["bem.nodes_across=16"]


def _sweep(out, scheduler, **kw):
    return run_sweep("elliptic", out, parameter="load.force", values=[50.0, 100.0], workers=1, overrides=FAST,
                     scheduler=scheduler, **kw)


@contextlib.contextmanager
def _server(reply, *, hang_up=False):
    """A one-connection TCP server on 127.0.0.1 that sends ``reply`` and then hangs up or keeps the
    connection open until the test leaves; it gives up after 10 s and closes itself."""
    sock = socket.create_server(("127.0.0.1", 0))
    sock.settimeout(10.0)
    leave = threading.Event()

    def serve():
        try:
            conn, _ = sock.accept()
        except OSError:
            return
        with conn:
            try:
                conn.sendall(reply)
            except OSError:
                return
            if not hang_up:
                leave.wait(10.0)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield sock.getsockname()[1]
    finally:
        leave.set()
        sock.close()
        thread.join(10.0)


@pytest.mark.parametrize("address", ["", "   ", "localhost", "localhost:", ":8786", "localhost:0",
                                     "localhost:65536", "localhost:http", "http://localhost:8786",
                                     "tcp://", "tcp://localhost:8786/x", "a b:8786", "tcp://[::1:8786"])
def test_malformed_address_refused_before_any_work(tmp_path, address):
    with pytest.raises(SchedulerError, match=r"--scheduler = .* is not allowed: it must be host:port or "
                                             r"tcp://host:port"):
        _sweep(tmp_path, address)
    assert not (tmp_path / "points").exists()


@pytest.mark.parametrize("address, url", [("127.0.0.1:8786", "tcp://127.0.0.1:8786"),
                                          (" tcp://node-1.cluster:8786 ", "tcp://node-1.cluster:8786"),
                                          ("[::1]:8786", "tcp://[::1]:8786")])
def test_address_forms(address, url):
    assert scheduler_address(address)[0] == url


def _closed_port():
    with socket.create_server(("127.0.0.1", 0)) as sock:
        return sock.getsockname()[1]


def test_nothing_listening_is_a_one_line_error(tmp_path):
    port = _closed_port()
    start = time.monotonic()
    with pytest.raises(SchedulerError, match=r"--scheduler = .* cannot connect"):
        _sweep(tmp_path, f"127.0.0.1:{port}")
    assert time.monotonic() - start < 20.0  # a timeout honoured, not a speed: the unbounded connect took 31 s
    assert not (tmp_path / "points").exists()
    for address in (f"127.0.0.1:{port}", ""):
        code, out, err = cli("sweep", "elliptic", "--param", "load.force", "--values", "50", "--out", tmp_path,
                             "--set", FAST[0], "--scheduler", address)
        assert code == 2 and err.startswith("contactlab: error: --scheduler") and err.count("\n") == 1, err


@pytest.mark.parametrize("reply, hang_up, said", [
    (b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n", False, "its first message announces"),  # 2.8 EiB
    (struct.pack("Q", 24) + b"\xff" * 24, False, "is not a Dask handshake"),
    (b"\x01\x02", True, "closed the connection"),
    (b"", False, "within 0.5 s"),
], ids=["http", "bad-frames", "hangs-up", "silent"])
def test_a_server_that_is_not_dask_is_refused_quickly(tmp_path, reply, hang_up, said):
    with _server(reply, hang_up=hang_up) as port:
        start = time.monotonic()
        with pytest.raises(SchedulerError, match=rf"--scheduler = 'tcp://127.0.0.1:{port}' .*{said}"):
            _sweep(tmp_path, f"tcp://127.0.0.1:{port}", scheduler_timeout=0.5)
        assert time.monotonic() - start < 20.0  # a timeout honoured, not a speed: the unbounded connect took 31 s
    assert not (tmp_path / "points").exists()


def test_cli_garbage_server_exit_2(tmp_path):
    with _server(b"SSH-2.0-OpenSSH_9.6\r\n") as port:
        code, _out, err = cli("sweep", "elliptic", "--param", "load.force", "--values", "50", "--out", tmp_path,
                              "--set", FAST[0], "--scheduler", f"127.0.0.1:{port}", "--scheduler-timeout", "2")
    assert code == 2 and "not a Dask scheduler" in err and err.count("\n") == 1, err


def test_timeout_must_be_positive(tmp_path):
    with pytest.raises(ValueError, match=r"--scheduler-timeout = 0.0 is not allowed"):
        _sweep(tmp_path, "127.0.0.1:8786", scheduler_timeout=0.0)


def test_real_scheduler_by_address_runs_the_points(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        summary = _sweep(tmp_path / "dask", cluster.scheduler_address)
    local = _sweep(tmp_path / "local", None)
    assert summary["computed"] == [0, 1] and summary["failed"] == []
    assert [r["p_max"] for r in summary["points"]] == [r["p_max"] for r in local["points"]]
