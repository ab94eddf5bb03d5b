"""The ceiling: a certified lower bound on the ranking's own measure, over every motion the Atlas model can make
(on a hexapod or a rig: over that platform's relaxation, :mod:`washbench.analysis.relaxation`, whose bounds a rig
gives in closed form and a hexapod's are found numerically; docs/yardstick.md).

The ranking scores a washout by ``score = sum_d w_d E_d / M_d`` (:mod:`washbench.analysis.ranking`): ``E_d`` the
integral of |perceived error| in DOF d (trapezoid rule), ``M_d`` the aircraft pilot's own perceived motion there,
``w_d`` weights from ``M_d`` alone. The weights and ``M_d`` do not depend on the platform, and the score is a sum
over DOFs, so

    min over platform motions of score  >=  sum_d w_d min_d E_d / M_d

and each ``min_d E_d`` is bounded below by a linear programme over a **relaxation** of what the platform can do
in that DOF. A relaxation contains every head-motion trace the platform model can produce; its minimum is therefore
at most every washout's ``E_d``, whatever the washout (classical, optimal, MPC, a plugin, the bound's own replay).
The ceiling of a DOF is ``r_d = min E_d / M_d``; the ceiling of the score is ``sum_d w_d r_d``.

The relaxation of one DOF on the Atlas (docs/yardstick.md, "The ceiling", derives each line; the same rows with
another platform's bounds: :class:`washbench.analysis.relaxation.Relaxation`). Body axes (x forward, y right,
z down), inertial NED, the Atlas stage's limits per inertial axis ``p_max, v_max, a_max`` (m, m/s, m/s^2), the
sphere's rate and angular-acceleration limits ``w_max`` (rad/s), ``alpha_max`` (rad/s^2), step ``dt``:

* rotation (roll, pitch, yaw; the canal input is the head's angular velocity ``omega``, the platform's body rate):
  ``|omega_k| <= w_max``, ``|omega_k - omega_{k-1}| <= alpha_max dt`` (one component of the sphere's norm limits);
* specific force (surge, sway, heave; the otolith input is ``f = R^T (a - g_I)``): ``f_k = b_k - gamma_k`` with

  - ``gamma = R^T g_I`` (gravity in body axes): ``|gamma_k| <= g``, ``|gamma_k - gamma_{k-1}| <= 2 g sin(w_max dt
    / 2)`` (a unit vector turned by at most ``w_max dt`` per step);
  - ``b = R^T a`` (the stage's acceleration in body axes), ``V = R^T v``, ``P = R^T p``: ``|b_k| <= |a_max|``,
    ``|V_k| <= |v_max|``, ``|P_k| <= |p_max|`` (norms of the limit boxes' corners), and the stage's integrator
    in the turning frame, ``V_k = V_{k-1} + b_k dt + e_k``, ``P_k = P_{k-1} + V_k dt + d_k`` with
    ``|e_k| <= 2 sin(w_max dt / 2) |v_max|`` and ``|d_k| <= 2 sin(w_max dt / 2) |p_max|`` (what the frame's turn
    over one step can add), the stage starting centred and at rest (``P_{-1} = V_{-1} = 0``, as the model starts);
  - a head away from the sphere's centre (``r`` != 0) adds ``dw/dt x r + w x (w x r)``: a term of norm at most
    ``|r| (alpha_max + w_max^2)``;

* the vestibular model's sections (:class:`washbench.perception.vestibular.DiscreteModel`) exactly as the metrics
  apply them, started as the metrics start them (the steady state of the first sample, or a pilot at rest).

What it does not charge (so where it is loose, docs/metrics.md): tilting costs no rotational cue (gravity's
direction and the canal input are separate variables), every DOF may use the whole of gravity and of the stage,
and the turning frame's terms are bounded by the largest turn, not by the turn actually made.

The LPs are solved by PIQP (proximal interior point); the bound taken is the dual objective (weak duality: a valid
lower bound of the LP whatever the solver's last iterate), made a little smaller for its tolerance.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse

from washbench.analysis.felt import FELT_PREFIX, FeltMeasure, felt_total
from washbench.analysis.lp_rows import Rows as _Rows
from washbench.analysis.lp_rows import solve_qp as _solve_qp
from washbench.analysis.lp_rows import trapezoid as _trapezoid
from washbench.analysis.metrics import DOFS
from washbench.analysis.relaxation import Relaxation, relaxation_of
from washbench.io import cost
from washbench.io.units import G0_MPS2
from washbench.perception.vestibular import (
    DiscreteModel,
    VestibularParams,
    canal_model,
    otolith_model,
)
from washbench.platform.limits import PlatformLimits

CEILING_TOL = 1e-7
"""The interior-point solver's gap and feasibility tolerances (relative)."""

EXACT = "Exact"
"""The status of a DOF whose ceiling is 0 by a motion the relaxation holds that equals the aircraft's (no LP)."""


@dataclass(frozen=True)
class FloorTerms:
    """The felt error's terms on one DOF (:mod:`washbench.analysis.felt`): its dead band (m/s^2 or deg/s), the false
    part's weight lambda, the jolt time tau_j (s) and the jerk dead band J_T (m/s^3)."""

    band: float
    false_weight: float
    jolt_time_s: float
    jerk_deadband_mps3: float


@dataclass(frozen=True)
class Ceiling:
    """The ceiling of one flight: per DOF the least integral error any platform motion can reach (``floor``, in
    the units of ``metrics.csv``: m/s^2*s, deg) and its solver status; with ``measure``, the least of the felt
    error's terms on that DOF, ``E + lambda F + tau_j J`` (the same units; :mod:`washbench.analysis.felt`)."""

    floor: dict[str, float]
    status: dict[str, str]
    measure: FeltMeasure | None = None

    def relative(self, motion: Mapping[str, float]) -> dict[str, float]:
        """``r_d = floor_d / M_d`` (NaN where the DOF was not felt: ``M_d`` 0); with the felt error's measure, ``M_d``
        the felt motion above threshold (``felt_<dof>`` of ``motion``)."""
        key = (lambda d: FELT_PREFIX + d) if self.measure is not None else (lambda d: d)
        return {d: (self.floor[d] / motion[key(d)] if motion.get(key(d), 0.0) > 0.0 else math.nan) for d in DOFS}

    def felt_score(self, motion: Mapping[str, float]) -> float:
        """The ceiling of the felt error's score: ``sum_d floor_d / T_d`` over the felt motion's total (NaN without
        the measure)."""
        if self.measure is None:
            return math.nan
        m = np.array([float(motion[FELT_PREFIX + d]) for d in DOFS])
        return float(np.sum(np.array([self.floor[d] for d in DOFS]) / self.measure.units())) / felt_total(
            m, self.measure)


def _sections(model: DiscreteModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    b, phi, steady = model.arrays()
    return b, phi, steady


def _perception_rows(
    rows: _Rows,
    u: np.ndarray,
    x0: int,
    t0: int,
    n: int,
    model: DiscreteModel,
    reference: np.ndarray,
    scale: float,
    rest_input: float | None,
    band: float = 0.0,
    false0: int | None = None,
) -> None:
    """The model's sections driven by input variables ``u`` (indices, length n) with states at ``x0 + s n + k``,
    and ``t_k >= |scale * y_k - reference_k| - band``, ``t_k >= 0`` with ``t`` at ``t0 + k`` (the felt error's
    integrand, :mod:`washbench.analysis.felt`); with ``false0``, the false part's integrand ``v_k`` at
    ``false0 + k``: ``v_k >= -s_k (y_k - reference_0) - band`` where the aircraft's cue ``s_k`` (its sign beyond
    ``band``) is not 0, ``v_k >= |y_k - reference_0| - band`` where it is, ``v_k >= 0``."""
    b, phi, steady = _sections(model)
    ns = len(phi)
    k = np.arange(1, n)
    for s in range(ns):
        xs = x0 + s * n + np.arange(n)
        if rest_input is None:  # x_0 = steady u_0
            rows.add([(xs[:1], 1.0), (u[:1], -steady[s])], np.zeros(1), equal=True)
        else:  # from the rest state, the input ramping from rest to u_0 over the step before the first sample
            rhs = np.array([phi[s] * steady[s] * rest_input + b[s, 1] * rest_input])
            rows.add([(xs[:1], 1.0), (u[:1], -b[s, 0])], rhs, equal=True)
        rows.add([(xs[k], 1.0), (xs[k - 1], -phi[s]), (u[k], -b[s, 0]), (u[k - 1], -b[s, 1])], np.zeros(n - 1),
                 equal=True)  # fmt: skip
    t = t0 + np.arange(n)
    y_terms = [(x0 + s * n + np.arange(n), scale) for s in range(ns)]
    rows.add([*y_terms, (t, -1.0)], reference + band, equal=False)
    rows.add([*[(i, -c) for i, c in y_terms], (t, -1.0)], -reference + band, equal=False)
    if band > 0.0:
        rows.box(t, 0.0, np.inf)
    if false0 is None:
        return
    v = false0 + np.arange(n)
    rows.box(v, 0.0, np.inf)
    dx = reference - reference[0]
    s_k = np.where(np.abs(dx) > band, np.sign(dx), 0.0)
    for sign in (1.0, -1.0):  # where the aircraft's cue is s: -s y_k - v_k <= band - s x_0; where none: both signs
        sel = np.flatnonzero((s_k == -sign) | (s_k == 0.0))
        if len(sel):
            rows.add([*[(i[sel], sign * c) for i, c in y_terms], (v[sel], -1.0)],
                     np.full(len(sel), band + sign * reference[0]), equal=False)  # fmt: skip


def _solve(c: np.ndarray, rows: _Rows, nvar: int) -> tuple[float, str]:
    sol = _solve_qp(sparse.csc_matrix((nvar, nvar)), c, rows, CEILING_TOL, 200)
    status = str(sol.status)
    if status != "Solved":
        return math.nan, status
    dual = float(sol.obj_val_dual)
    # the dual objective is a lower bound of the LP; the tolerance may still leave it a hair above the optimum
    return max(0.0, dual - CEILING_TOL * max(1.0, abs(dual))), status


def _follows_exactly_rotation(w_air: np.ndarray, dt: float, relax: Relaxation, axis: int) -> bool:
    """True when the aircraft's own rate on this axis (N,) rad/s is within the relaxation's rows: the platform's head
    rate can equal it, so the least error is 0 exactly (the same model, the same start)."""
    return bool(np.all(np.abs(w_air) <= relax.rate[axis]) and np.all(np.abs(np.diff(w_air)) <= relax.rate_step))


def _follows_exactly_force(f_air: np.ndarray, dt: float, relax: Relaxation, axis: int) -> bool:
    """True when the relaxation holds a motion whose specific force on this axis equals the aircraft's (N,) m/s^2:
    gravity's component turned towards ``-f`` as fast as the rows allow, the stage making up the rest, its velocity
    and position in the turning frame pulled towards zero by as much as the turning terms allow (``e_k``, ``d_k``),
    and every row then checked. The least error is then 0 exactly."""
    lo, hi = relax.gravity_lo[axis], relax.gravity_hi[axis]
    chord = relax.chord
    a_bar, v_bar, p_bar = relax.acc[axis], relax.vel[axis], relax.pos[axis]
    ev, ep = chord * relax.vel_norm, chord * relax.pos_norm
    step = _gravity_step(relax)
    target = np.clip(-np.asarray(f_air, dtype=np.float64), lo, hi)
    gk, vk, pk = float(target[0]), 0.0, 0.0
    for k in range(len(target)):
        gk = gk + min(max(float(target[k]) - gk, -step), step)
        b = float(f_air[k]) + gk
        if abs(b) > a_bar:
            return False
        vk = vk + b * dt
        if k > 0:  # the turning terms (none on the first step from rest)
            vk -= min(max(vk, -ev), ev)
        pk = pk + vk * dt
        if k > 0:
            pk -= min(max(pk, -ep), ep)
        if abs(vk) > v_bar or abs(pk) > p_bar:
            return False
    return True


def _gravity_step(relax: Relaxation) -> float:
    """The bound on |gamma_k - gamma_{k-1}| (m/s^2, each component): gravity's norm g (the largest |gamma_z|) times
    the chord of the largest turn per sample."""
    return max(abs(relax.gravity_hi[2]), abs(relax.gravity_lo[2])) * relax.chord


def translational_floor(
    reference: np.ndarray,
    axis: int,
    dt_s: float,
    limits: PlatformLimits | Relaxation | Any,
    gravity_mps2: float,
    model: DiscreteModel,
    rest_start: bool,
    head_offset_m: float = 0.0,
    terms: FloorTerms | None = None,
    aircraft_head: np.ndarray | None = None,
) -> tuple[float, str]:
    """The least integral of |perceived specific-force error| (m/s^2*s) on body axis ``axis`` over the relaxation
    (module docstring); ``reference`` (N,) the aircraft pilot's perceived specific force on that axis, m/s^2;
    ``limits``: the platform (Atlas limits, a hexapod, a rig) or its :class:`Relaxation`. With ``terms``, the least
    of the felt error's terms on that axis instead, ``E + lambda F + tau_j J`` (:mod:`washbench.analysis.felt`; the
    jolt needs ``aircraft_head`` (N,), the aircraft pilot's head specific force on the axis, m/s^2)."""
    n = len(reference)
    dt = float(dt_s)
    relax = relaxation_of(limits, dt, gravity_mps2)
    chord = relax.chord
    a_bar = relax.acc[axis]
    v_bar, p_bar = relax.vel[axis], relax.pos[axis]
    w_max = max(relax.rate)
    o_bar = abs(head_offset_m) * (relax.ang_acc + w_max * w_max)
    ns = len(model.phi)
    names = ["f", "gam", "V", "P", "o", "t", "v", "j"] if terms is not None else ["f", "gam", "V", "P", "o", "t"]
    off = {nm: i * n for i, nm in enumerate(names)}
    x0 = len(names) * n
    nvar = x0 + ns * n
    idx = {nm: off[nm] + np.arange(n) for nm in names}
    rows = _Rows()
    k = np.arange(1, n)
    # b = f + gamma - o (the stage's acceleration in body axes)
    f, gam, vv, pp, o = idx["f"], idx["gam"], idx["V"], idx["P"], idx["o"]
    rows.box(gam, relax.gravity_lo[axis], relax.gravity_hi[axis])
    rows.box(o, -o_bar, o_bar)
    step = _gravity_step(relax)
    rows.add([(gam[k], 1.0), (gam[k - 1], -1.0)], np.full(n - 1, step), equal=False)
    rows.add([(gam[k], -1.0), (gam[k - 1], 1.0)], np.full(n - 1, step), equal=False)
    rows.add([(f, 1.0), (gam, 1.0), (o, -1.0)], np.full(n, a_bar), equal=False)
    rows.add([(f, -1.0), (gam, -1.0), (o, 1.0)], np.full(n, a_bar), equal=False)
    rows.box(vv, -v_bar, v_bar)
    rows.box(pp, -p_bar, p_bar)
    ev = chord * relax.vel_norm
    ep = chord * relax.pos_norm
    # V_k - V_{k-1} - dt b_k in [-ev, ev], V_{-1} = 0 (and its first step: the frame has not turned a moving stage)
    for sign in (1.0, -1.0):
        rows.add([(vv[k], sign), (vv[k - 1], -sign), (f[k], -sign * dt), (gam[k], -sign * dt), (o[k], sign * dt)],
                 np.full(n - 1, ev), equal=False)  # fmt: skip
        rows.add([(pp[k], sign), (pp[k - 1], -sign), (vv[k], -sign * dt)], np.full(n - 1, ep), equal=False)
    rows.add([(vv[:1], 1.0), (f[:1], -dt), (gam[:1], -dt), (o[:1], dt)], np.zeros(1), equal=True)
    start = relax.start_pos[axis]
    if start > 0.0:  # P_0 - dt V_0 = P_{-1}: the platform starts at rest where its first set point put it
        rows.add([(pp[:1], 1.0), (vv[:1], -dt)], np.full(1, start), equal=False)
        rows.add([(pp[:1], -1.0), (vv[:1], dt)], np.full(1, start), equal=False)
    else:  # from rest at neutral
        rows.add([(pp[:1], 1.0), (vv[:1], -dt)], np.zeros(1), equal=True)
    rest_input = float(np.array((0.0, 0.0, -G0_MPS2))[axis]) if rest_start else None
    band = terms.band if terms is not None else 0.0
    _perception_rows(rows, f, x0, off["t"], n, model, np.asarray(reference, dtype=np.float64), 1.0, rest_input,
                     band, off["v"] if terms is not None else None)  # fmt: skip
    c = np.zeros(nvar)
    c[idx["t"]] = _trapezoid(n, dt)
    if terms is not None:
        c[idx["v"]] = terms.false_weight * _trapezoid(n, dt)
        if terms.jolt_time_s > 0.0 and n > 1:
            if aircraft_head is None:
                raise ValueError("the jolt term needs the aircraft pilot's head specific force")
            j = idx["j"]
            rows.box(j, 0.0, np.inf)
            # j_k >= |f_k - f_{k-1}| / dt - |F_k - F_{k-1}| / dt - J_T, k >= 1 (m/s^3; j_0 unused: its cost is 0)
            allow = np.abs(np.diff(np.asarray(aircraft_head, dtype=np.float64))) / dt + terms.jerk_deadband_mps3
            for sign in (1.0, -1.0):
                rows.add([(f[k], sign / dt), (f[k - 1], -sign / dt), (j[k], -1.0)], allow, equal=False)
            c[j[1:]] = terms.jolt_time_s * dt
    return _solve(c, rows, nvar)


def rotational_floor(
    reference_radps: np.ndarray,
    dt_s: float,
    limits: PlatformLimits | Relaxation | Any,
    model: DiscreteModel,
    rest_start: bool,
    axis: int = 0,
    terms: FloorTerms | None = None,
) -> tuple[float, str]:
    """The least integral of |perceived angular-velocity error| (deg) on body axis ``axis`` over the relaxation;
    ``reference_radps`` (N,) the aircraft pilot's perceived angular velocity on that axis, rad/s. With ``terms``
    (their band in deg/s), the least of the felt error's terms on that axis, ``E + lambda F`` (deg), instead."""
    n = len(reference_radps)
    dt = float(dt_s)
    relax = relaxation_of(limits, dt, G0_MPS2)
    slack = 1.0 + 1e-9  # the platform's rounding
    w_max = relax.rate[axis] * slack
    dw = relax.rate_step * slack
    ns = len(model.phi)
    w = np.arange(n)
    t0 = n
    v0 = 2 * n if terms is not None else None
    x0 = (3 if terms is not None else 2) * n
    nvar = x0 + ns * n
    rows = _Rows()
    k = np.arange(1, n)
    rows.box(w, -w_max, w_max)
    if math.isfinite(dw):
        rows.add([(w[k], 1.0), (w[k - 1], -1.0)], np.full(n - 1, dw), equal=False)
        rows.add([(w[k], -1.0), (w[k - 1], 1.0)], np.full(n - 1, dw), equal=False)
    # solved in rad (70 interior-point iterations on the aerobatics' roll, against 95 with the error in deg), given
    # in deg as metrics.csv gives it
    band = math.radians(terms.band) if terms is not None else 0.0
    _perception_rows(rows, w, x0, t0, n, model, np.asarray(reference_radps, dtype=np.float64), 1.0,
                     0.0 if rest_start else None, band, v0)  # fmt: skip
    c = np.zeros(nvar)
    c[t0 : t0 + n] = _trapezoid(n, dt)
    if terms is not None and v0 is not None:
        c[v0 : v0 + n] = terms.false_weight * _trapezoid(n, dt)
    value, status = _solve(c, rows, nvar)
    return math.degrees(value), status


def ceiling(
    perceived_f_mps2: np.ndarray,
    perceived_omega_radps: np.ndarray,
    dt_s: float,
    limits: PlatformLimits | Relaxation | Any,
    gravity_mps2: float,
    vestibular: VestibularParams | None = None,
    filter_start: str = "steady",
    head_offset_m: tuple[float, float, float] = (0.0, 0.0, 0.0),
    f_mps2: np.ndarray | None = None,
    omega_radps: np.ndarray | None = None,
    measure: FeltMeasure | None = None,
) -> Ceiling:
    """The ceiling of a flight from the aircraft pilot's perceived motion (N, 3) each (module docstring).

    ``limits``: the platform (Atlas limits, a hexapod, a rig: :func:`washbench.analysis.relaxation.relaxation_of`)
    or its relaxation. ``f_mps2``, ``omega_radps`` (N, 3): the aircraft pilot's head motion itself, when known: a
    DOF where the relaxation holds a motion equal to it has the ceiling 0 without a programme (status ``Exact``).
    ``measure``: the ceiling of the felt error (:mod:`washbench.analysis.felt`: its terms per DOF; its jolt needs
    ``f_mps2``) instead of the integral error's.

    Raises ValueError for perception thresholds (a dead band makes the error non-convex in the head motion: the
    ceiling is not defined for them)."""
    vest = vestibular if vestibular is not None else VestibularParams()
    if vest.thresholds is not None:
        raise ValueError("the ceiling is not defined with perception thresholds (a dead band)")
    # its programmes must fit before they are built (announced with the bound, :func:`washbench.io.cost.bound`)
    cost.check(cost.ceiling(len(perceived_f_mps2), dt_s), announce=False)
    oto = otolith_model(vest.otolith, dt_s)
    can = canal_model(vest.canals, dt_s)
    rest = filter_start == "rest"
    r = math.hypot(*head_offset_m)
    relax = relaxation_of(limits, dt_s, gravity_mps2)
    floor: dict[str, float] = {}
    status: dict[str, str] = {}
    if measure is not None and f_mps2 is None and measure.jolt_time_s > 0.0:
        raise ValueError("the felt error's ceiling needs the aircraft pilot's head specific force (its jolt term)")
    bands = measure.bands() if measure is not None else np.zeros(6)

    def terms(i: int) -> FloorTerms | None:
        if measure is None:
            return None
        return FloorTerms(float(bands[i]), measure.false_weight, measure.jolt_time_s, measure.jerk_deadband_mps3)

    for axis, dof in enumerate(DOFS[:3]):
        if f_mps2 is not None and _follows_exactly_force(f_mps2[:, axis], dt_s, relax, axis):
            floor[dof], status[dof] = 0.0, EXACT
            continue
        floor[dof], status[dof] = translational_floor(
            perceived_f_mps2[:, axis], axis, dt_s, relax, gravity_mps2, oto, rest, r, terms(axis),
            f_mps2[:, axis] if f_mps2 is not None else None,
        )  # fmt: skip
    for axis, dof in enumerate(DOFS[3:]):
        if omega_radps is not None and _follows_exactly_rotation(omega_radps[:, axis], dt_s, relax, axis):
            floor[dof], status[dof] = 0.0, EXACT
            continue
        floor[dof], status[dof] = rotational_floor(perceived_omega_radps[:, axis], dt_s, relax, can, rest, axis,
                                                   terms(3 + axis))  # fmt: skip
    return Ceiling(floor=floor, status=status, measure=measure)


__all__ = ["CEILING_TOL", "EXACT", "Ceiling", "ceiling", "rotational_floor", "translational_floor"]
