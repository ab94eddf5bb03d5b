"""Atomic file output: a reader never sees a half-written result file.

Each writer writes to a temporary file in the destination folder and renames it over
the destination (``os.replace`` is atomic on POSIX within one file system). A failure of the
file system (full disk, read-only place, a folder in the way) is a one-line WashbenchError
naming the destination; the temporary file is removed and the destination left untouched.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from washbench.errors import WashbenchError, located


@contextlib.contextmanager
def atomic_path(dest: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``dest``; on success rename it to ``dest``.

    On an exception the temporary file is removed and ``dest`` is left untouched; an OSError (from the
    file system, in here or in the caller's writing) becomes a WashbenchError naming ``dest``.
    """
    dest = Path(dest)
    try:
        dest.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=".tmp", dir=dest.parent)
    except OSError as exc:
        raise WashbenchError(located(dest, f"cannot write: {exc.strerror or exc}")) from None
    os.close(fd)
    tmp_path = Path(tmp)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp_path, 0o666 & ~umask)  # mkstemp makes 0600; give results the usual permissions
    try:
        try:
            yield tmp_path
            os.replace(tmp_path, dest)
        except OSError as exc:
            raise WashbenchError(located(dest, f"cannot write: {exc.strerror or exc}")) from None
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()


def write_text_atomic(dest: str | Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``dest`` atomically."""
    with atomic_path(dest) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_bytes_atomic(dest: str | Path, data: bytes) -> None:
    """Write ``data`` to ``dest`` atomically."""
    with atomic_path(dest) as tmp:
        tmp.write_bytes(data)
