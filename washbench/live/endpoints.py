"""The sockets of a live session: addresses, the listening socket, the platform command sink."""

from __future__ import annotations

import errno
import socket
from collections.abc import Sequence

import numpy as np

from washbench.errors import WashbenchError
from washbench.live import commands

RECV_BUFFER = 1 << 23
"""Bytes of the receive buffer asked for (8 MiB: seconds of a 1 kHz source if the loop ever stalls; the system
may grant less, see net.core.rmem_max)."""


def parse_address(text: str, option: str, default_host: str = "127.0.0.1") -> tuple[str, int]:
    """``HOST:PORT``, ``udp://HOST:PORT`` or ``:PORT`` as (host, port); WashbenchError naming ``option``."""
    s = text.strip()
    if s.startswith("udp://"):
        s = s[len("udp://") :]
    elif "://" in s:
        raise WashbenchError(f"{option}: only udp:// addresses are supported, got {text!r}")
    host, sep, port = s.rpartition(":")
    if not sep:
        raise WashbenchError(f"{option}: expected HOST:PORT, got {text!r}")
    host = host.strip("[]") or default_host
    try:
        number = int(port)
    except ValueError:
        raise WashbenchError(f"{option}: port {port!r} is not a number") from None
    if not 0 < number < 65536:
        raise WashbenchError(f"{option}: port {number} is outside 1..65535")
    return host, number


def bind_udp(address: tuple[str, int], option: str = "--listen") -> socket.socket:
    """A UDP socket bound to ``address`` with a large receive buffer; one-line WashbenchError if it cannot be."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RECV_BUFFER)
        sock.bind(address)
    except OSError as exc:
        sock.close()
        if exc.errno == errno.EADDRINUSE:
            why = "the port is already in use (another program, or another washbench live, listens there)"
        elif isinstance(exc, socket.gaierror):
            why = f"unknown host ({exc.strerror})"
        else:
            why = exc.strerror or str(exc)
        raise WashbenchError(f"{option} {address[0]}:{address[1]}: cannot listen: {why}") from None
    return sock


class Sink:
    """The platform command socket (connected UDP): a refused or failed send is counted, never fatal."""

    def __init__(self, address: tuple[str, int] | None, fmt: str, names: Sequence[str]) -> None:
        if fmt not in commands.SINK_FORMATS:
            raise WashbenchError(f"--sink-format: expected one of {', '.join(commands.SINK_FORMATS)}, got {fmt!r}")
        self.address, self.fmt, self.names = address, fmt, tuple(names)
        self.sent = 0
        self.errors = 0
        self.seq = 0
        self._sock: socket.socket | None = None
        if address is not None:
            sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            try:
                sock.connect(address)
            except OSError as exc:
                sock.close()
                raise WashbenchError(f"--sink {address[0]}:{address[1]}: {exc.strerror or exc}") from None
            sock.setblocking(False)
            self._sock = sock

    def send(self, t_s: float, flags: int, rows: np.ndarray) -> None:
        seq = self.seq
        self.seq += 1
        if self._sock is None:
            return
        if self.fmt == "binary":
            data = commands.encode_binary(seq, t_s, flags, rows)
        else:
            data = commands.encode_json(seq, t_s, flags, rows, self.names)
        try:
            self._sock.send(data)
            self.sent += 1
        except OSError:  # ECONNREFUSED (nobody listens: the ICMP answer of an earlier send), a full buffer, ...
            self.errors += 1

    def close(self) -> None:
        if self._sock is not None:
            self._sock.close()
