"""``--rank-by``, ``--vestibular``, the cue classification and the MSDV end to end: ``washbench cue`` on a short
trace (in this process, three runs shared by the tests), files read back."""

import csv
import json
import math
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from scipy import signal

from washbench.analysis.metrics import DOFS
from washbench.cli import main
from washbench.cueing.variants import DEFAULT_WASHOUTS
from washbench.io.metrics_csv import read_metrics_csv
from washbench.io.paths import DATA_DIR
from washbench.perception.sickness import wf_tf
from washbench.perception.vestibular import MODELS, canal_tf

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


def cue(*args: object) -> int:
    return main(["cue", *map(str, args), "--no-recording", "--no-figures"])


def _params(path: Path, section: str) -> Path:
    path.write_text((DATA_DIR / "cw1.yaml").read_text() + "\n" + section)
    return path


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """default; weighted (the parameter file's rule); tc (--rank-by false-cue overriding it, --vestibular)."""
    d = tmp_path_factory.mktemp("fid")
    trace = _input(d / "trace.csv")
    params = _params(d / "p.yaml", "ranking:\n  by: weighted\n  dof_weights: {surge: 1, roll: 3}\n")
    assert cue(trace, "--out", d / "default") == 0
    assert cue(trace, "--out", d / "weighted", "--params", params) == 0
    assert cue(trace, "--out", d / "tc", "--params", params, "--rank-by", "false-cue",
               "--vestibular", "telban-cardullo") == 0  # fmt: skip
    return {"trace": trace, "default": d / "default", "weighted": d / "weighted", "tc": d / "tc"}


def _ranking(folder: Path) -> list[dict[str, str]]:
    with (folder / "ranking.csv").open() as fh:
        return list(csv.DictReader(fh))


def _prov(folder: Path) -> dict:
    return json.loads((folder / "run.json").read_text())["provenance"]


def test_rule_from_the_parameter_file_and_rank_by_override(runs: dict[str, Path]) -> None:
    prov = _prov(runs["weighted"])["ranking"]
    assert prov["by"] == "weighted" and prov["dof_weights"]["roll"] == 3.0 and prov["dof_weights"]["yaw"] == 0.0
    rows = _ranking(runs["weighted"])
    assert {r["rule"] for r in rows} == {"weighted"} and all(r["tied"] in ("true", "false") for r in rows)
    assert "Ranked by user-weighted relative integral error" in (runs["weighted"] / "report.md").read_text()

    assert _prov(runs["tc"])["ranking"]["by"] == "false-cue"
    metrics = read_metrics_csv(runs["tc"] / "metrics.csv")
    # false cues by size and duration: each DOF's false part over its threshold, over the felt motion (both in
    # threshold-seconds), worked out here from the files
    units = {"surge": 0.17, "sway": 0.17, "heave": 0.28, "roll": 3.0, "pitch": 3.6, "yaw": 2.6}
    motion = json.loads((runs["tc"] / "run.json").read_text())["perceived_motion"]
    felt = max(sum(motion[f"felt_{d}"]["value"] / u for d, u in units.items()), 1.0)
    false = {w: sum(m.felt_false / units[m.dof] for m in metrics if m.washout == w) / felt
             for w in {m.washout for m in metrics}}  # fmt: skip
    rows = _ranking(runs["tc"])
    assert {r["washout"]: float(r["score"]) for r in rows} == pytest.approx(false)
    ranks = [int(r["rank"]) for r in rows]
    assert ranks == sorted(ranks) and ranks[0] == 1
    assert _prov(runs["default"])["ranking"]["by"] == "felt"  # the default rule


def test_cue_classification_columns_are_consistent(runs: dict[str, Path]) -> None:
    metrics = read_metrics_csv(runs["default"] / "metrics.csv")
    assert len(metrics) == len(DEFAULT_WASHOUTS) * len(DOFS)
    for m in metrics:
        total = m.cue_correct_frac + m.cue_scaled_frac + m.cue_false_frac + m.cue_missing_frac
        assert 0.0 <= total <= 1.0 + 1e-12
    # the surge step is felt by the aircraft pilot (2 m/s^2 >> 0.17): some simulator surge cue is classified
    surge = [m for m in metrics if m.dof == "surge"]
    assert all(m.cue_correct_frac + m.cue_scaled_frac + m.cue_missing_frac > 0.05 for m in surge)
    header = (runs["default"] / "metrics.csv").read_text().splitlines()[0]
    assert header.startswith("washout,dof,npc,integral_error,max_error,cue_correct_frac")


def test_bad_ranking_section_is_one_line_exit_2(runs: dict[str, Path], tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    params = _params(tmp_path / "bad.yaml", "ranking:\n  by: best\n")
    assert cue(runs["trace"], "--out", tmp_path / "x", "--params", params) == 2
    err = capsys.readouterr().err
    assert "bad.yaml" in err and "ranking.by" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x").exists()
    params = _params(tmp_path / "noweights.yaml", "ranking:\n  by: weighted\n")
    assert cue(runs["trace"], "--out", tmp_path / "y", "--params", params) == 2
    assert "dof_weights" in capsys.readouterr().err


def test_msdv_on_the_heave_rows_equals_an_independent_analogue_simulation(runs: dict[str, Path]) -> None:
    """The aircraft pilot's MSDV: the analogue Wf simulated by scipy.signal.lsim on the input's vertical motion."""
    rows = read_metrics_csv(runs["default"] / "metrics.csv")
    heave = [r for r in rows if r.dof == "heave"]
    assert len(heave) == len(DEFAULT_WASHOUTS)
    assert all(r.msdv_mps15 > 0.0 for r in heave if r.washout != "still")  # (still: level, no vertical motion)
    assert all(math.isnan(r.msdv_mps15) for r in rows if r.dof != "heave")
    data = np.loadtxt(runs["trace"], delimiter=",", skiprows=1)
    t, f_z = data[:, 0], data[:, 3]
    _, aw, _ = signal.lsim(signal.lti(*wf_tf()), -(f_z + G), t)
    expected = math.sqrt(float(np.sum(aw * aw)) * DT)
    assert expected > 0.3  # 0.5 m/s^2 at 0.2 Hz (Wf 0.99) for 10 s, less the filter's start: about 1.1
    assert heave[0].msdv_aircraft_mps15 == pytest.approx(expected, rel=1e-3)
    assert "## Motion sickness dose" in (runs["default"] / "report.md").read_text()


def test_vestibular_choice_changes_the_perception_and_is_recorded(runs: dict[str, Path]) -> None:
    """--vestibular telban-cardullo: the aircraft pilot's perceived roll rate is the Telban-Cardullo canal model's
    (scipy lsim of its transfer function on the input), the choice is in the provenance and the report."""
    prov = _prov(runs["tc"])
    assert prov["vestibular"]["model"] == "telban-cardullo"
    assert prov["vestibular"]["values"]["canals"]["T_N_s"] == 0.06
    assert "Telban-Cardullo otolith and canals" in (runs["tc"] / "report.md").read_text()
    table = pq.read_table(runs["tc"] / "traces.parquet")
    t = table.column("t_s").to_numpy()
    p = table.column("aircraft.perceived_omega_x_degps").to_numpy()
    u = np.loadtxt(runs["trace"], delimiter=",", skiprows=1)[:, 4]  # omega_x_degps of the input
    _, y, _ = signal.lsim(signal.lti(*canal_tf(MODELS["telban-cardullo"].canals)), u, t)
    np.testing.assert_allclose(p, y, atol=1e-6 * 20.0 * 12.0)
    p_ym = pq.read_table(runs["default"] / "traces.parquet").column("aircraft.perceived_omega_x_degps").to_numpy()
    assert np.max(np.abs(p_ym - p)) > 1.0  # a different model, a different perception
    assert _prov(runs["default"])["vestibular"]["model"] == "young-meiry"


def test_msi_on_the_heave_rows_equals_the_model_on_the_input(runs: dict[str, Path]) -> None:
    """The aircraft pilot's MSI: the SVC model on the input file's head motion (the surge step, roll doublet and
    heave sine); every simulator pilot has one, the report shows them next to the MSDV."""
    from washbench.perception.svc import head_msi, svc_msi

    rows = read_metrics_csv(runs["default"] / "metrics.csv")
    heave = [r for r in rows if r.dof == "heave"]
    assert all(math.isnan(r.msi_pct) for r in rows if r.dof != "heave")
    data = np.loadtxt(runs["trace"], delimiter=",", skiprows=1)
    f, w = data[:, 1:4], np.radians(data[:, 4:7])
    expected = head_msi(f, w, DT)
    assert expected > 1e-4 and heave[0].msi_aircraft_pct == pytest.approx(expected, rel=1e-12)
    assert svc_msi(f, w, DT).conflict_mps2.max() > 0.3  # the 2 m/s^2 surge step is a real conflict
    assert all(r.msi_pct >= 0.0 and math.isfinite(r.msi_pct) for r in heave)
    report = (runs["default"] / "report.md").read_text()
    assert "| pilot | MSDV (m/s^1.5) | MSI (%) |" in report and "subjective vertical conflict" in report


def test_the_sickness_models_are_in_the_provenance_and_report(runs: dict[str, Path]) -> None:
    from washbench.perception.svc import IN1

    rec = _prov(runs["tc"])["vestibular"]["sickness"]
    assert rec["msdv"] == "ISO 2631-1 Wf" and rec["msi"]["model"] == "6dof-svc-in1"
    assert rec["msi"]["values"]["tau_i_s"] == IN1.tau_i_s == 720.0 and rec["msi"]["values"]["k_vc"] == 5.0
    assert "| sickness models | MSDV: ISO 2631-1 Wf; MSI: 6-DOF subjective vertical conflict, In1" in (
        runs["tc"] / "report.md"
    ).read_text()
