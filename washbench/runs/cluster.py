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
        try:
            _CLIENTS[address] = Client(address, timeout="10s", set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise WashbenchError(f"--dask {address}: cannot connect to the scheduler ({exc})") from None
    return _CLIENTS[address]


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
