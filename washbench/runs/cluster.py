"""The Dask back end: the same work as the local pool, shipped as tasks to an existing dask.distributed cluster.

``--dask ADDRESS`` (``suite``, ``sweep``, ``tune``) connects to a running scheduler (``tcp://host:8786``, or the
address a ``LocalCluster`` prints). Each task calls the same function the local run calls, so the results are the
same bit for bit. dask is optional: ``pip install 'washbench[cluster]'``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from typing import Any

from washbench.errors import WashbenchError

_CLIENTS: dict[str, Any] = {}


def client(address: str) -> Any:
    """A dask.distributed Client connected to ``address`` (one per address and process)."""
    try:
        from dask.distributed import Client
    except ImportError:
        raise WashbenchError("--dask needs dask.distributed: pip install 'washbench[cluster]'") from None
    if address not in _CLIENTS:
        _probe(address)
        try:
            _CLIENTS[address] = Client(address, timeout=f"{CONNECT_TIMEOUT_S:g}s", set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise WashbenchError(
                f"--dask {address}: something accepted the connection but did not answer as a Dask scheduler within "
                f"{CONNECT_TIMEOUT_S:g} s ({type(exc).__name__})"
            ) from None
        except Exception as exc:  # distributed raises ValueError, TypeError ... for addresses it cannot use
            raise WashbenchError(f"--dask {address}: not a usable scheduler address ({exc})") from None
    return _CLIENTS[address]


#: How long to wait for the scheduler to answer (s).
CONNECT_TIMEOUT_S = 5.0
#: How long to wait for a scheduler's handshake, which it sends as soon as it accepts a connection (s).
HANDSHAKE_TIMEOUT_S = 2.0


def _probe(address: str) -> None:
    """Refuse at once an address that is malformed or where nothing listens (one line saying which)."""
    import socket
    from urllib.parse import urlsplit

    url = urlsplit(address if "://" in address else f"tcp://{address}")
    try:
        host, port = url.hostname, url.port
    except ValueError:
        host, port = None, None
    if url.scheme not in ("tcp", "tls", "ws", "wss") or not host or port is None:
        raise WashbenchError(f"--dask {address}: not a scheduler address (expected tcp://HOST:PORT)")
    try:
        sock = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S)
    except OSError as exc:
        raise WashbenchError(f"--dask {address}: nothing answered at {host}:{port} ({exc.strerror or exc})") from None
    with sock:
        if url.scheme != "tcp":
            return
        try:  # a Dask scheduler sends its handshake as soon as a connection is accepted
            sock.settimeout(HANDSHAKE_TIMEOUT_S)
            first = sock.recv(64)
        except TimeoutError:
            first = None
        except OSError as exc:
            first = f"{exc.strerror or exc}".encode()
    if not first:
        what = "closed the connection at once" if first == b"" else f"sent nothing within {HANDSHAKE_TIMEOUT_S:g} s"
        raise WashbenchError(f"--dask {address}: something accepted the connection but {what}: not a Dask scheduler")
    if first[:4] in (b"HTTP", b"SSH-", b"220 ", b"<!DO", b"<htm"):
        shown = first[:24].decode("ascii", "backslashreplace").strip()
        raise WashbenchError(f"--dask {address}: the server answered {shown!r}: not a Dask scheduler")


def dask_map(address: str, fn: Callable[..., Any], args: Sequence[tuple[Any, ...]]) -> Iterator[Any]:
    """``fn(*a)`` for every ``a`` in ``args`` on the cluster (all submitted at once); results in ``args`` order."""
    c = client(address)
    futures = [c.submit(fn, *a, pure=False) for a in args]
    for fut in futures:
        yield fut.result()


def dask_gather(address: str, fn: Callable[..., Any], shared: Any, args: Sequence[tuple[Any, ...]]) -> list[Any]:
    """``fn(shared, *a)`` for every ``a`` on the cluster, ``shared`` sent to every worker once; results in order."""
    c = client(address)
    # Scattered once, to one worker; the others fetch it from there when their first task needs it. (With
    # broadcast=True the replication raced with the tasks under load: "failed to acquire keys", "lost dependencies".)
    [big] = c.scatter([shared], broadcast=False, hash=False)
    futures = [c.submit(fn, big, *a, pure=False) for a in args]
    return c.gather(futures)


def close_all() -> None:
    """Close every client this process opened (the cluster itself keeps running)."""
    for c in _CLIENTS.values():
        c.close()
    _CLIENTS.clear()
