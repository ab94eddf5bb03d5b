"""Keep numba's on-disk cache honest across modules.

numba keys a cached function on its own source file only: when a jitted function inlines jitted helpers
from another file and that file changes, the stale machine code would still be loaded. Each module that
compiles in helpers from elsewhere calls :func:`drop_stale_cache` at import, before anything is compiled.
"""

from __future__ import annotations

import hashlib
from pathlib import Path


def drop_stale_cache(module_file: str, deps: list[Path]) -> None:
    """Delete ``module_file``'s numba cache files if it or any of ``deps`` changed since they were written.

    A hash of the sources is kept in ``__pycache__/<module>.deps.sha256``. Errors (read-only install) are
    ignored: numba does not cache there either.
    """
    here = Path(module_file).resolve()
    digest = hashlib.sha256(b"".join(p.read_bytes() for p in [here, *deps])).hexdigest()
    cache_dir = here.parent / "__pycache__"
    stamp = cache_dir / f"{here.stem}.deps.sha256"
    try:
        if stamp.is_file() and stamp.read_text() == digest:
            return
        cache_dir.mkdir(exist_ok=True)
        for p in cache_dir.glob(f"{here.stem}.*.nb[ic]"):
            p.unlink(missing_ok=True)
        stamp.write_text(digest)
    except OSError:
        pass
