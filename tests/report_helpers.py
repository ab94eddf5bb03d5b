"""Shared by the report tests: every figure a Markdown report links exists and is a valid image."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib.image
import numpy as np

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def linked_files(report: Path) -> list[Path]:
    """Every local file a Markdown report links or embeds."""
    targets = re.findall(r"\]\(([^)]+)\)", report.read_text())
    return [report.parent / t for t in targets if "://" not in t]


PDF_HINT = "Vector versions of the figures for papers (PDF): `washbench report` on this folder draws them."


def without_pdf_links(text: str) -> str:
    """A report's text without its PDF links and with the one hint a run writes at its end instead (``washbench
    report`` adds the PDFs)."""
    text = re.sub(r"Vector version for papers: \[[^]]+\.pdf\]\([^)]+\.pdf\)\n\n", "", text)
    return text.rstrip() + "\n\n" + PDF_HINT + "\n"


def check_images(report: Path, vector: bool = False) -> int:
    """Every linked figure exists and is a valid image; returns the number of PNGs.

    ``vector``: each PNG has its PDF linked (``washbench report``); else none is linked and the report says how to
    get them (``run``, ``cue``, ``suite`` write PNG only).
    """
    files = linked_files(report)
    pngs = [f for f in files if f.suffix == ".png"]
    assert pngs, "the report embeds no figure"
    for f in files:
        assert f.is_file(), f
    for f in pngs:
        assert f.read_bytes()[:8] == PNG_SIGNATURE, f
        image = matplotlib.image.imread(f)
        assert image.ndim == 3 and image.shape[0] >= 200 and image.shape[1] >= 400, (f, image.shape)
        assert np.ptp(image[..., :3]) > 0.5, f"{f} is blank"
        pdf = f.with_suffix(".pdf")
        if vector:
            assert pdf in files, f"no vector version linked for {f.name}"
            data = pdf.read_bytes()
            assert data.startswith(b"%PDF-") and data.rstrip().endswith(b"%%EOF"), pdf
        else:
            assert pdf not in files and not pdf.exists(), f"{pdf.name}: a run writes PNG only"
    if not vector:
        # said once, not under each of the figures (issue 52, item 10: some 70 times in a suite's report)
        assert report.read_text().count(PDF_HINT) == 1, "the report does not say once how to get the PDFs"
    return len(pngs)


def check_tables(report: Path) -> int:
    """Every Markdown table is well formed (a delimiter row, the same cell count in every row); returns the count."""
    lines = report.read_text().splitlines()
    tables = 0
    i = 0
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and re.fullmatch(r"\|(---\|)+", lines[i + 1]):
            width = lines[i].count("|")
            assert lines[i + 1].count("|") == width, lines[i]
            j = i + 2
            while j < len(lines) and lines[j].startswith("|"):
                assert lines[j].count("|") == width, f"{report}: {lines[j]!r} has not {width - 1} cells"
                j += 1
            assert j == len(lines) or lines[j] == "", f"{report}: no blank line after the table at {lines[j]!r}"
            tables += 1
            i = j
        else:
            assert not lines[i].startswith("|"), f"{report}: table row outside a table: {lines[i]!r}"
            i += 1
    return tables
