"""Installed entry points, read one distribution at a time: another package's broken metadata is passed over.

``importlib.metadata.entry_points(group=...)`` parses the ``entry_points.txt`` of every installed distribution, so
one unrelated package whose file is garbage (a line without ``=``: ``TypeError: Pair.__new__() missing 1 required
positional argument``; bytes that are not UTF-8) made every washbench command, ``--help`` included, end in a
traceback. :func:`entry_points` reads each distribution's entry points on its own; one that cannot be read is
named once on stderr and passed over (it cannot hold a washbench plugin anyone could load anyway).

pydantic reads the entry points of every distribution too (its own plugins', group ``pydantic``) when it builds its
first model, wherever that happens: :func:`read_pydantic_plugins`, called as the command starts, has it read them
then, once, and passes a failure over the same way (pydantic then builds its models without plugins).
"""

from __future__ import annotations

import importlib.metadata
import re
import sys

from washbench.errors import printable

_WARNED: set[str] = set()


def _name(dist: importlib.metadata.Distribution) -> str:
    """A distribution's name (its metadata's ``Name``; its folder where that cannot be read)."""
    try:
        name = dist.metadata["Name"]
    except Exception:  # broken metadata: named by its folder
        name = None
    return str(name) if name else str(getattr(dist, "_path", "an installed distribution"))


def _all() -> tuple[importlib.metadata.EntryPoint, ...]:
    """Every readable entry point of every installed distribution (the first of each name on ``sys.path``, as
    importlib.metadata does)."""
    out: list[importlib.metadata.EntryPoint] = []
    seen: set[str] = set()
    for dist in importlib.metadata.distributions():
        name = _name(dist)
        key = re.sub(r"[-_.]+", "-", name).lower()
        if key in seen:
            continue
        seen.add(key)
        try:
            out.extend(dist.entry_points)
        except Exception as exc:  # another package's file: any error there is passed over, said once
            if key not in _WARNED:
                _WARNED.add(key)
                text = " ".join(str(exc).split())
                print(f"washbench: warning: the installed distribution {printable(name)}: its entry points cannot "
                      f"be read ({type(exc).__name__}: {printable(text)[:120]}); passed over", file=sys.stderr)
    return tuple(out)


def entry_points(group: str) -> tuple[importlib.metadata.EntryPoint, ...]:
    """The installed entry points of ``group`` (:func:`_all`: a distribution whose entry points cannot be read is
    passed over with one warning)."""
    return tuple(ep for ep in _all() if ep.group == group)


def read_pydantic_plugins() -> None:
    """Have pydantic read its plugins' entry points now (what it does when it builds its first model; it keeps what
    it read): if another distribution's entry points cannot be read, they are named on stderr (:func:`_all`) and
    pydantic goes on without plugins (it marks them read before reading), instead of a traceback from the first
    model anywhere."""
    try:
        from pydantic.plugin import _loader  # pydantic's own reader: the cache its models use
    except ImportError:  # (another pydantic: its models read the entry points themselves)
        return
    try:
        _loader.get_plugins()
    except Exception:  # another package's file
        _all()


__all__ = ["entry_points", "read_pydantic_plugins"]
