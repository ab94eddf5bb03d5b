"""The one way washbench publishes results: built in a hidden stage, then swapped in whole, under the lock.

Every command that writes a result folder or a set of them publishes it through this module (a single file a
command is asked for, such as ``signal``'s CSV or ``schema --out``, is written atomically by
:mod:`washbench.io.atomic`), in one of two forms:

* :func:`result_set`, a whole ``--out`` owned by one command (``cue``, ``fly``, ``sweep``, ``tune``, ``omct``;
  ``examples`` and ``report`` use the same steps on a folder of the user's and on a result folder):

  1. the lock (:func:`washbench.io.lock.output_lock`: created with ``O_CREAT|O_EXCL|O_NOFOLLOW``, a link refused);
  2. :func:`recover`: what a killed command left is removed (hidden stage and old folders, ``.*.tmp`` files,
     legacy ``.NAME.partial-PID`` folders), or, if it was killed in the middle of publishing, the publication
     finished from its journal, so the folder holds one whole result set, never a mix;
  3. :func:`owned_entries`: everything in the folder must be listed in the manifest ``.washbench.json`` a
     previous run of the same command wrote; anything else (a user's file of the same name as a result, a
     symbolic link) is refused with one line before any work, and left untouched;
  4. :func:`staged`: the command writes into a fresh hidden stage folder ``OUT/.washbench-stage-PID`` (inside
     ``--out``, so no link in ``--out`` is ever followed: every file is created inside a folder washbench just
     made), and then
  5. :func:`swap_in`: with SIGINT and SIGTERM held back, a journal is written, the previous entries are renamed
     into a hidden old folder, the new ones renamed into place, the journal removed, the old folder deleted
     (``shutil.rmtree`` never follows links). A signal during the swap takes effect once the set is whole.

* :func:`result_entry`, one named entry in a folder that holds other results too: ``washbench run``'s
  ``OUT/<aircraft>/<manoeuvre>`` in an ``OUT`` that gathers many runs, and each run of a suite (whose worker
  processes publish side by side into the same ``<aircraft>/`` folder). The same steps, for one entry: what
  stands at its place must be a washbench result of the same thing (else one line, before any work); what
  interrupted publications left in the shared folder is recovered by :func:`recover_shared` (only those of
  processes no longer running, since several may publish there at once: a journal rolled forward, stage and
  old folders removed); the entry is built in ``<aircraft>/.washbench-stage-PID/<manoeuvre>`` and swapped in by
  the same journalled :func:`swap_in`, replacing only the previous entry of that name.

A ``washbench suite`` is a result set too (:func:`staged` under the lock, after :func:`recover`), marked by its
``suite.json`` rather than a manifest; its runs are result entries inside its stage. The hidden names are
spelt in :mod:`washbench.io.result_files`.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.io.interrupts import signals_held, uninterrupted  # (defined there; kept importable from here)
from washbench.io.lock import output_lock
from washbench.io.owners import announce, folder_owner, read_manifest, refuse_nested, refuse_other_owner
from washbench.io.result_files import (
    JOURNAL_PREFIX,
    LOCK_NAME,
    MANIFEST,
    OLD_PREFIX,
    PROBE_PREFIX,
    STAGE_PREFIX,
    is_legacy_leftover,
    is_own_hidden,
    publication_pid,
)

_TMP = re.compile(r"^\..+\.tmp$")

__all__ = [
    "JOURNAL_PREFIX", "MANIFEST", "OLD_PREFIX", "STAGE_PREFIX", "check_out_path", "discard_stage", "folder_owner",
    "is_own_hidden", "make_stage", "owned_entries", "recover", "recover_shared", "refuse_other_owner",
    "replace_entries", "result_entry", "result_set", "signals_held", "staged", "swap_in", "uninterrupted",
    "unstaged_error",
]  # fmt: skip


def _why(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def remove_tree(path: Path) -> None:
    """Remove a file, link or folder (a link is removed itself, never followed)."""
    with contextlib.suppress(FileNotFoundError):
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink()


def recover(out_dir: Path, *, only_washbench: bool = False) -> None:
    """Finish or remove what an interrupted command left in ``out_dir`` (call it holding the folder's lock).

    A journal ``.washbench-swap-PID`` means the command was killed while publishing: its publication is
    finished (the stage was complete). Every other leftover (stage, old folders, ``.*.tmp``, legacy
    ``.NAME.partial-PID``/``.NAME.old-PID``) is removed; so are ``.*.tmp`` files one level down.
    ``only_washbench`` (a folder of the user's, ``washbench examples``): only ``.washbench-*`` leftovers.
    One level down only in the folders washbench wrote (listed in the manifest, or in a suite's ``suite.json``):
    a folder of the user's inside ``--out`` is refused afterwards, never cleaned of the user's ``.*.tmp`` files.
    """
    for journal in sorted(out_dir.glob(JOURNAL_PREFIX + "*")):
        _roll_forward(out_dir, journal)
    listed = _listed_folders(out_dir)
    for entry in list(out_dir.iterdir()):
        name = entry.name
        if only_washbench:
            if name.startswith((STAGE_PREFIX, OLD_PREFIX, PROBE_PREFIX, ".suite.partial-", ".suite.old-")):
                remove_tree(entry)
            continue
        if name.startswith((STAGE_PREFIX, OLD_PREFIX, PROBE_PREFIX)) or is_legacy_leftover(name) or _TMP.match(name):
            remove_tree(entry)
        elif name in listed and entry.is_dir() and not entry.is_symlink():
            for sub in list(entry.iterdir()):
                if _TMP.match(sub.name) or is_legacy_leftover(sub.name):
                    remove_tree(sub)


def _listed_folders(out_dir: Path) -> set[str]:
    """Top-level names washbench wrote into ``out_dir``: its manifest's, or a suite's (``suite.json`` entries)."""
    manifest = read_manifest(out_dir)
    if manifest is not None:
        return set(manifest[1])
    suite = out_dir / "suite.json"
    if suite.is_symlink() or not suite.is_file():
        return set()
    try:
        doc = json.loads(suite.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return set()
    entries = doc.get("entries") if isinstance(doc, dict) and doc.get("washbench") == "suite" else None
    return {n for n in entries if isinstance(n, str) and "/" not in n} if isinstance(entries, list) else set()


def _roll_forward(out_dir: Path, journal: Path) -> None:
    try:
        doc = json.loads(journal.read_text(encoding="utf-8"))
        previous, new = list(doc["previous"]), list(doc["new"])
        stage, old = out_dir / str(doc["stage"]), out_dir / str(doc["old"])
    except (OSError, ValueError, KeyError, TypeError):
        remove_tree(journal)
        return
    plain = all("/" not in p.name and p.parent == out_dir for p in (stage, old))
    if not (plain and stage.name.startswith((STAGE_PREFIX, ".suite.partial-")) and old.name.startswith(OLD_PREFIX)):
        remove_tree(journal)  # not a journal washbench wrote: nothing is moved by it
        return
    safe = [n for n in (*previous, *new) if isinstance(n, str) and "/" not in n and n not in ("", ".", "..")]
    old.mkdir(exist_ok=True)

    def present(path: Path) -> bool:
        return path.exists() or path.is_symlink()

    for name in previous:  # an old entry still in place goes, unless the new one already replaced it
        if name in safe and present(out_dir / name) and (name not in new or present(stage / name)):
            os.replace(out_dir / name, old / name)
    for name in new:
        if name in safe and present(stage / name):
            os.replace(stage / name, out_dir / name)
    remove_tree(journal)
    remove_tree(old)
    remove_tree(stage)


def owned_entries(out_dir: Path, command: str, adopt: Sequence[str] = ()) -> list[Path]:
    """The entries of ``out_dir`` a new result set of ``command`` replaces (those its manifest lists).

    Raises WashbenchError (one line, naming the entry) for anything else: a file or folder washbench did
    not write, another command's result set, or a symbolic link (never followed, never replaced). ``adopt``:
    names the command itself is writing there for the new set (``washbench live``'s saved input), neither
    refused nor replaced.
    """
    refuse_other_owner(out_dir, command)
    manifest = read_manifest(out_dir)
    listed: set[str] = set(manifest[1]) if manifest is not None else set()
    found: list[Path] = []
    for entry in sorted(out_dir.iterdir()):
        if is_own_hidden(entry.name) and (manifest is not None or entry.name == LOCK_NAME):
            continue  # in a folder without a manifest, a hidden file is the user's unless it is the lock
        if entry.name in adopt and entry.is_file() and not entry.is_symlink():
            continue
        if entry.is_symlink():
            raise WashbenchError(located(entry, "is a symbolic link: washbench never follows or replaces a link in "
                                         "its output folder; remove it or choose another --out"))  # fmt: skip
        if entry.name not in listed:
            raise WashbenchError(located(entry, "washbench did not write this (not listed in .washbench.json): "
                                         "not replaced; move it away or choose an empty or new --out"))  # fmt: skip
        found.append(entry)
    return found


def discard_stage(stage: Path) -> None:
    """Remove ``stage`` unless a journal says its publication is under way (then :func:`recover` finishes it)."""
    if not (stage.parent / f"{JOURNAL_PREFIX}{os.getpid()}").exists():
        remove_tree(stage)


def make_stage(out_dir: Path) -> Path:
    """A new empty hidden folder inside ``out_dir`` to build a result set in."""
    stage = out_dir / f"{STAGE_PREFIX}{os.getpid()}"
    remove_tree(stage)
    try:
        stage.mkdir()
    except OSError as exc:
        raise WashbenchError(located(out_dir, f"cannot create a folder to build the results in: {_why(exc)}")) from None
    return stage


def write_manifest(stage: Path, command: str, extra: Sequence[str] = ()) -> None:
    """``stage/.washbench.json``: the command and every top-level name of the set (``extra`` too)."""
    names = sorted({e.name for e in stage.iterdir() if not is_own_hidden(e.name)} | set(extra))
    text = json.dumps({"washbench": 1, "command": command, "entries": names}, indent=2) + "\n"
    try:
        (stage / MANIFEST).write_text(text, encoding="utf-8")
    except OSError as exc:
        raise WashbenchError(located(stage.parent / MANIFEST, f"cannot write: {_why(exc)}")) from None


def swap_in(stage: Path, out_dir: Path, previous: Sequence[Path]) -> None:
    """Replace the ``previous`` entries of ``out_dir`` by everything in ``stage``, as one step.

    Journalled (a kill in the middle is finished by the next :func:`recover`) and with SIGINT/SIGTERM held.
    """
    pid = os.getpid()
    old = out_dir / f"{OLD_PREFIX}{pid}"
    journal = out_dir / f"{JOURNAL_PREFIX}{pid}"
    new = sorted(e.name for e in stage.iterdir())
    doc = {"stage": stage.name, "old": old.name, "previous": [p.name for p in previous], "new": new}
    with signals_held():
        try:
            tmp = journal.with_name(f"{journal.name}.tmp")
            tmp.write_text(json.dumps(doc), encoding="utf-8")
            os.replace(tmp, journal)
            old.mkdir(exist_ok=True)
            for entry in previous:
                if entry.exists() or entry.is_symlink():
                    os.replace(entry, old / entry.name)
            for name in new:
                os.replace(stage / name, out_dir / name)
            journal.unlink()
        except OSError as exc:
            raise WashbenchError(located(out_dir, f"cannot publish the results: {_why(exc)}")) from None
        finally:
            if not journal.exists():
                remove_tree(old)
                remove_tree(stage)


def check_out_path(out: str | Path) -> Path:
    """``--out`` as a Path; an empty string is refused (it would mean the current folder)."""
    if str(out) == "":
        raise WashbenchError("--out: an empty path; name a folder (use . for the current folder)")
    return Path(out)


@contextlib.contextmanager
def staged(
    out_dir: Path, previous: Sequence[Path], before_swap: Callable[[Path], None] | None = None
) -> Iterator[Path]:
    """Yield a fresh stage folder inside ``out_dir`` (:func:`make_stage`); once the body is done, replace the
    ``previous`` entries of ``out_dir`` by everything in the stage (:func:`swap_in`: journalled, signals held).

    ``before_swap(stage)`` runs just before the swap (a manifest written, a last check). On an exception (a signal
    included) nothing is published and the stage is removed; a WashbenchError then names its files where they were
    going (:func:`unstaged_error`), not in the hidden stage. Call it holding the lock of ``out_dir`` (or, for a
    result entry, of the output folder above it).
    """
    stage = make_stage(out_dir)
    try:
        yield stage
        if before_swap is not None:
            before_swap(stage)
        swap_in(stage, out_dir, previous)
    except WashbenchError as exc:  # name the files where they were going, not the hidden stage
        raise unstaged_error(exc, stage, out_dir) from None
    finally:
        discard_stage(stage)


@contextlib.contextmanager
def result_set(out: str | Path, command: str, adopt: Sequence[str] = ()) -> Iterator[Path]:
    """Own ``out`` for one result set of ``command``; yield the stage folder to write the set into.

    Refuse an ``out`` inside other results (:func:`washbench.io.owners.refuse_nested`), lock, recover, refuse
    foreign entries (before the caller does any work), say that earlier results of ``command`` are replaced
    (:mod:`washbench.io.owners`), build in the stage, then publish the whole set at once with its manifest
    (:func:`staged`). On an exception (a signal included) nothing is
    published and the previous set stays as it was; a folder created here is removed again if left empty.
    ``adopt``: files the command already wrote into ``out`` for this set (``washbench live``'s saved input):
    moved into the set when it is published, left where they are otherwise.
    """
    refuse_nested(check_out_path(out), command)  # before the lock: a refused --out is not even created
    with output_lock(check_out_path(out)) as out_dir:
        foreign = read_manifest(out_dir) is None  # not (yet) washbench's: only its own .washbench-* leftovers go
        recover(out_dir, only_washbench=foreign)
        previous = owned_entries(out_dir, command, adopt)
        if previous:  # replacing is never silent (io.owners)
            announce(f"{out_dir} holds earlier `washbench {command}` results: replaced when these are complete "
                     "(until then, and after a failure or Ctrl-C, they stay as they are)")  # fmt: skip

        def finish(stage: Path) -> None:
            for name in adopt:
                if (out_dir / name).is_file():
                    os.replace(out_dir / name, stage / name)
            write_manifest(stage, command)

        with staged(out_dir, previous, finish) as stage:
            yield stage


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # a process of another user's
    return True


def recover_shared(folder: Path, *, only_dead: bool = True) -> None:
    """Finish or remove what interrupted publications of result entries left in ``folder``, a folder several
    entries (and several processes publishing them) share: ``OUT/<aircraft>/``.

    A journal ``.washbench-swap-PID`` is rolled forward (:func:`recover`'s way: the entry it was swapping in
    was complete), then stage and old folders (``.washbench-stage-PID``, ``.washbench-old-PID``) and the legacy
    ``.NAME.partial-PID``/``.NAME.old-PID`` folders are removed. ``only_dead`` (the default: a suite's workers
    publish side by side): only those of processes no longer running; without it all (for a caller that holds
    the lock of the output folder and knows nobody else publishes there). Nothing else is touched.
    """
    try:
        entries = sorted(folder.iterdir())
    except OSError:
        return
    for entry in entries:
        pid = publication_pid(entry.name)
        if pid is None or (only_dead and _pid_alive(pid)):
            continue
        if entry.name == f"{JOURNAL_PREFIX}{pid}":
            _roll_forward(folder, entry)
    for entry in sorted(folder.iterdir()):
        pid = publication_pid(entry.name)
        if pid is None or (only_dead and _pid_alive(pid)):
            continue
        if is_legacy_leftover(entry.name) and (entry.is_symlink() or not entry.is_dir()):
            continue  # a legacy leftover was always a folder: a file of such a name is the user's
        remove_tree(entry)


@contextlib.contextmanager
def result_entry(final: Path, check: Callable[[Path], None]) -> Iterator[Path]:
    """Build the result entry ``final`` (a folder, ``OUT/<aircraft>/<manoeuvre>``) in a folder that holds other
    results too, and publish it whole; yield the folder to build it in.

    Before the caller does any work: ``check(final)`` raises WashbenchError (one line) unless what stands at
    ``final`` may be replaced (a washbench result of the same thing); the folder above it is created (a file in
    the way fails now); what interrupted publications of dead processes left there is recovered
    (:func:`recover_shared`). The entry is built in ``.washbench-stage-PID/<name>`` beside its place and swapped
    in by :func:`staged` (journalled, signals held), after ``check`` once more, replacing only a previous entry
    of that name. On an exception (a signal included) nothing is published, the previous entry stays, and a
    folder created here is removed again if left empty. The caller holds the lock of the output folder.
    """
    parent = final.parent
    check(final)
    existed = parent.is_dir()
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WashbenchError(located(parent, f"cannot create a result folder: {_why(exc)}")) from None
    published = False
    try:
        recover_shared(parent)
        with staged(parent, [final], lambda _: check(final)) as stage:
            entry = stage / final.name
            entry.mkdir()
            yield entry
        published = True
    finally:
        if not published and not existed:
            with contextlib.suppress(OSError):
                parent.rmdir()  # only if empty


_TMP_PART = re.compile(r"/\.([^/]+?)\.[A-Za-z0-9_]{8}\.tmp\b")


def unstaged_error(exc: WashbenchError, stage: Path, final: Path) -> WashbenchError:
    """``exc`` with every path in the hidden folder ``stage`` named where it was going (in ``final``) and
    temporary file names replaced by the published ones: what a command building its results in a stage raises."""
    shown = [_unstaged(p, stage, final) for p in exc.problems]
    return WashbenchError(shown[0], shown[1:])


def _unstaged(message: str, stage: Path, out_dir: Path) -> str:
    """``message`` with the stage folder and temporary file names replaced by the published ones."""
    return _TMP_PART.sub(r"/\1", message.replace(str(stage), str(out_dir)))


def refuse_links(folder: Path, names: Sequence[str]) -> None:
    """WashbenchError (one line) if any of ``names`` in ``folder`` is a symbolic link: checked before a command
    rewrites anything (``washbench report`` of a suite checks every result folder and the suite's own first)."""
    for name in names:
        entry = folder / name
        if entry.is_symlink():
            raise WashbenchError(located(entry, "is a symbolic link: washbench never follows or replaces a link in "
                                         "a result folder; remove it"))  # fmt: skip


def replace_entries(folder: Path, stage: Path, names: Sequence[str]) -> None:
    """Publish ``stage``'s entries into ``folder`` replacing the entries ``names`` (``washbench report``).

    Each of ``names`` present in ``folder`` must not be a symbolic link (refused, one line). A manifest in
    ``folder`` is rewritten to list the new entries too.
    """
    refuse_links(folder, names)
    previous = [folder / name for name in names if (folder / name).exists()]
    manifest = read_manifest(folder)
    if manifest is not None:
        listed = set(manifest[1]) | {e.name for e in stage.iterdir()}
        write_manifest(stage, manifest[0], sorted(listed))
        previous.append(folder / MANIFEST)
    swap_in(stage, folder, previous)
