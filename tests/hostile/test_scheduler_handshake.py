"""``--scheduler`` at a port that is not a Dask scheduler (issue 25.7).

A port that accepts the connection and never answers (a silent socket, ``python -m
http.server``, which waits for a request line that Dask's binary handshake does not end) held
the command for ever: Dask bounds the connection, not the server's handshake. A server that
answers HTTP at once was reported as "out of memory" (Dask read ``HTTP/1.0`` as a frame size
of 3 EiB). Each must be refused within the handshake timeout, on one line saying what answered.
"""

from __future__ import annotations

import http.server
import socket
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from hystkit.errors import HystkitError
from hystkit.parallel import open_executor

from .conftest import snapshot

pytest.importorskip("distributed")

TIMEOUT = 1.0  # seconds given to the handshake here (the default is 20)
# What a refusal may take beyond TIMEOUT: the look at the port (1 s at most) and the test
# machine's load (2 cores shared by several test runs).
SLACK = 4.0


@contextmanager
def _listener(on_accept: Callable[[socket.socket], None]) -> Iterator[str]:
    """A TCP server on a free local port whose every connection goes to `on_accept` (on a
    daemon thread); yields its ``tcp://`` address."""
    server = socket.create_server(("127.0.0.1", 0))
    accepted: list[socket.socket] = []
    stop = threading.Event()

    def serve() -> None:
        while not stop.is_set():
            try:
                conn, _ = server.accept()
            except OSError:  # closed at the end of the test
                return
            accepted.append(conn)
            on_accept(conn)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{server.getsockname()[1]}"
    finally:
        stop.set()
        server.shutdown(socket.SHUT_RDWR)  # wakes the blocked accept (close alone does not)
        server.close()
        for conn in accepted:
            conn.close()
        thread.join(5)


def _silent(conn: socket.socket) -> None:
    """Accept and never answer."""


def _http_at_once(conn: socket.socket) -> None:
    """Answer HTTP before reading anything (what Dask read as a 3 EiB frame)."""
    conn.sendall(b"HTTP/1.0 400 Bad request\r\nContent-Length: 0\r\n\r\n")


@pytest.fixture
def http_server() -> Iterator[str]:
    """The standard library's HTTP server (``python -m http.server``) on a free local port."""
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _QuietHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(5)


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:
        pass


def _refusal(address: str) -> tuple[str, float]:
    start = time.monotonic()
    with pytest.raises(HystkitError) as info, \
            open_executor(scheduler=address, connect_timeout=TIMEOUT):
        pass
    return str(info.value), time.monotonic() - start


def test_a_silent_port_is_refused_within_the_timeout():
    with _listener(_silent) as address:
        message, took = _refusal(address)
    assert took < TIMEOUT + SLACK, took
    assert f"--scheduler {address}: cannot connect to a Dask scheduler there" in message
    assert "accepts connections but no Dask handshake came within 1 s" in message
    assert "\n" not in message


def test_an_http_server_that_answers_at_once_is_named_not_out_of_memory():
    with _listener(_http_at_once) as address:
        message, took = _refusal(address)
    assert took < TIMEOUT + SLACK, took
    assert "an HTTP server answers (HTTP/1.0 400 Bad request)" in message
    assert "memory" not in message.lower()


def test_python_http_server_is_refused_within_the_timeout_and_named(http_server):
    message, took = _refusal(http_server)
    assert took < TIMEOUT + SLACK, took
    assert "an HTTP server answers (HTTP/1.0 200 OK)" in message
    assert "port 8786" in message


def test_the_cli_refuses_a_silent_scheduler_in_one_line(cli, good: dict[str, Path],
                                                        tmp_path: Path):
    out = tmp_path / "cmp"
    with _listener(_silent) as address:
        start = time.monotonic()
        run = cli("compare", good["fit"], good["val"], "--models", "pl", "--out", out,
                  "--scheduler", address, "--scheduler-timeout", TIMEOUT)
        took = time.monotonic() - start
    assert run.code == 2, run.err
    run.error_line(f"--scheduler {address}", "no Dask handshake came within 1 s")
    assert took < TIMEOUT + SLACK, took
    assert snapshot(tmp_path) == {} and not out.exists()


def test_scheduler_timeout_without_a_scheduler_is_refused(cli, good: dict[str, Path],
                                                          tmp_path: Path):
    run = cli("compare", good["fit"], good["val"], "--models", "pl", "--out",
              tmp_path / "cmp", "--scheduler-timeout", 5)
    assert run.code == 2
    run.error_line("--scheduler-timeout applies to --scheduler only")
    assert not (tmp_path / "cmp").exists()
