"""What JSBSim is given to read: XML checked first, and its ``<output>`` directives neutralised.

A JSBSim script (``<runscript>``) or aircraft (``<fdm_config>``) may hold ``<output>`` directives: JSBSim then
writes CSV files wherever they say (a path climbing out of any folder, an absolute path onto an existing file)
or opens TCP/UDP sockets, at load time. washbench records the flight itself, so these directives are switched
off: JSBSim reads a copy (a script in a temporary folder; an aircraft in a temporary aircraft folder that links
every other file of the model's folder) in which each directive is a CSV file of a plain name in JSBSim's output
path (a scratch folder) logging nothing, and the output is disabled after loading; washbench says so on standard
error. Nothing is written by JSBSim outside the scratch folder and no socket is opened. The directives are not
removed: JSBSim creates properties for each (``simulation/output/log_rate_hz`` ...), and scripts set them in
events (JSBSim's ``c1723.xml`` does; without the property it stops with ``No property ... is defined``).

JSBSim writes one more file of its own: setting the property ``simulation/write-state-file`` (a script's
``<set>``, an aircraft's flight-control component, a manoeuvre's property input) writes ``initfile.T.xml`` into
its output path, which is JSBSim's root folder (the installed package) unless set. Every FDM washbench creates
gets :func:`scratch_output_dir` (a private temporary folder of the process, removed when it ends) as its
output path, so such a file never lands in the JSBSim installation, the current folder or ``--out``.

Before JSBSim sees a file, :func:`read_xml` parses it with Python's expat, at most :data:`MAX_XML_BYTES`,
accepting only plain internal text entities (JSBSim's scripts name constants so) and refusing entities that
refer to entities (a "billion laughs" DTD), external and parameter entities: a malformed, empty or hostile
file is one line naming the file and line, never a parser traceback or an exhausted memory.
"""

from __future__ import annotations

import os
import sys
import tempfile
import xml.etree.ElementTree as ET
import xml.parsers.expat as expat
from pathlib import Path

from washbench.errors import WashbenchError, located, printable
from washbench.io import budget

#: Largest XML file read (JSBSim's biggest aircraft file is about 1 MB).
MAX_XML_BYTES = 32 * 1024 * 1024


class _RefusedError(Exception):
    pass


def _plain_entity(
    name: str, parameter: bool, value: str | None, base: str | None, system: str | None, public: str | None,
    notation: str | None,
) -> None:  # fmt: skip
    """Accept only a plain internal text entity (JSBSim's scripts name constants so); refuse the rest."""
    if parameter or value is None or system or public or notation:
        raise _RefusedError(f"entity {name!r}: only plain text entities are accepted (no external or parameter ones)")
    if "&" in value or len(value) > 1024:
        raise _RefusedError(f"entity {name!r} refers to other entities or is longer than 1024 characters (refused: "
                            "an entity expansion bomb)")  # fmt: skip


def read_xml(path: str | Path) -> ET.Element:
    """The root element of XML file ``path``; WashbenchError (file, line, what) if it is not plain, well-formed XML."""

    path = Path(path)
    data = budget.read_bounded(path, MAX_XML_BYTES)
    if not data.strip():
        raise WashbenchError(located(path, "the file is empty"))
    builder = ET.TreeBuilder()
    parser = expat.ParserCreate()
    parser.StartElementHandler = builder.start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    parser.EntityDeclHandler = _plain_entity
    try:
        parser.Parse(data, True)
        return builder.close()
    except _RefusedError as exc:
        raise WashbenchError(located(path, str(exc), line=parser.CurrentLineNumber)) from None
    except expat.ExpatError as exc:
        what = expat.errors.messages.get(exc.code, str(exc))
        raise WashbenchError(located(path, f"not well-formed XML ({what})", line=exc.lineno)) from None


_SCRATCH: tuple[int, str] | None = None


_SCRATCH_PREFIX = "washbench-jsbsim-out-"


def _remove_dead_scratch() -> None:
    """Remove the scratch folders of processes that no longer run (killed with SIGKILL: no exit handler ran),
    this user's only."""
    import shutil

    for entry in Path(tempfile.gettempdir()).glob(f"{_SCRATCH_PREFIX}*-*"):
        pid = entry.name[len(_SCRATCH_PREFIX) :].split("-", 1)[0]
        try:
            if not pid.isdigit() or entry.is_symlink() or entry.stat().st_uid != os.getuid():
                continue
        except OSError:
            continue
        if not _running(int(pid)):
            shutil.rmtree(entry, ignore_errors=True)


def _running(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, dead but not yet reaped, does not)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
        return stat[stat.rindex(")") + 2 :].split()[0] != "Z"
    except FileNotFoundError:
        return False
    except (OSError, ValueError, IndexError):  # no /proc (macOS): ask the kernel
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        except OSError:
            return True
        return True


def scratch_output_dir() -> str:
    """A private temporary folder of this process for JSBSim's output path (``FGFDMExec.set_output_path``).

    Created on first use (per process: a forked worker gets its own), removed when the process ends (a pool
    worker's exit included; a process killed with SIGKILL leaves its folder, removed by the next process that
    creates one); whatever JSBSim writes there (``simulation/write-state-file``) is thrown away.
    """
    global _SCRATCH
    if _SCRATCH is None or _SCRATCH[0] != os.getpid():
        import multiprocessing.util
        import shutil

        _remove_dead_scratch()
        path = tempfile.mkdtemp(prefix=f"{_SCRATCH_PREFIX}{os.getpid()}-")
        _SCRATCH = (os.getpid(), path)
        # run at exit by the main process (atexit) and by multiprocessing workers alike
        multiprocessing.util.Finalize(None, shutil.rmtree, args=(path,), kwargs={"ignore_errors": True},
                                      exitpriority=0)  # fmt: skip
    return _SCRATCH[1] + os.sep


def _neutralise(root: ET.Element, stem: str) -> int:
    """Point every top-level ``<output>`` of ``root`` at a CSV file of a plain name (``washbench-STEM-N.csv``, in
    JSBSim's output path: a scratch folder) and drop what it would log; return how many there were.

    The directives stay, so the properties JSBSim creates for each (``simulation/output/log_rate_hz``,
    ``simulation/output[1]/enabled`` ...) exist for the script events that set them (JSBSim's ``c1723.xml``
    does); a socket type, a path of the user's, an output-definition ``file`` and the logged properties are gone.
    The caller also switches the output off (``FGFDMExec.disable_output``), so not even the scratch file fills.
    """
    found = root.findall("output")
    for i, elem in enumerate(found):
        rate = elem.get("rate")
        elem.attrib.clear()
        elem.set("name", f"washbench-{stem}-{i}.csv")
        elem.set("type", "CSV")
        if rate is not None:
            elem.set("rate", rate)
        for child in list(elem):
            elem.remove(child)
        elem.text = None
    return len(found)


def _note(path: Path, n: int) -> None:
    print(
        printable(f"washbench: note: {path}: {n} JSBSim <output> directive(s) switched off (washbench records the "
                  "flight itself; no file is written and no socket opened by JSBSim)"),
        file=sys.stderr,
    )  # fmt: skip


def script_for_jsbsim(path: Path, tmp: Path) -> Path:
    """``path`` if its ``<runscript>`` has no ``<output>``; else a copy with them neutralised in folder ``tmp``."""
    root = read_xml(path)
    n = _neutralise(root, "script")
    if not n:
        return path
    copy = tmp / path.name
    ET.ElementTree(root).write(copy, encoding="utf-8", xml_declaration=True)
    _note(path, n)
    return copy


def aircraft_for_jsbsim(aircraft_root: Path, name: str, tmp: Path) -> Path:
    """The aircraft folder to give JSBSim for model ``name``: ``aircraft_root`` if ``<name>/<name>.xml`` holds
    no ``<output>``; else ``tmp`` holding ``<name>/`` with the file with them neutralised and links to the rest.

    The model file is checked with :func:`read_xml` either way.
    """
    model = aircraft_root / name / f"{name}.xml"
    root = read_xml(model)
    if root.tag != "fdm_config":
        raise WashbenchError(
            located(model, f"not a JSBSim aircraft: the root element is <{root.tag}>, not <fdm_config>")
        )
    n = _neutralise(root, "aircraft")
    if not n:
        return aircraft_root
    folder = tmp / name
    folder.mkdir(parents=True, exist_ok=True)
    for entry in (aircraft_root / name).iterdir():
        if entry.name != model.name:
            os.symlink(entry.resolve(), folder / entry.name)
    ET.ElementTree(root).write(folder / model.name, encoding="utf-8", xml_declaration=True)
    _note(model, n)
    return tmp
