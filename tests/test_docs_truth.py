"""Issue 38, item 8: what a new user reads stays true: the README names the plugin guide, every page has one title
(a second top-level heading splits it in the site's navigation), the suite's metrics.csv columns are listed as
written, and ``washbench --help`` names documentation that ships with the wheel."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from washbench.io.metrics_csv import METRICS_COLUMNS

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
