"""Evaluations for studies: many washout candidates on one recorded flight, in one compiled call.

An evaluation is one washout (kind + parameter set) on one recorded trace: the washout, the Atlas platform and
the simulator pilot's head motion (the same compiled loop as streaming, :func:`washbench.cueing.kernel.bank_block`),
the vestibular models (:func:`washbench.perception.sections.sections_step`), the metrics
(:func:`washbench.analysis.metric_sums.acc_update`) and the ranking rule's score. :func:`evaluate_batch` runs a
batch of candidates in parallel threads (numba ``prange``, one candidate per thread at a time), sample by sample,
keeping only each candidate's running sums: nothing per sample is stored or written. Because every stage is the
same code as ``washbench cue``, the metrics and scores are those of ``washbench cue`` on the same trace, bit for
bit.

Units: metrics as in ``metrics.csv`` (m/s^2 and m/s^2*s for surge, sway, heave; deg/s and deg for roll, pitch,
yaw); ``saturated_s`` the time (s) during which any platform limit (position, velocity, acceleration, sphere rate,
angular acceleration) was active.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from washbench.analysis.metric_sums import (
    NACC,
    NFELT,
    acc_update,
    cue_sign,
    felt_finish,
    felt_update,
    finish,
    jolt_step,
)
from washbench.analysis.metrics import DOFS, npc_from_pc
from washbench.analysis.ranking import DEFAULT_RULE, RankRule, perceived_motion, rule_values
from washbench.cueing.bank import build_arrays, cue_trace
from washbench.cueing.kernel import C_KIND, NFIELDS, NSTATE, O_HEAD_F, O_HEAD_OMEGA, O_SAT, SAT_KINDS, bank_block
from washbench.io.metrics_csv import MetricRow
from washbench.numerics.jit import njit, prange
from washbench.numerics.jitcache import announce_compile, drop_stale_cache
from washbench.perception.sections import sections_init, sections_step
from washbench.perception.vestibular import VestibularModel

PLATFORM_SAT = tuple(SAT_KINDS.index(k) for k in ("pos", "vel", "acc", "rate", "angacc"))
"""Indices of the platform's own limits among the saturation kinds (the tilt-rate and rotational limits are the
washout's)."""

_DEG = 180.0 / math.pi


@njit(cache=True)
def _account(k, row, ob, ophi, oss, cb, cphi, css, xo, xc, u_prev, ac_perceived, acc, felt, band, fa, allow):
    """Sample k of one candidate: its output ``row`` through the vestibular models into the DOF accumulators
    ``acc`` (6, NACC) and the felt error's ``felt`` (6, NFELT) (dead bands ``band`` (6,)) and, in ``felt[:3,
    NFELT]``, the jolts against the aircraft's head specific force ``fa`` (N, 3) (``allow`` = J_T dt); returns 1 if
    a platform limit was active at this sample."""
    if k == 0:
        for j in range(3):
            sections_init(oss, xo[j], row[O_HEAD_F + j])
            sections_init(css, xc[j], row[O_HEAD_OMEGA + j])
            u_prev[j] = row[O_HEAD_F + j]
            u_prev[3 + j] = row[O_HEAD_OMEGA + j]
    for j in range(3):
        u = row[O_HEAD_F + j]
        y = sections_step(ob, ophi, xo[j], u_prev[j], u)
        if k > 0:
            felt[j, NFELT] += jolt_step(u, u_prev[j], fa[k, j], fa[k - 1, j], allow)
        u_prev[j] = u
        x = ac_perceived[k, j]
        acc_update(acc[j], x, y)
        felt_update(felt[j], x, y, band[j], cue_sign(x, ac_perceived[0, j], band[j]), ac_perceived[0, j])
    for j in range(3):
        u = row[O_HEAD_OMEGA + j]
        y = sections_step(cb, cphi, xc[j], u_prev[3 + j], u)
        u_prev[3 + j] = u
        x = ac_perceived[k, 3 + j]
        acc_update(acc[3 + j], x, y * _DEG)
        felt_update(felt[3 + j], x, y * _DEG, band[3 + j], cue_sign(x, ac_perceived[0, 3 + j], band[3 + j]),
                    ac_perceived[0, 3 + j])  # fmt: skip
    hit = 0
    for j in PLATFORM_SAT:
        if row[O_SAT + j] != 0.0:
            hit = 1
    return hit


EVAL_CHUNK = 1024
"""Samples :func:`evaluate_batch` steps at a time through :func:`washbench.cueing.kernel.bank_block` before it
accounts for them (a candidate's rows, 1024 x NFIELDS floats, stay in the processor's cache)."""


@njit(cache=True, parallel=True)
def evaluate_batch(f, om, cfg, coef, oto, can, ac_perceived, dt, acc_out, counts_out, felt_out, band, allow):
    """Run candidates i = 0..M-1 (``cfg`` (M, NCFG), ``coef`` (M, NFILT, 9)) over f, om (N, 3), checked finite.

    ``oto`` and ``can``: (b (S, 2), phi (S,), steady (S,)) of the otolith and canal models. ``ac_perceived`` (N, 6):
    the aircraft pilot's perceived specific force (m/s^2) and angular velocity (deg/s). Writes per candidate the
    six DOF accumulators ``acc_out`` (M, 6, NACC), the felt error's ``felt_out`` (M, 6, NFELT + 1) (dead bands
    ``band`` (6,), jolts with ``allow`` = J_T dt) and ``counts_out`` (M, 8) int64: steps at each limit kind, then
    steps at any platform limit. Compiled washouts only (a Python algorithm's candidates go through
    :func:`evaluate_fields`).

    Each candidate's samples go through :func:`washbench.cueing.kernel.bank_block` (the compiled loop ``cue`` and
    the whole-trace step run, called as :func:`washbench.cueing.kernel.bank_trace` calls it, so the same compiled
    function is loaded from numba's cache, not the per-sample step compiled a second time: a first evaluation took
    18.6 s of CPU, now 8.3 s, on a loaded two-core machine), :data:`EVAL_CHUNK` samples at a time, then accounted
    sample by sample in order: the same operations in the same order as before, the same bits.
    """
    n = f.shape[0]
    ob, ophi, oss = oto
    cb, cphi, css = can
    for i in prange(cfg.shape[0]):
        if cfg[i, C_KIND] < 0.0:  # a Python algorithm: evaluate_fields
            continue
        state = np.zeros((1, NSTATE))
        counts = np.zeros((1, len(SAT_KINDS)), dtype=np.int64)
        xo = np.zeros((3, ophi.shape[0]))
        xc = np.zeros((3, cphi.shape[0]))
        u_prev = np.zeros(6)
        any_sat = 0
        for k0 in range(0, n, EVAL_CHUNK):
            k1 = min(n, k0 + EVAL_CHUNK)
            rows = np.empty((1, k1 - k0, NFIELDS))  # as bank_trace allocates it: the same compiled bank_block
            bank_block(f[k0:k1], om[k0:k1], cfg[i : i + 1], coef[i : i + 1], state, counts, rows)
            for k in range(k0, k1):
                row = rows[0, k - k0]
                any_sat += _account(k, row, ob, ophi, oss, cb, cphi, css, xo, xc, u_prev, ac_perceived, acc_out[i],
                                    felt_out[i], band, f, allow)  # fmt: skip
        for j in range(len(SAT_KINDS)):
            counts_out[i, j] = counts[0, j]
        counts_out[i, len(SAT_KINDS)] = any_sat


@njit(cache=True)
def evaluate_fields(out, oto, can, ac_perceived, acc, counts_out, felt, band, fa, allow):
    """One candidate already run (its field-major outputs ``out`` (NFIELDS, N), e.g. a Python algorithm through
    :func:`washbench.cueing.bank.cue_trace`): the same perception and accumulation as :func:`evaluate_batch`, into
    ``acc`` (6, NACC), ``felt`` (6, NFELT + 1) and ``counts_out`` (8,) int64 (``fa`` the aircraft's head specific
    force (N, 3))."""
    ob, ophi, oss = oto
    cb, cphi, css = can
    xo = np.zeros((3, ophi.shape[0]))
    xc = np.zeros((3, cphi.shape[0]))
    u_prev = np.zeros(6)
    row = np.zeros(NFIELDS)
    any_sat = 0
    for k in range(out.shape[1]):
        for j in range(NFIELDS):
            row[j] = out[j, k]
        for j in range(len(SAT_KINDS)):
            counts_out[j] += int(row[O_SAT + j] != 0.0)
        any_sat += _account(k, row, ob, ophi, oss, cb, cphi, css, xo, xc, u_prev, ac_perceived, acc, felt, band, fa,
                            allow)  # fmt: skip
    counts_out[len(SAT_KINDS)] = any_sat


@dataclass(frozen=True)
class Evaluation:
    """Results of M candidates on one flight: ``npc``, ``integral_error``, ``max_error``, ``felt_error``,
    ``felt_false`` (M, 6) and ``jolt`` (M, 3) in DOFS order (units of metrics.csv), ``score`` (M,) (the ranking
    rule's, lower is better), ``saturated_s`` (M,) and ``saturation_steps`` (M, 7) per limit kind (SAT_KINDS order)."""

    npc: np.ndarray
    integral_error: np.ndarray
    max_error: np.ndarray
    score: np.ndarray
    saturated_s: np.ndarray
    saturation_steps: np.ndarray
    felt_error: np.ndarray
    felt_false: np.ndarray
    jolt: np.ndarray

    def metric_rows(self, i: int, washout: str) -> list[MetricRow]:
        """Candidate i's six rows of metrics.csv (without the cue classification)."""
        return [
            MetricRow(washout, d, float(self.npc[i, j]), float(self.integral_error[i, j]), float(self.max_error[i, j]),
                      felt_error=float(self.felt_error[i, j]), felt_false=float(self.felt_false[i, j]),
                      jolt=float(self.jolt[i, j]) if j < 3 else math.nan)
            for j, d in enumerate(DOFS)
        ]


class FlightEvaluator:
    """One recorded flight, ready to evaluate batches of washout candidates on it.

    Built once per flight: the aircraft pilot's perception, the motion the ranking rule ``rule`` divides by, the
    vestibular models' sections. :meth:`evaluate` then costs one compiled call per batch.
    """

    def __init__(
        self, f_mps2: np.ndarray, omega_radps: np.ndarray, dt_s: float, limits: object, rule: RankRule = DEFAULT_RULE
    ) -> None:
        self.f = np.ascontiguousarray(f_mps2, dtype=np.float64)
        self.om = np.ascontiguousarray(omega_radps, dtype=np.float64)
        if self.f.ndim != 2 or self.f.shape[1] != 3 or self.om.shape != self.f.shape or len(self.f) < 2:
            raise ValueError(f"f and omega must both be (N >= 2, 3), got {self.f.shape} and {self.om.shape}")
        if not (np.isfinite(self.f).all() and np.isfinite(self.om).all()):
            raise ValueError("non-finite specific force or angular velocity")
        self.dt_s = float(dt_s)
        self.limits = limits
        model = VestibularModel(self.dt_s)
        p = model.perceive(self.f, self.om)
        self.ac_perceived = np.ascontiguousarray(np.column_stack([p.f_mps2, p.omega_radps * _DEG]))
        self.rule = rule
        self.motion = perceived_motion(p.f_mps2, p.omega_radps, self.dt_s, rule.measure)
        self.band = rule.measure.bands()
        self.allow = rule.measure.jerk_deadband_mps3 * self.dt_s
        self.oto = model.otolith.arrays()
        self.can = model.canals.arrays()

    @property
    def n(self) -> int:
        """Samples in the flight."""
        return len(self.f)

    def arrays(self, washouts: Sequence[object]) -> tuple[np.ndarray, np.ndarray]:
        """The compiled configuration and filters of the candidates (Washout objects)."""

        return build_arrays(washouts, self.limits, self.dt_s)  # type: ignore[arg-type]

    def evaluate(self, washouts: Sequence[object]) -> Evaluation:
        """Evaluate every candidate (:class:`washbench.cueing.variants.Washout`) on this flight."""
        cfg, coef = self.arrays(washouts)
        return self.evaluate_arrays(cfg, coef, washouts)

    def evaluate_arrays(self, cfg: np.ndarray, coef: np.ndarray, washouts: Sequence[object] = ()) -> Evaluation:
        """Evaluate candidates given as compiled arrays (M, NCFG), (M, NFILT, 9). A Python algorithm's rows (kind
        KIND_SETPOINT) need their ``washouts`` (the Washout objects, same order): they are run through
        :func:`washbench.cueing.bank.cue_trace` and then the same compiled perception and metrics."""
        m = cfg.shape[0]
        acc = np.zeros((m, len(DOFS), NACC))
        counts = np.zeros((m, len(SAT_KINDS) + 1), dtype=np.int64)
        felt = np.zeros((m, len(DOFS), NFELT + 1))
        python = [i for i in range(m) if cfg[i, C_KIND] < 0.0]
        if m:
            announce_compile(evaluate_batch)
            evaluate_batch(self.f, self.om, cfg, coef, self.oto, self.can, self.ac_perceived, self.dt_s, acc, counts,
                           felt, self.band, self.allow)  # fmt: skip
        if python:
            if len(washouts) != m:
                raise ValueError("a Python algorithm's candidate needs its Washout")
            for i in python:
                w = washouts[i]
                out = np.empty((NFIELDS, self.n))
                trace = cue_trace(self.f, self.om, self.dt_s, [w], None, self.limits, fields_out=out)
                del trace
                evaluate_fields(out, self.oto, self.can, self.ac_perceived, acc[i], counts[i], felt[i], self.band,
                                self.f, self.allow)  # fmt: skip
        npc = np.empty((m, len(DOFS)))
        integral = np.empty((m, len(DOFS)))
        max_error = np.empty((m, len(DOFS)))
        felt_error = np.empty((m, len(DOFS)))
        felt_false = np.empty((m, len(DOFS)))
        for i in range(m):
            for j in range(len(DOFS)):
                pc, e, mx = finish(acc[i, j], self.dt_s)
                npc[i, j] = npc_from_pc(float(pc))
                integral[i, j] = e
                max_error[i, j] = mx
                felt_error[i, j], felt_false[i, j] = felt_finish(felt[i, j], self.dt_s)
        ev = Evaluation(npc=npc, integral_error=integral, max_error=max_error, score=np.empty(m),
                        saturated_s=counts[:, -1] * self.dt_s, saturation_steps=counts[:, :-1], felt_error=felt_error,
                        felt_false=felt_false, jolt=felt[:, :3, NFELT].copy())  # fmt: skip
        for i in range(m):  # the ranking rule's value, as the ranking computes it from metrics.csv's rows
            ev.score[i] = rule_values(ev.metric_rows(i, "c"), self.motion, self.rule)[0]["c"]
        return ev


_HERE = Path(__file__).resolve().parent
_PKG = _HERE.parent
drop_stale_cache(
    __file__,
    [
        _HERE / "metric_sums.py",
        _PKG / "cueing" / "kernel.py",
        _PKG / "numerics" / "rotations.py",
        _PKG / "cueing" / "filters.py",
        _PKG / "platform" / "kinematics.py",
        _PKG / "perception" / "sections.py",
    ],
)

__all__ = ["PLATFORM_SAT", "Evaluation", "FlightEvaluator", "evaluate_batch", "evaluate_fields"]
