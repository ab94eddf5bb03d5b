"""numba's on-disk cache for the compiled washout kernel: where it lives, when it is stale, and saying so.

- Where: numba's own default (``__pycache__`` next to the sources) when the installed package folder is
  writable; otherwise (a read-only site-packages) a writable user cache folder,
  ``platformdirs.user_cache_dir("washbench")/numba``, set through ``NUMBA_CACHE_DIR`` before numba reads its
  configuration. A ``NUMBA_CACHE_DIR`` the user set is left alone.
- Stale: numba keys a cached function on its own source file only: when a jitted function inlines jitted
  helpers from another file and that file changes, the stale machine code would still be loaded. Each module
  that compiles in helpers from elsewhere calls :func:`drop_stale_cache` at import, before anything is compiled.
- Compiled at install: building the package compiles every kernel into its cache
  (:mod:`washbench.numerics.precompile`, run by ``setup.py``). What follows is for where that did not happen or
  does not apply (another CPU or numba, a read-only install, ``WASHBENCH_NO_PRECOMPILE``).
- Saying so: the first command after an install or upgrade that needs a compiled function compiles it (the
  washout kernel 13-20 s of CPU; the flight step, perception and metric sums, the recording's thinning a few
  seconds each: a first ``washbench run`` took 22-23 s of CPU, 25-29 s on two idle cores and 60-80 s on a busy
  machine, measured on the two-core development machine).
  :func:`announce_compile` is called before every compiled call a command makes from Python (it costs a flag test
  once it has looked) and prints one line to stderr, once per command, when the cache holds nothing for a function
  about to run: the suite's process server looks at every kernel its workers will run before it forks them
  (:mod:`washbench.runs.preload`), so a suite says it once, not once per worker.
"""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent.parent
_announced = False


def _writable(folder: Path) -> bool:
    cache = folder / "__pycache__"
    return os.access(cache if cache.is_dir() else folder, os.W_OK)


def configure_cache() -> None:
    """Send numba's cache to the user cache folder when the package's own folders are not writable.

    Must run before numba is imported (``washbench.cueing`` calls it first thing); if numba is already
    imported, its configuration is updated in place (it is read when a jitted function is decorated).
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    jitted = ("numerics", "flight", "cueing", "platform", "perception", "analysis")
    if all(_writable(_PACKAGE_DIR / sub) for sub in jitted):
        return
    import platformdirs

    folder = str(Path(platformdirs.user_cache_dir("washbench")) / "numba")
    os.environ["NUMBA_CACHE_DIR"] = folder
    numba = sys.modules.get("numba")
    if numba is not None:
        numba.config.CACHE_DIR = folder


def _any_function() -> None:
    """A function to ask numba's cache locators with (see :func:`_cache_dir`)."""


def _cache_dir(module_file: Path) -> Path:
    """The folder numba caches ``module_file``'s functions in (numba's own choice of locator)."""
    try:
        from numba.core.caching import FunctionCache

        for cls in FunctionCache._impl_class._locator_classes:
            # a locator reads its function's first line number (a disambiguator, not part of the folder): any
            # function serves (``None`` raised AttributeError in numba 0.68, which sent every stamp to __pycache__)
            locator = cls.from_function(_any_function, str(module_file))
            if locator is not None:
                return Path(locator.get_cache_path())
    except (ImportError, AttributeError, TypeError):  # pragma: no cover - another numba's internals
        pass
    return module_file.parent / "__pycache__"


def drop_stale_cache(module_file: str, deps: list[Path]) -> None:
    """Delete ``module_file``'s numba cache files if it or any of ``deps`` changed since they were written.

    A hash of the sources is kept next to the cache files in ``<module>.deps.sha256``. Errors (a cache folder
    that cannot be written) are ignored: numba does not cache there either.
    """
    here = Path(module_file).resolve()
    digest = hashlib.sha256(b"".join(p.read_bytes() for p in [here, *deps])).hexdigest()
    cache_dir = _cache_dir(here)
    stamp = cache_dir / f"{here.stem}.deps.sha256"
    try:
        if stamp.is_file() and stamp.read_text() == digest:
            return
        cache_dir.mkdir(parents=True, exist_ok=True)
        for p in cache_dir.glob(f"{here.stem}.*.nb[ic]"):
            p.unlink(missing_ok=True)
        stamp.write_text(digest)
    except OSError:
        pass


def _needs_compile(dispatcher: object) -> tuple[bool, str | None]:
    """(compiles now, the cache folder) for a jitted function: no signature in memory and no index file on disk."""
    if getattr(dispatcher, "signatures", None):
        return False, None
    cache = getattr(dispatcher, "_cache", None)
    index = getattr(getattr(cache, "_cache_file", None), "_index_path", None)
    if index is None or not os.path.exists(index):
        return True, str(Path(index).parent) if index else None
    return False, None


def _cache_place(folder: str | None) -> str:
    """Where the kernels' cache files go, for the announcement: ``NUMBA_CACHE_DIR`` when set; numba's default, the
    ``__pycache__`` folder next to each source, named as the package folder's; else the folder itself."""
    if folder is None:
        return "memory only"
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.environ["NUMBA_CACHE_DIR"]
    if Path(folder).is_relative_to(_PACKAGE_DIR):
        return f"the __pycache__ folders under {_PACKAGE_DIR}"
    return folder


def cache_place() -> str:
    """Where the package's kernels are cached, in words (:func:`_cache_place` of the package folder)."""
    return _cache_place(str(_PACKAGE_DIR))


def announce_compile(*dispatchers: object) -> None:
    """Print one line to stderr, once per process, if any of these jitted functions is about to be compiled.

    A function with no compiled signature in memory and no index file in its on-disk cache will compile
    now; one whose cache exists is loaded in well under a second and is not announced. Forked workers inherit
    the "said" state of the process they fork from.
    """
    global _announced
    if _announced:
        return
    for d in dispatchers:
        compiles, folder = _needs_compile(d)
        if compiles:
            _announced = True
            print(
                "washbench: compiling the numerical kernels for this machine (not compiled when washbench was "
                "installed here: about 30 s on two idle cores, a minute or more on a busy machine; kept in "
                f"{_cache_place(folder)} for later commands; `python -m washbench.numerics.precompile` compiles them "
                "all)",
                file=sys.stderr,
                flush=True,
            )
            return
