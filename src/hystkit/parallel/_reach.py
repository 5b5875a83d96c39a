"""Reaching a Dask scheduler (``--scheduler``): its whole handshake within one deadline, and
what answered instead when that fails.

Dask's own ``connect`` bounds the TCP connection by its timeout but then waits for the
server's handshake without one: a port that accepts the connection and never answers (a
silent socket, ``python -m http.server``) held the command for ever. Here the handshake is
bounded as a whole. A server that answers at once in another protocol fails Dask's reader in
odd ways (the first 8 bytes of ``HTTP/1.0`` read as a frame size of 3 EiB: a MemoryError),
so a failure is described by a plain look at the port, not by Dask's exception.
"""

from __future__ import annotations

import asyncio
import socket
import threading
import time
from collections.abc import Coroutine
from typing import Any

from distributed.comm import connect
from distributed.comm.addressing import parse_address, parse_host_port

from ..errors import HystkitError

__all__ = ["DEFAULT_CONNECT_TIMEOUT", "SchedulerError", "check_handshake"]

# Seconds for the whole handshake: a scheduler on another continent answers in well under one;
# a loaded one, or one still starting, in a few.
DEFAULT_CONNECT_TIMEOUT = 20.0
# Seconds to look at a port that failed the handshake (its reply to a HEAD request, if any).
LOOK_TIMEOUT = 1.0
HTTP_PROBE = b"HEAD / HTTP/1.0\r\n\r\n"


class SchedulerError(HystkitError):
    """A Dask scheduler that cannot be reached or whose workers cannot run hystkit."""


def check_handshake(address: str, timeout: float) -> None:
    """Complete Dask's handshake with `address` (then close it) within `timeout` seconds.

    Parameters
    ----------
    address : str
        The scheduler's address, ``tcp://host:port`` (or ``host:port``; other Dask schemes
        such as ``tls://`` are bounded too, but not looked at on failure).
    timeout : float
        Seconds for the connection and the handshake together.

    Raises
    ------
    SchedulerError
        No handshake within `timeout`, or a server that is not a Dask scheduler, on one line
        that says what answered (nothing, an HTTP server, another protocol).
    """
    try:
        _run(_handshake(address, timeout))
    except Exception as exc:  # noqa: BLE001  (a foreign server can fail Dask's reader anyhow)
        timed_out = isinstance(exc, TimeoutError)
        raise SchedulerError(f"--scheduler {address}: cannot connect to a Dask scheduler "
                             f"there: {_what_answers(address, exc, timed_out, timeout)}"
                             ) from None


async def _handshake(address: str, timeout: float) -> None:
    comm = await asyncio.wait_for(connect(address, timeout=timeout), timeout)
    await comm.close()


def _run(coroutine: Coroutine[Any, Any, None]) -> None:
    """`asyncio.run`, on a thread of its own where this one already runs a loop (a notebook)."""
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        asyncio.run(coroutine)
        return
    failure: list[BaseException] = []

    def run() -> None:
        try:
            asyncio.run(coroutine)
        except BaseException as exc:  # noqa: BLE001  (handed to the caller's thread)
            failure.append(exc)

    thread = threading.Thread(target=run, name="hystkit-scheduler-handshake", daemon=True)
    thread.start()
    thread.join()
    if failure:
        raise failure[0]


def _what_answers(address: str, exc: BaseException, timed_out: bool, timeout: float) -> str:
    """One clause on what is at `address`, from a plain TCP look at it."""
    found = _look(address)
    if found is None:  # not a TCP address: Dask's own words
        return (f"no Dask handshake within {timeout:g} s" if timed_out
                else f"{type(exc).__name__}: {exc}")
    kind, reply = found
    if kind == "refused":
        return "nothing listens on that port (connection refused)"
    if kind == "error":
        return reply
    if reply.startswith(b"HTTP/"):
        status = reply.split(b"\r\n", 1)[0].decode("ascii", "replace")
        return (f"an HTTP server answers ({status}), not a Dask scheduler; a scheduler "
                f"listens on port 8786 by default (its dashboard, HTTP, on 8787)")
    if timed_out and not reply:
        return (f"the port accepts connections but no Dask handshake came within "
                f"{timeout:g} s (a firewall, or a server that is not a Dask scheduler)")
    if timed_out:
        return f"no Dask handshake within {timeout:g} s (the server there sent {reply[:16]!r})"
    return (f"the server there does not speak Dask's protocol (it sent {reply[:16]!r}, "
            f"{type(exc).__name__})")


def _look(address: str) -> tuple[str, bytes | str] | None:
    """("refused", ""), ("error", reason) or ("reply", its first bytes) from a TCP connection
    to `address` given an HTTP HEAD request; None for an address that is not TCP."""
    try:
        scheme, location = parse_address(address)
        if scheme != "tcp":
            return None
        host, port = parse_host_port(location)
    except (ValueError, TypeError):
        return None
    deadline = time.monotonic() + LOOK_TIMEOUT
    try:
        with socket.create_connection((host, port), timeout=LOOK_TIMEOUT) as sock:
            sock.sendall(HTTP_PROBE)
            reply = b""
            while len(reply) < 64 and (left := deadline - time.monotonic()) > 0:
                sock.settimeout(left)
                try:
                    chunk = sock.recv(64 - len(reply))
                except TimeoutError:
                    break
                if not chunk:
                    break
                reply += chunk
                if b"\r\n" in reply:
                    break
            return "reply", reply
    except ConnectionRefusedError:
        return "refused", ""
    except OSError as err:
        return "error", f"{type(err).__name__}: {err}"
