"""Where results may go, checked before any work: output folders that can be written, result paths proven inside
``--out``, and whether what stands where a result goes is a washbench result it may replace.

These are checks only. Publishing, the one way every command puts its results in place (built in a hidden
stage, then swapped in whole), is :mod:`washbench.io.outfolder`'s. What stands where a result goes is replaced
only if it is a washbench result of the same thing, recognised by its marker file (``run.json`` for
``washbench run``, whose ``aircraft`` and ``manoeuvre`` must match: :func:`check_replaceable`); anything else is
left alone and the command fails with one line.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.io.names import identifier_problem
from washbench.io.result_files import PROBE_PREFIX, publication_pid


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
        fd, probe = tempfile.mkstemp(prefix=PROBE_PREFIX, dir=path)
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
    subs = [e for e in folder.iterdir() if publication_pid(e.name) is None]  # not a publication's leftover
    return bool(subs) and all(is_washbench_result(e, marker, expect) for e in subs)


def check_replaceable(final: str | Path, marker: str, expect: Mapping[str, object], nested: bool = False) -> None:
    """Raise WashbenchError unless ``final`` is absent or a washbench result that may be replaced."""
    final = Path(final)
    if (final.exists() or final.is_symlink()) and not is_washbench_result(final, marker, expect, nested):
        what = ", ".join(f"{k} {v}" for k, v in expect.items())
        problem = f"exists and is not a washbench result of {what} (no matching {marker}): not replaced"
        raise WashbenchError(located(final, f"{problem}; move it away or choose another --out"))
