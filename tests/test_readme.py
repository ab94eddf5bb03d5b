"""The README is also the package's long description (pyproject ``readme``): it must render on a package index,
where relative links and images break, and its two commands and the pages it names must stay true."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _outside_code(text: str) -> str:
    """The README without fenced code blocks and inline code (where brackets are not links)."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    return re.sub(r"`[^`\n]*`", "", text)


def test_no_relative_links_or_images() -> None:
    prose = _outside_code(README)
    targets = re.findall(r"\]\(([^)\s]+)", prose) + re.findall(r"<img[^>]*src=[\"']([^\"']+)", prose)
    targets += re.findall(r"^\[[^\]]+\]:\s*(\S+)", prose, flags=re.M)  # reference-style link definitions
    relative = [t for t in targets if not re.match(r"https?://", t)]
    assert relative == []


def test_the_two_commands_are_there() -> None:
    assert "python3 -m venv .venv && .venv/bin/pip install -e . && .venv/bin/washbench suite --out results" in README
    assert "python3 -m venv .venv && .venv/bin/pip install -e '.[test]' && .venv/bin/python -m pytest -q" in README


def test_named_docs_pages_exist() -> None:
    named = set(re.findall(r"`(docs/[\w./-]+)`", README))
    assert "docs/tutorial/getting-started.md" in named
    missing = sorted(p for p in named if not (ROOT / p).exists())
    assert missing == []


def test_pyproject_uses_it_as_long_description() -> None:
    import tomllib

    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert meta["readme"] == "README.md"
