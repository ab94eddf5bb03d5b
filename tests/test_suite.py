"""washbench suite: parallel runs, a broken manoeuvre reported while the others complete, determinism."""

from __future__ import annotations

import csv
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from report_helpers import check_images, check_tables, without_pdf_links

from washbench.cueing.variants import DEFAULT_WASHOUTS
from washbench.io.paths import MANOEUVRES_DIR
from washbench.review.report import NO_FIGURES

GOOD = [MANOEUVRES_DIR / "c172" / "coordinated_turn.yaml", MANOEUVRES_DIR / "c172" / "stall_recovery.yaml"]


def suite(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "washbench", "suite", *map(str, args)], capture_output=True, text=True, timeout=900
    )


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("manoeuvres")
    for f in GOOD:
        shutil.copy(f, folder / f.name)
    broken = GOOD[0].read_text().replace("phases:", "phasez:", 1)
    (folder / "broken.yaml").write_text(broken)
    return folder


@pytest.fixture(scope="module")
def first(inputs: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, subprocess.CompletedProcess[str]]:
    out = tmp_path_factory.mktemp("suite1")
    return out, suite(inputs, "--out", out, "--jobs", "2")


def test_broken_file_is_reported_and_the_others_complete(first: tuple[Path, subprocess.CompletedProcess[str]]) -> None:
    out, proc = first
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr
    assert "broken.yaml" in proc.stderr and "phasez" in proc.stderr
    # the session's warm-up (tests/warm_kernels.py) compiled every kernel a suite runs: nothing is announced as
    # compiling (a kernel the suite announced but never ran was announced at every suite)
    assert "compiling" not in proc.stderr, proc.stderr
    report = (out / "report.md").read_text()
    assert "2 of 3 manoeuvres" in report
    assert "broken.yaml" in report and "unknown key" in report
    with (out / "metrics.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2 * len(DEFAULT_WASHOUTS) * 6
    assert list(rows[0]) == ["aircraft", "manoeuvre", "washout", "dof", "npc", "integral_error", "max_error",
                             "cue_correct_frac", "cue_scaled_frac", "cue_false_frac", "cue_missing_frac",
                             "msdv_mps15", "msdv_aircraft_mps15", "false_cue_events", "msi_pct",
                             "msi_aircraft_pct", "felt_error", "felt_false", "jolt"]  # fmt: skip
    assert {r["manoeuvre"] for r in rows} == {"coordinated_turn", "stall_recovery"}
    for name in ("coordinated_turn", "stall_recovery"):
        run = out / "c172p" / name
        assert (run / "recording.rrd").is_file() and (run / "metrics.csv").is_file()
        assert f"c172p/{name}/recording.rrd" in report


def test_suite_report_puts_failures_first_and_embeds_valid_figures(
    first: tuple[Path, subprocess.CompletedProcess[str]],
) -> None:
    out, _ = first
    report = out / "report.md"
    text = report.read_text()
    # failures first: before any verdict on what ran, which says on how many it is
    assert text.index("## Failures") < text.index("## Verdict") < text.index("## Summary")
    assert text.index("## Summary") < text.index("## c172p / coordinated_turn")
    assert "**1 of 3 manoeuvres failed**" in text
    assert "![score per manoeuvre and washout](figures/scores.png)" in text and "figures/table4.png" in text
    assert "c172p/coordinated_turn/figures/perceived.png" in text
    assert check_images(report) == 2 + 2 * 2  # scores, Table 4; perceived motion and cue lanes per manoeuvre
    assert check_tables(report) >= 2 + 2 * 4  # provenance, summary; per manoeuvre ranking, 3 metrics (and limits)
    for name in ("coordinated_turn", "stall_recovery"):
        assert check_images(out / "c172p" / name / "report.md") == 3  # perceived motion, cues, envelope
    suite_doc = json.loads((out / "suite.json").read_text())
    assert [e["ok"] for e in suite_doc["manoeuvres"]].count(False) == 1
    assert suite_doc["provenance"]["params"]["name"] == "CW1"
    assert suite_doc["provenance"]["ranking"]["by"] == "felt"  # the ranking rule is recorded
    decided = re.search(r"First place shared \(decided by less than that margin\): (\d) of 2 manoeuvres", text)
    with (out / "ranking.csv").open() as f:
        ranking = list(csv.DictReader(f))
    shared_first = {r["manoeuvre"] for r in ranking if r["rank"] == "1" and r["tied"] == "true"}
    assert decided is not None and int(decided.group(1)) == len(shared_first)


def test_report_command_rebuilds_the_suite_report(
    first: tuple[Path, subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    out, _ = first
    copy = tmp_path / "suite"
    shutil.copytree(out, copy)
    (copy / "report.md").unlink()
    shutil.rmtree(copy / "figures")
    shutil.rmtree(copy / "c172p" / "stall_recovery" / "figures")
    proc = subprocess.run(
        [sys.executable, "-m", "washbench", "report", str(copy)], capture_output=True, text=True, timeout=600
    )
    assert proc.returncode == 0, proc.stderr
    assert without_pdf_links((copy / "report.md").read_text()) == (out / "report.md").read_text()
    assert (copy / "c172p" / "stall_recovery" / "figures" / "perceived.png").is_file()
    for name in ("scores", "table4"):  # the suite's workers drew them; the report command, in its own process
        assert (copy / "figures" / f"{name}.png").read_bytes() == (out / "figures" / f"{name}.png").read_bytes()
    assert check_images(copy / "report.md", vector=True) == 2 + 2 * 2  # every figure now with its PDF
    for name in ("coordinated_turn", "stall_recovery"):
        assert check_images(copy / "c172p" / name / "report.md", vector=True) == 3


def test_ranking_and_comparison_tables(first: tuple[Path, subprocess.CompletedProcess[str]]) -> None:
    out, _ = first
    with (out / "ranking.csv").open() as f:
        ranking = list(csv.DictReader(f))
    assert len(ranking) == 2 * len(DEFAULT_WASHOUTS)
    for name in ("coordinated_turn", "stall_recovery"):
        rows = [r for r in ranking if r["manoeuvre"] == name]
        ranks = sorted((int(r["rank"]), float(r["score"])) for r in rows)
        assert ranks[0][0] == 1 and [s for _, s in ranks] == sorted(s for _, s in ranks)
        for r in rows:  # honest ties: a shared rank only within the documented margin, "tied" says so
            same = [float(x["score"]) for x in rows if x["rank"] == r["rank"]]
            assert (r["tied"] == "true") == (len(same) > 1) and r["rule"] == "felt"
            assert max(same) - min(same) <= max(0.03 * min(same), 0.005)
            better = sum(1 for x in rows if int(x["rank"]) < int(r["rank"]))
            assert int(r["rank"]) == better + 1  # competition ranking: 1, 1, 3
    with (out / "comparison.csv").open() as f:
        comparison = list(csv.DictReader(f))
    assert len(comparison) == 2 * 6 * 3
    for row in comparison:
        for w in ("large-angle", "unrestricted"):
            if row["small-angle"] and row[w]:
                diff = float(row["small-angle"]) - float(row[w])
                assert float(row[f"{w}_better_by"]) == pytest.approx(diff)


def test_same_suite_twice_gives_identical_metrics_and_lean_outputs(
    inputs: Path, first: tuple[Path, subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    # the second time in one process, without recordings and figures: the same numbers, no .rrd and no figure
    out, _ = first
    again = suite(inputs, "--out", tmp_path, "--jobs", "1", "--quiet", "--no-recording", "--no-figures")
    assert again.returncode == 1
    for name in ("metrics.csv", "comparison.csv", "ranking.csv"):
        assert (tmp_path / name).read_bytes() == (out / name).read_bytes(), name
    for name in ("coordinated_turn", "stall_recovery"):
        run = tmp_path / "c172p" / name
        recorded = {p.name for p in (out / "c172p" / name).iterdir()}
        assert "recording.rrd" in recorded and "figures" in recorded
        assert {p.name for p in run.iterdir()} == recorded - {"recording.rrd", "figures"}
        assert (run / "traces.parquet").read_bytes() == (out / "c172p" / name / "traces.parquet").read_bytes()
        assert NO_FIGURES in (run / "report.md").read_text()
    assert "recording.rrd" not in (tmp_path / "report.md").read_text()
    assert not list(tmp_path.rglob("figures")) and not list(tmp_path.rglob("*.png"))
    assert not list(tmp_path.rglob("*.rrd"))
    text = (tmp_path / "report.md").read_text()
    assert NO_FIGURES in text and "## Summary" in text and check_tables(tmp_path / "report.md") >= 2


def test_bad_arguments_are_one_line(tmp_path: Path) -> None:
    proc = suite(tmp_path / "nope", "--out", tmp_path / "o")
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "no such file or folder" in proc.stderr
