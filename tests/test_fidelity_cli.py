"""``--rank-by`` and the cue classification end to end: ``washbench cue`` in a subprocess, files read back."""

import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from washbench.analysis.metrics import DOFS
from washbench.io.paths import DATA_DIR
from washbench.io.results import read_metrics_csv

G = 9.80665
DT = 1 / 120


def _input(path: Path) -> Path:
    """10 s at 120 Hz: a 2 m/s^2 surge step 1-4 s, a +-20 deg/s roll doublet 5-7 s, a 0.5 m/s^2 heave sine."""
    t = np.arange(10 * 120 + 1) * DT
    cols = {
        "t_s": t,
        "f_x_mps2": np.where((t >= 1.0) & (t < 4.0), 2.0, 0.0),
        "f_y_mps2": np.zeros_like(t),
        "f_z_mps2": -G + 0.5 * np.sin(2 * np.pi * 0.2 * t),
        "omega_x_degps": np.where((t >= 5.0) & (t < 6.0), 20.0, 0.0) - np.where((t >= 6.0) & (t < 7.0), 20.0, 0.0),
        "omega_y_degps": np.zeros_like(t),
        "omega_z_degps": np.zeros_like(t),
    }
    lines = [",".join(cols)] + [",".join(repr(float(cols[c][i])) for c in cols) for i in range(len(t))]
    path.write_text("\n".join(lines) + "\n")
    return path


def cue(*args: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "washbench", "cue", *map(str, args), "--no-recording",
                           "--no-figures"], capture_output=True, text=True, timeout=300)  # fmt: skip


@pytest.fixture(scope="module")
def trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _input(tmp_path_factory.mktemp("fid") / "trace.csv")


def _params(path: Path, section: str) -> Path:
    path.write_text((DATA_DIR / "cw1.yaml").read_text() + "\n" + section)
    return path


def _ranking(folder: Path) -> list[dict[str, str]]:
    with (folder / "ranking.csv").open() as fh:
        return list(csv.DictReader(fh))


def test_rule_from_the_parameter_file_and_rank_by_override(trace: Path, tmp_path: Path) -> None:
    params = _params(tmp_path / "p.yaml", "ranking:\n  by: weighted\n  dof_weights: {surge: 1, roll: 3}\n")
    res = cue(trace, "--out", tmp_path / "w", "--params", params)
    assert res.returncode == 0, res.stderr
    prov = json.loads((tmp_path / "w" / "run.json").read_text())["provenance"]["ranking"]
    assert prov["by"] == "weighted" and prov["dof_weights"]["roll"] == 3.0 and prov["dof_weights"]["yaw"] == 0.0
    rows = _ranking(tmp_path / "w")
    assert {r["rule"] for r in rows} == {"weighted"} and all(r["tied"] in ("true", "false") for r in rows)
    assert "Ranked by user-weighted relative integral error" in (tmp_path / "w" / "report.md").read_text()

    res = cue(trace, "--out", tmp_path / "f", "--params", params, "--rank-by", "false-cue")
    assert res.returncode == 0, res.stderr
    assert json.loads((tmp_path / "f" / "run.json").read_text())["provenance"]["ranking"]["by"] == "false-cue"
    metrics = read_metrics_csv(tmp_path / "f" / "metrics.csv")
    false_time = {w: sum(m.cue_false_frac for m in metrics if m.washout == w) for w in {m.washout for m in metrics}}
    rows = _ranking(tmp_path / "f")
    assert {r["washout"]: float(r["score"]) for r in rows} == pytest.approx(false_time)
    ranks = [int(r["rank"]) for r in rows]
    assert ranks == sorted(ranks) and ranks[0] == 1


def test_cue_classification_columns_are_consistent(trace: Path, tmp_path: Path) -> None:
    res = cue(trace, "--out", tmp_path / "o")
    assert res.returncode == 0, res.stderr
    metrics = read_metrics_csv(tmp_path / "o" / "metrics.csv")
    assert len(metrics) == 3 * len(DOFS)
    for m in metrics:
        total = m.cue_correct_frac + m.cue_scaled_frac + m.cue_false_frac + m.cue_missing_frac
        assert 0.0 <= total <= 1.0 + 1e-12
    # the surge step is felt by the aircraft pilot (2 m/s^2 >> 0.17): some simulator surge cue is classified
    surge = [m for m in metrics if m.dof == "surge"]
    assert all(m.cue_correct_frac + m.cue_scaled_frac + m.cue_missing_frac > 0.05 for m in surge)
    header = (tmp_path / "o" / "metrics.csv").read_text().splitlines()[0]
    assert header.startswith("washout,dof,npc,integral_error,max_error,cue_correct_frac")


def test_bad_ranking_section_is_one_line_exit_2(trace: Path, tmp_path: Path) -> None:
    params = _params(tmp_path / "bad.yaml", "ranking:\n  by: best\n")
    res = cue(trace, "--out", tmp_path / "x", "--params", params)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "bad.yaml" in res.stderr and "ranking.by" in res.stderr
    assert not (tmp_path / "x").exists()
    params = _params(tmp_path / "noweights.yaml", "ranking:\n  by: weighted\n")
    res = cue(trace, "--out", tmp_path / "y", "--params", params)
    assert res.returncode == 2 and "dof_weights" in res.stderr and "Traceback" not in res.stderr


def test_msdv_on_the_heave_rows_equals_an_independent_analogue_simulation(trace: Path, tmp_path: Path) -> None:
    """The aircraft pilot's MSDV: the analogue Wf simulated by scipy.signal.lsim on the input's vertical motion."""
    import math

    from scipy import signal

    from washbench.perception.sickness import wf_tf

    res = cue(trace, "--out", tmp_path / "m")
    assert res.returncode == 0, res.stderr
    rows = read_metrics_csv(tmp_path / "m" / "metrics.csv")
    heave = [r for r in rows if r.dof == "heave"]
    assert len(heave) == 3 and all(r.msdv_mps15 > 0.0 for r in heave)
    assert all(math.isnan(r.msdv_mps15) for r in rows if r.dof != "heave")
    data = np.loadtxt(trace, delimiter=",", skiprows=1)
    t, f_z = data[:, 0], data[:, 3]
    _, aw, _ = signal.lsim(signal.lti(*wf_tf()), -(f_z + G), t)
    expected = math.sqrt(float(np.sum(aw * aw)) * DT)
    assert expected > 0.3  # 0.5 m/s^2 at 0.2 Hz (Wf 0.99) for 10 s, less the filter's start: about 1.1
    assert heave[0].msdv_aircraft_mps15 == pytest.approx(expected, rel=1e-3)
    assert "## Motion sickness dose" in (tmp_path / "m" / "report.md").read_text()


def test_vestibular_choice_changes_the_perception_and_is_recorded(trace: Path, tmp_path: Path) -> None:
    """--vestibular telban-cardullo: the aircraft pilot's perceived roll rate is the Telban-Cardullo canal model's
    (scipy lsim of its transfer function on the input), the choice is in the provenance and the report."""
    import pyarrow.parquet as pq
    from scipy import signal

    from washbench.perception.vestibular import MODELS, canal_tf

    res = cue(trace, "--out", tmp_path / "tc", "--vestibular", "telban-cardullo")
    assert res.returncode == 0, res.stderr
    prov = json.loads((tmp_path / "tc" / "run.json").read_text())["provenance"]
    assert prov["vestibular"]["model"] == "telban-cardullo"
    assert prov["vestibular"]["values"]["canals"]["T_N_s"] == 0.06
    assert "Telban-Cardullo otolith and canals" in (tmp_path / "tc" / "report.md").read_text()
    table = pq.read_table(tmp_path / "tc" / "traces.parquet")
    t = table.column("t_s").to_numpy()
    p = table.column("aircraft.perceived_omega_x_degps").to_numpy()
    u = np.loadtxt(trace, delimiter=",", skiprows=1)[:, 4]  # omega_x_degps of the input
    _, y, _ = signal.lsim(signal.lti(*canal_tf(MODELS["telban-cardullo"].canals)), u, t)
    np.testing.assert_allclose(p, y, atol=1e-6 * 20.0 * 12.0)
    default = cue(trace, "--out", tmp_path / "ym")
    assert default.returncode == 0
    p_ym = pq.read_table(tmp_path / "ym" / "traces.parquet").column("aircraft.perceived_omega_x_degps").to_numpy()
    assert np.max(np.abs(p_ym - p)) > 1.0  # a different model, a different perception
    assert json.loads((tmp_path / "ym" / "run.json").read_text())["provenance"]["vestibular"]["model"] == "young-meiry"
