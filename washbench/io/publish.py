"""Where results go: output folders checked before any work, result paths proven inside ``--out``, and
folders published whole, replacing only a previous result that washbench itself wrote.

A result folder is built under a hidden temporary name beside its final place
(``.NAME.partial-PID``), then renamed into place (:func:`publish_dir`). What already stands at the final
place is replaced only if it is a washbench result of the same thing, recognised by its marker file
(``run.json`` for ``washbench run``, whose ``aircraft`` and ``manoeuvre`` must match); anything else is
left alone and the run fails with one line. Leftovers of an interrupted run (``.NAME.partial-PID``,
``.NAME.old-PID``) are removed by :func:`clean_partials` at the next run into the same place.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import tempfile
from collections.abc import Mapping
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.io.names import identifier_problem

_LEFTOVER = re.compile(r"^\.(?P<name>.+)\.(?:partial|old)-(?P<pid>\d+)$")


def _why(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def prepare_output_dir(path: str | Path) -> Path:
    """Create folder ``path`` if missing and prove it can be written; return it.

    Raises WashbenchError (one line) if it is a file, lies under a file, or cannot be written (read-only
    place, no permission, full disk): checked before any flying or computing, so nothing is lost later.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise WashbenchError(located(path, "the output path exists and is not a folder"))
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise WashbenchError(located(path, "cannot create the output folder: a part of the path is a file")) from None
    except NotADirectoryError:
        raise WashbenchError(located(path, "cannot create the output folder: a part of the path is a file")) from None
    except OSError as exc:
        raise WashbenchError(located(path, f"cannot create the output folder: {_why(exc)}")) from None
    try:
        fd, probe = tempfile.mkstemp(prefix=".washbench-probe-", dir=path)
    except OSError as exc:
        raise WashbenchError(located(path, f"cannot write into the output folder: {_why(exc)}")) from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)
    return path


def prepare_output_file(path: str | Path) -> Path:
    """Check that file ``path`` can be written (its folder is created and probed; it is not a folder)."""
    path = Path(path)
    if path.is_dir():
        raise WashbenchError(located(path, "the output path is a folder, not a file"))
    prepare_output_dir(path.parent if str(path.parent) else Path("."))
    return path


def inside(root: str | Path, path: str | Path) -> bool:
    """Whether ``path`` (resolved, symlinks followed) lies strictly inside folder ``root`` (resolved)."""
    root_r = Path(root).resolve()
    path_r = Path(path).resolve()
    return path_r != root_r and path_r.is_relative_to(root_r)


def result_path(out_root: str | Path, *parts: str) -> Path:
    """``out_root / part / ...`` for identifier parts, proven to lie inside ``out_root``.

    Raises WashbenchError if a part is not a plain identifier (:mod:`washbench.io.names`) or the path
    leaves ``out_root`` (through a symbolic link, say).
    """
    out_root = Path(out_root)
    for part in parts:
        problem = identifier_problem(part)
        if problem is not None:
            raise WashbenchError(located(out_root, f"refusing a result path part: {problem}"))
    path = out_root.joinpath(*parts)
    if not inside(out_root, path):
        raise WashbenchError(located(path, f"refusing to write outside the output folder {out_root}"))
    return path


def read_marker(folder: Path, marker: str) -> dict[str, object] | None:
    """The JSON object in ``folder/marker``, or None if the folder or the file is missing or not such an object."""
    try:
        if folder.is_symlink() or not folder.is_dir():
            return None
        doc = json.loads((folder / marker).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) else None


def is_washbench_result(folder: str | Path, marker: str, expect: Mapping[str, object], nested: bool = False) -> bool:
    """Whether ``folder`` holds a result washbench wrote: ``marker`` is a JSON object with the ``expect`` items.

    With ``nested``, a folder of such results (each sub-folder one, e.g. the runs of a JSBSim script) counts too.
    """
    folder = Path(folder)
    doc = read_marker(folder, marker)
    if doc is not None and all(doc.get(k) == v for k, v in expect.items()):
        return True
    if not nested or folder.is_symlink() or not folder.is_dir():
        return False
    subs = [e for e in folder.iterdir() if not is_leftover(e.name)]
    return bool(subs) and all(is_washbench_result(e, marker, expect) for e in subs)


def check_replaceable(final: str | Path, marker: str, expect: Mapping[str, object], nested: bool = False) -> None:
    """Raise WashbenchError unless ``final`` is absent or a washbench result that may be replaced."""
    final = Path(final)
    if (final.exists() or final.is_symlink()) and not is_washbench_result(final, marker, expect, nested):
        what = ", ".join(f"{k} {v}" for k, v in expect.items())
        problem = f"exists and is not a washbench result of {what} (no matching {marker}): not replaced"
        raise WashbenchError(located(final, f"{problem}; move it away or choose another --out"))


def partial_dir(final: str | Path) -> Path:
    """Create and return an empty hidden folder ``.NAME.partial-PID`` beside ``final`` to build a result in."""
    final = Path(final)
    partial = final.with_name(f".{final.name}.partial-{os.getpid()}")
    shutil.rmtree(partial, ignore_errors=True)
    try:
        partial.mkdir(parents=True)
    except OSError as exc:
        raise WashbenchError(located(partial.parent, f"cannot create a result folder: {_why(exc)}")) from None
    return partial


def publish_dir(
    partial: str | Path, final: str | Path, marker: str, expect: Mapping[str, object], nested: bool = False
) -> None:
    """Rename the finished folder ``partial`` to ``final``, replacing a previous washbench result there.

    What stands at ``final`` is replaced only if :func:`is_washbench_result` recognises it; anything else
    raises WashbenchError and is left untouched (``partial`` is then removed by the caller).
    """
    partial, final = Path(partial), Path(final)
    check_replaceable(final, marker, expect, nested)
    old = final.with_name(f".{final.name}.old-{os.getpid()}")
    try:
        if final.exists():
            os.replace(final, old)
        os.replace(partial, final)
    except OSError as exc:
        raise WashbenchError(located(final, f"cannot publish the result folder: {_why(exc)}")) from None
    shutil.rmtree(old, ignore_errors=True)


def is_leftover(name: str) -> bool:
    """Whether ``name`` is a leftover of an interrupted run (``.NAME.partial-PID`` or ``.NAME.old-PID``)."""
    return _LEFTOVER.match(name) is not None


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def clean_partials(folder: str | Path, *, only_dead: bool = True) -> list[Path]:
    """Remove leftovers of interrupted runs in ``folder`` (``.NAME.partial-PID``, ``.NAME.old-PID``).

    With ``only_dead`` (the default) only those of processes no longer running; without it all of them
    (for a caller that holds the folder's :func:`washbench.io.lock.output_lock`). Returns what was removed.
    """
    folder = Path(folder)
    removed: list[Path] = []
    try:
        entries = list(folder.iterdir())
    except OSError:
        return removed
    for entry in entries:
        match = _LEFTOVER.match(entry.name)
        if match is None or entry.is_symlink() or not entry.is_dir():
            continue
        if only_dead and _pid_alive(int(match.group("pid"))):
            continue
        shutil.rmtree(entry, ignore_errors=True)
        removed.append(entry)
    return removed


def remove_if_empty(folder: str | Path) -> None:
    """Remove ``folder`` if it exists and is empty (e.g. an ``OUT/<aircraft>/`` left by a failed run)."""
    with contextlib.suppress(OSError):
        Path(folder).rmdir()
