"""Issue 38, item 8: what a new user reads stays true: the README names the plugin guide, every page has one title
(a second top-level heading splits it in the site's navigation), the suite's metrics.csv columns are listed as
written, and ``washbench --help`` names documentation that ships with the wheel."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from washbench.cli import build_parser
from washbench.cli_examples import EXAMPLES
from washbench.flight.scripts import bundled_script
from washbench.io.metrics_csv import METRICS_COLUMNS
from washbench.io.paths import bundled_file, resolve_data_file, resolve_manoeuvre

ROOT = Path(__file__).resolve().parents[1]
PAGES = sorted(p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts)


def _without_code(text: str) -> str:
    return re.sub(r"^(```|~~~).*?^\1", "", text, flags=re.S | re.M)


def test_the_readme_names_the_plugin_guide() -> None:
    assert "`docs/washouts.md`" in (ROOT / "README.md").read_text()


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT / "docs")))
def test_every_page_has_one_title(page: Path) -> None:
    text = page.read_text()
    for included in re.findall(r"^```\{include\} (\S+)", text, flags=re.M):  # a page that is another file
        text = text + "\n" + (page.parent / included).read_text()
    titles = re.findall(r"^# \S.*$", _without_code(text), flags=re.M)
    assert len(titles) == 1, titles


@pytest.mark.parametrize("page", ["docs/tutorial/getting-started.md", "docs/reference/outputs.md"])
def test_the_suite_metrics_columns_are_listed_as_written(page: str, tmp_path: Path) -> None:
    """The suite's metrics.csv: every run's columns with its aircraft and manoeuvre in front (runs/suite.py)."""
    text = (ROOT / page).read_text()
    (listed,) = re.findall(r"^\| `DIR/metrics\.csv` \| `([^`]+)`", text, flags=re.M)
    assert listed.split(",") == ["aircraft", "manoeuvre", *METRICS_COLUMNS]


def test_top_level_help_names_documentation_a_wheel_has(tmp_path: Path) -> None:
    proc = subprocess.run([sys.executable, "-m", "washbench", "--help"], capture_output=True, text=True, check=True,
                          cwd=tmp_path)  # fmt: skip
    help_text = " ".join(proc.stdout.split())
    assert "python -m pydoc washbench" in help_text and "--help" in help_text
    assert "the wheel holds no docs/" in help_text
    pydoc = subprocess.run([sys.executable, "-m", "pydoc", "washbench"], capture_output=True, text=True, cwd=tmp_path,
                           timeout=60)  # fmt: skip
    assert pydoc.returncode == 0 and "washbench" in pydoc.stdout and "PACKAGE CONTENTS" in pydoc.stdout


COMMAND = re.compile(r"^\s*(?:\$ )?(?:\S*/)?washbench\s")
#: Words of a synopsis (``washbench send FILE --to HOST:PORT [--speed N]``), which is read, not copied.
PLACEHOLDER = re.compile(r"^\[|\]$|^[A-Z][A-Z_0-9]*(?:\.\.\.)?$|HOST:PORT|^FILE\b")
#: Where the manoeuvres of a bundled name live (``c172/steep_turn``): a word like that must name one.
BUNDLED_AIRCRAFT = ("c172", "columbia400")


def _doc_commands() -> list[tuple[str, str, list[str]]]:
    """Every ``washbench`` command in a fenced code block of the README and the docs, and of each command's
    ``--help`` examples: (page, line as written, argv after ``washbench``), continuation lines joined, ``&&`` and
    ``|`` chains split, comments dropped; synopses (placeholders in capitals, ``[optional]`` parts) left out."""
    found = []
    for page in [ROOT / "README.md", *PAGES]:
        text = page.read_text()
        for block in re.findall(r"^(?:```|~~~)[^\n]*\n(.*?)^(?:```|~~~)", text, flags=re.S | re.M):
            for line in block.replace("\\\n", " ").splitlines():
                for part in re.split(r"&&|\|", line):
                    if not COMMAND.match(part):
                        continue
                    words = shlex.split(part, comments=True)
                    words = words[:-1] if words[-1] == "&" else words  # started in the background
                    if any(PLACEHOLDER.search(w) for w in words[1:]):
                        continue
                    found.append((str(page.relative_to(ROOT)), part.strip(), words[1:]))
    for command, lines in EXAMPLES.items():  # and the examples that end each command's --help
        for line in lines:
            found += [(f"washbench {command} --help", part, shlex.split(part)[1:]) for part in re.split(r"&&|\|", line)
                      if COMMAND.match(part)]  # fmt: skip
    return found


DOC_COMMANDS = _doc_commands()


def test_the_docs_have_commands_to_check() -> None:
    pages = {page for page, _, _ in DOC_COMMANDS}
    assert {"docs/platforms.md", "docs/optimal-mpc.md", "docs/how-to/own-log.md", "README.md"} <= pages
    assert len(DOC_COMMANDS) > 40


@pytest.mark.parametrize(("page", "line", "argv"), DOC_COMMANDS, ids=[f"{p}:{i}" for i, (p, _, _) in
                                                                      enumerate(DOC_COMMANDS)])  # fmt: skip
def test_every_docs_command_works_as_copied(page: str, line: str, argv: list[str]) -> None:
    """Issue 52, item 9: each command of the docs as a user copies it, into a shell in any folder after the README's
    main job: the real parser takes it (a missing --out fails here), no literal ``...`` stands for words left out,
    every bundled manoeuvre, JSBSim script and platform or parameter file it names resolves from any folder (never a
    path into a checkout, ``washbench/data/...``), and it writes into no folder the main job's suite would refuse
    or lose (``results`` is the suite's: issue 52, item 6)."""
    assert "..." not in argv, line
    if not argv or argv[0].startswith("-"):
        return
    try:
        args = build_parser().parse_args(argv)
    except SystemExit:
        pytest.fail(f"{page}: the parser refuses {line!r}")
    for option in ("platform", "params"):
        value = getattr(args, option, None)
        if value is not None:
            assert not str(value).startswith("washbench/"), f"{page}: {line}: a checkout's path; name it by name"
            if bundled_file(value) is not None or ("/" not in str(value) and not str(value).endswith(".yaml")):
                resolve_data_file(value, f"--{option}")  # a bundled name: raises if it is none
    names = [*getattr(args, "manoeuvres", []), *([args.manoeuvre] if getattr(args, "manoeuvre", None) else []),
             *getattr(args, "inputs", []), *([args.fly] if getattr(args, "fly", None) else [])]  # fmt: skip
    for name in map(str, names):
        bundled_like = name.split("/")[0] in BUNDLED_AIRCRAFT or (name.endswith(".xml") and "/" not in name)
        if bundled_like or name.startswith(("washbench:", "jsbsim:")):
            assert resolve_manoeuvre(Path(name)).exists(), f"{page}: {line}: {name} names nothing"
    for script in getattr(args, "jsbsim_scripts", []):
        bundled_script(script)
    out = str(getattr(args, "out", None) or "").rstrip("/")
    if out == "results" or out.startswith("results/"):
        assert args.command == "suite" and out == "results", f"{page}: {line}: results holds the main job's suite"


def test_the_descriptions_name_what_the_code_has() -> None:
    """Issue 52, item 14: ``washbench --help``, the README, the tutorial and the packages' docstrings described the
    project as it was three washouts ago ("the three washouts", "the Atlas"). Every built-in washout is named in the
    README (a washout added to the registry must be added there too: the marked sentence says where), every
    platform model and bundled platform file in the README and the platform package's docstring, and no description
    counts the washouts as three."""
    import washbench.cueing
    import washbench.platform
    from washbench.cueing.params import WASHOUT_KINDS
    from washbench.cueing.registry import BUILTIN_PYTHON
    from washbench.io.paths import BUNDLED_PLATFORMS
    from washbench.platform.model import KINDS

    readme = (ROOT / "README.md").read_text()
    tutorial = (ROOT / "docs" / "tutorial" / "getting-started.md").read_text()
    top_help = " ".join(build_parser().format_help().split())
    for kind in (*WASHOUT_KINDS, *BUILTIN_PYTHON):
        assert f"`{kind}`" in readme, kind
    cueing_doc = washbench.cueing.__doc__ or ""
    assert all(f"``{kind}``" in cueing_doc for kind in (*WASHOUT_KINDS[:3], *BUILTIN_PYTHON)), cueing_doc
    platform_doc = " ".join((washbench.platform.__doc__ or "").split())
    for name in (*KINDS, *BUNDLED_PLATFORMS):
        assert name in platform_doc.lower() and name in readme.lower(), name
    for text in (readme, tutorial, top_help, cueing_doc, platform_doc):
        prose = re.sub(r"<!--.*?-->", "", text, flags=re.S)  # (the marked notes quote the old wording)
        assert not re.search(r"\b(?:three|3) washout", prose, flags=re.I), text[:80]
    assert "hexapod" in top_help and "model-predictive" in top_help and "adaptive" in top_help
