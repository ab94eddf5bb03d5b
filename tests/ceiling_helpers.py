"""The ``washbench`` command in a fresh process, the check that no washout scores below the ceiling on a result
folder's files (ceiling.csv, ranking.csv, metrics.csv, run.json), and the independent formulation's pieces (lsim's
response matrix, the trapezoid rule): shared by the tests of the bound's outputs, of the ceiling and of the
platforms."""

from __future__ import annotations

import csv
import json
import subprocess
from pathlib import Path

import inprocess
import numpy as np
import pytest
from scipy import signal


def washbench(*args: str | Path) -> subprocess.CompletedProcess[str]:
    """The ``washbench`` command (the outputs as a user gets them; in the test process where it can be:
    :func:`inprocess.washbench`)."""
    return inprocess.washbench(*args, timeout=1800)


def read_csv(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


def check_ceiling_below_every_washout(run_dir: Path) -> dict[str, float]:
    """Every washout's score and relative error per DOF (ceiling.csv, the replay included) at or above the ceiling,
    every recovered fraction at most 1, the ceiling's solver converged on every DOF and nothing flagged below it
    (run.json), and ceiling.csv's values those of ranking.csv and metrics.csv. Returns washout -> score."""
    rows = read_csv(run_dir / "ceiling.csv")
    assert rows, run_dir
    ranking = {r["washout"]: float(r["score"]) for r in read_csv(run_dir / "ranking.csv")}
    run = json.loads((run_dir / "run.json").read_text())
    motion = {d: v["value"] for d, v in run["perceived_motion"].items()}
    rule = run["provenance"]["ranking"]
    measure = rule.get("measure") or {}

    def term(m: dict[str, str]) -> float:
        """The rule's term of a DOF (m/s^2*s or deg) from metrics.csv's row, worked out here from the file."""
        if rule["by"] != "felt":
            return float(m["integral_error"])
        jolt = float(m["jolt"]) if m["jolt"] else 0.0
        return (float(m["felt_error"]) + measure["false_weight"] * float(m["felt_false"])
                + measure["jolt_time_s"] * jolt)  # fmt: skip

    errors = {(r["washout"], r["dof"]): term(r) for r in read_csv(run_dir / "metrics.csv")}
    felt = "felt_" if rule["by"] == "felt" else ""
    scores = {}
    for r in rows:
        if r["dof"] == "score":
            assert float(r["relative_error"]) == ranking[r["washout"]]  # the ranking's own measure
            scores[r["washout"]] = float(r["relative_error"])
        elif r["relative_error"]:
            rel = errors[(r["washout"], r["dof"])] / float(motion[felt + r["dof"]])
            assert float(r["relative_error"]) == pytest.approx(rel, rel=1e-12)
        if not r["ceiling"]:
            continue
        ceiling, value = float(r["ceiling"]), float(r["relative_error"])
        assert 0.0 <= ceiling <= 1.0 + 1e-9, (run_dir, r)
        # the LPs are solved to 1e-9 and their dual objective taken: a washout below by more is a defect
        assert ceiling <= value + 1e-9, f"{run_dir}: {r['washout']} {r['dof']} ({value}) beats the ceiling ({ceiling})"
        if r["recovered"]:
            assert float(r["recovered"]) <= 1.0 + 1e-9
    doc = json.loads((run_dir / "run.json").read_text())["bound"]
    assert set(doc["solver_status"].values()) <= {"Solved", "Exact"}, doc["solver_status"]
    assert doc["below_ceiling"] == []
    return scores


def response_matrix(num: np.ndarray, den: np.ndarray, n: int, dt: float) -> np.ndarray:
    """H (n, n): y = H u for the continuous model num/den, input linear between samples, started in the steady
    state of u[0] (scipy.signal.lsim, one column per unit input)."""
    sys_ = signal.StateSpace(*signal.tf2ss(num, den))
    x_unit = -np.linalg.solve(sys_.A, sys_.B).ravel()  # the steady state per unit constant input
    t = np.arange(n) * dt
    h = np.empty((n, n))
    for j in range(n):
        u = np.zeros(n)
        u[j] = 1.0
        _, y, _ = signal.lsim(sys_, u, t, X0=x_unit if j == 0 else np.zeros_like(x_unit))
        h[:, j] = y
    return h


def trapezoid(n: int, dt: float) -> np.ndarray:
    w = np.full(n, dt)
    w[0] = w[-1] = 0.5 * dt
    return w
