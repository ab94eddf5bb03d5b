"""Vestibular models: what a pilot perceives of specific force and angular velocity.

Two linear models from the paper (Eqs. 11 and 12, after Reid and Nahon, Part 1), applied
independently to each body axis (x forward, y right, z down) of a whole trace:

* otolith (Meiry and Young), specific force ``f`` [m/s^2] -> perceived specific force [m/s^2]::

      f_hat / f = (K tau_a s + 1) / ((tau_L s + 1)(tau_S s + 1))     DC gain 1

* semicircular canals (Young and Oman), angular velocity ``omega`` [rad/s] -> perceived angular
  velocity [rad/s]::

      w_hat / w = T_L T_a s^2 / ((T_L s + 1)(T_S s + 1)(T_a s + 1))  DC gain 0

Discretisation (done once per time step ``dt``): each model is split into partial fractions
``sum_i r_i / (s - p_i)`` (its poles are real and distinct; both models are strictly proper)
and every first-order term is discretised exactly for an input that is linear between samples
(first-order hold, "triangle hold"). That is the same input assumption as
``scipy.signal.lsim``, so the discrete response equals the continuous one for the linearly
interpolated input, for any uniform ``dt`` (1/50, 1/120, 1/1000 s ...). The parallel form keeps
full precision where a direct polynomial form would not (poles within 3e-5 of z = 1 at 1 kHz,
and the canal's exact DC gain of 0).

Filters start in the steady state of the first sample (``start="steady"``): a trace that begins in level
flight (f = [0, 0, -g], omega = 0) perceives [0, 0, -g] and zero rotation from the first sample on. With
``start="rest"`` they start in the steady state of a pilot at rest (f = [0, 0, -g0], g0 = 9.80665 m/s^2,
omega = 0), the input ramping from rest to the first sample over the step before it: a recording that
begins mid-manoeuvre is then felt as a change, not as motion the pilot has long adapted to.

Optional perception thresholds (:mod:`washbench.perception.thresholds`) are applied to the
model outputs as a dead band; they are off by default.

**Telban and Cardullo** (NASA CR-2005-213747, 2005), the other choice (``--vestibular telban-cardullo``,
:data:`MODELS`): the same two forms with other values and a lead on the canal model::

      f_hat / f = (tau_A s + 1) / ((tau_L s + 1)(tau_S s + 1))            tau_A 10, tau_L 5, tau_S 0.016 s
      w_hat / w = T_L T_a s^2 (T_N s + 1) / ((T_L s + 1)(T_S s + 1)(T_a s + 1))
                                                        T_L 5.73, T_S 0.005, T_a 80, T_N 0.06 s

The canal model is then proper, not strictly proper: its direct term ``T_N / T_S`` (12) is one more section
with ``phi = 0``. The values are those of Telban and Cardullo as quoted in the motion-cueing literature that
cites them; the report itself was not available to this project (docs/fidelity.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydantic import Field

from washbench.io.units import G0_MPS2
from washbench.io.yamlio import StrictModel
from washbench.numerics.jitcache import announce_compile
from washbench.perception.svc import sickness_record
from washbench.perception.thresholds import Thresholds, apply_deadband


class OtolithParams(StrictModel):
    """Otolith model, Eq. 11: ``(K tau_a s + 1) / ((tau_L s + 1)(tau_S s + 1))``.

    Defaults are the paper's "typical values" (Reid and Nahon, Part 1).
    """

    K: float = Field(default=0.4, ge=0.0, description="lead gain [-]")
    tau_L_s: float = Field(default=5.33, gt=0.0, description="long time constant [s]")  # noqa: N815 (paper notation)
    tau_S_s: float = Field(default=0.66, gt=0.0, description="short time constant [s]")  # noqa: N815
    tau_a_s: float = Field(default=13.2, gt=0.0, description="lead time constant [s]")


class CanalParams(StrictModel):
    """Semicircular canal model, Eq. 12: ``T_L T_a s^2 (T_N s + 1) / ((T_L s + 1)(T_S s + 1)(T_a s + 1))``.

    Defaults are the paper's "typical values" (Reid and Nahon, Part 1), without lead (``T_N_s`` 0: Young-Oman).
    """

    T_L_s: float = Field(default=10.2, gt=0.0, description="long time constant [s]")
    T_S_s: float = Field(default=0.1, gt=0.0, description="short time constant [s]")
    T_a_s: float = Field(default=30.0, gt=0.0, description="adaptation time constant [s]")
    T_N_s: float = Field(default=0.0, ge=0.0, description="lead time constant [s] (Telban-Cardullo)")


class VestibularParams(StrictModel):
    """Both vestibular models and the optional perception thresholds (``None``: no dead band)."""

    otolith: OtolithParams = OtolithParams()
    canals: CanalParams = CanalParams()
    thresholds: Thresholds | None = None


MODELS: dict[str, VestibularParams] = {
    "young-meiry": VestibularParams(),
    "telban-cardullo": VestibularParams(
        otolith=OtolithParams(K=1.0, tau_L_s=5.0, tau_S_s=0.016, tau_a_s=10.0),
        canals=CanalParams(T_L_s=5.73, T_S_s=0.005, T_a_s=80.0, T_N_s=0.06),
    ),
}
"""The vestibular models ``--vestibular`` chooses (module docstring): ``young-meiry`` (the paper's Meiry-Young
otolith and Young-Oman canals, the default) and ``telban-cardullo``."""

DEFAULT_MODEL = "young-meiry"


def model_record(name: str | None) -> dict[str, object]:
    """The provenance record of a model of :data:`MODELS`: ``{"model": name, "values": its parameters}``, and of
    the motion-sickness models fed by the same head motion (``"sickness"``,
    :func:`washbench.perception.svc.sickness_record`)."""

    key = DEFAULT_MODEL if name is None else name
    return {"model": key, "values": model_params(key).model_dump(mode="json"), "sickness": sickness_record()}


def model_params(name: str | None) -> VestibularParams:
    """The parameters of a model of :data:`MODELS` (None: the default); ValueError naming the valid ones."""
    key = DEFAULT_MODEL if name is None else name
    if key not in MODELS:
        raise ValueError(f"unknown vestibular model {name!r} (valid: {', '.join(MODELS)})")
    return MODELS[key]


def otolith_tf(p: OtolithParams) -> tuple[np.ndarray, np.ndarray]:
    """Continuous otolith transfer function as (numerator, denominator) polynomial coefficients in s."""
    num = np.array([p.K * p.tau_a_s, 1.0])
    den = np.polymul([p.tau_L_s, 1.0], [p.tau_S_s, 1.0])
    return num, den


def canal_tf(p: CanalParams) -> tuple[np.ndarray, np.ndarray]:
    """Continuous semicircular canal transfer function as (numerator, denominator) coefficients in s."""
    num = np.array([p.T_L_s * p.T_a_s, 0.0, 0.0])
    if p.T_N_s > 0.0:
        num = np.polymul(num, [p.T_N_s, 1.0])
    den = np.polymul(np.polymul([p.T_L_s, 1.0], [p.T_S_s, 1.0]), [p.T_a_s, 1.0])
    return num, den


@dataclass(frozen=True)
class PartialFractions:
    """``H(s) = direct + sum_i residues[i] / (s - poles[i])`` with real, distinct, negative poles [1/s]."""

    residues: tuple[float, ...]
    poles: tuple[float, ...]
    direct: float = 0.0


def partial_fractions(num: np.ndarray, time_constants_s: tuple[float, ...]) -> PartialFractions:
    """Partial fractions of ``num(s) / prod_i (tau_i s + 1)`` (degree of ``num`` at most the number of taus; a
    proper one has the direct term ``num[0] / prod tau_i``).

    Raises ValueError if two time constants are (nearly) equal: the models then have a repeated
    pole, which this parallel form does not represent.
    """
    taus = tuple(float(t) for t in time_constants_s)
    num = np.asarray(num, dtype=np.float64)
    if len(num) > len(taus) + 1:
        raise ValueError("transfer function must be proper")
    direct = 0.0
    if len(num) == len(taus) + 1:  # proper: take out the direct term, leave a strictly proper remainder
        direct = float(num[0]) / math.prod(taus)
        num = np.polysub(num, direct * np.poly1d(np.poly([-1.0 / t for t in taus])).coeffs * math.prod(taus))[1:]
    for i, a in enumerate(taus):
        for b in taus[i + 1 :]:
            if abs(a - b) <= 1e-6 * max(a, b):
                raise ValueError(f"time constants {a} s and {b} s must differ (repeated pole)")
    poles = tuple(-1.0 / t for t in taus)
    lead = math.prod(taus)
    residues = []
    for i, p_i in enumerate(poles):
        others = math.prod(p_i - p_j for j, p_j in enumerate(poles) if j != i)
        residues.append(float(np.polyval(num, p_i)) / (lead * others))
    return PartialFractions(residues=tuple(residues), poles=poles, direct=direct)


def _foh_weights(x: float) -> tuple[float, float]:
    """Dimensionless first-order-hold weights for ``dx/dt = -a x + u`` over one step, ``x = a dt``.

    ``x[k+1] = exp(-a dt) x[k] + dt (g0 u[k] + g1 u[k+1])`` with u linear over the step.
    ``g0 + g1 = (1 - exp(-x)) / x`` and ``g1 = (x - 1 + exp(-x)) / x^2`` (series for small x,
    where the closed form loses digits to cancellation).
    """
    total = -math.expm1(-x) / x
    if x < 1e-2:
        g1 = 0.0
        term = 0.5
        n = 2
        while abs(term) > 1e-18:
            g1 += term
            n += 1
            term *= -x / n
    else:
        g1 = (x + math.expm1(-x)) / (x * x)
    return total - g1, g1


@dataclass(frozen=True)
class DiscreteModel:
    """A vestibular model discretised for one uniform time step, in parallel first-order sections.

    Section i: ``x_i[k] = phi_i x_i[k-1] + b1_i u[k] + b0_i u[k-1]`` (residue folded into b),
    output ``y[k] = sum_i x_i[k]``. Apply with :meth:`apply`.
    """

    dt_s: float
    b: tuple[tuple[float, float], ...]  # per section: (coefficient of u[k], coefficient of u[k-1])
    phi: tuple[float, ...]
    dc_gain: float
    steady: tuple[float, ...] = ()  # per section: its state for a unit constant input (its DC gain, -r/p)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The sections as the compiled core wants them: b (S, 2), phi (S,), steady (S,), float64."""
        return np.array(self.b, dtype=np.float64), np.array(self.phi), np.array(self.steady)

    @classmethod
    def from_partial_fractions(cls, pf: PartialFractions, dt_s: float) -> DiscreteModel:
        if not (dt_s > 0.0 and math.isfinite(dt_s)):
            raise ValueError(f"time step must be positive and finite, got {dt_s}")
        b, phi = [], []
        for r, p in zip(pf.residues, pf.poles, strict=True):
            a = -p
            g0, g1 = _foh_weights(a * dt_s)
            b.append((r * dt_s * g1, r * dt_s * g0))
            phi.append(math.exp(-a * dt_s))
        steady = tuple(-r / p for r, p in zip(pf.residues, pf.poles, strict=True))
        if pf.direct != 0.0:  # the direct term: a section x[k] = direct u[k] (phi 0), steady value = direct
            b.append((pf.direct, 0.0))
            phi.append(0.0)
            steady = (*steady, pf.direct)
        return cls(dt_s=dt_s, b=tuple(b), phi=tuple(phi), dc_gain=sum(steady), steady=steady)

    def start(self, u0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """State for :meth:`run`: the section states (sections, m) at rest in the steady state of the first
        sample ``u0`` (m,), and the previous input (``u0``)."""
        u0 = np.array(u0, dtype=np.float64).reshape(-1)
        return np.array(self.steady)[:, None] * u0[None, :], u0

    def run(self, u: np.ndarray, state: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        """Filter the next samples ``u`` (N, m), advancing ``state`` (from :meth:`start`) in place.

        The same compiled step as :meth:`apply`: feeding a trace in chunks gives the same bits as feeding it whole.
        """
        from washbench.perception.sections import sections_run  # deferred: numba

        announce_compile(sections_run)
        b, phi, _ = self.arrays()
        x, u_prev = state
        return sections_run(b, phi, x, u_prev, np.ascontiguousarray(u, dtype=np.float64))

    def apply(self, u: np.ndarray, start: np.ndarray | None = None) -> np.ndarray:
        """Filter ``u`` (N,) or (N, m) along axis 0, starting in the steady state of ``start`` (default ``u[0]``).

        Returns float64 of the same shape. One compiled pass per column (:mod:`washbench.perception.sections`),
        the same step the studies' evaluation kernel takes per sample.
        """
        from washbench.perception.sections import sections_apply, sections_apply_from  # deferred: numba

        announce_compile(sections_apply if start is None else sections_apply_from)
        u = np.asarray(u, dtype=np.float64)
        if u.ndim not in (1, 2) or u.shape[0] == 0:
            raise ValueError(f"expected a non-empty (N,) or (N, m) array, got shape {u.shape}")
        b, phi, steady = self.arrays()
        # C order and writable, the one array type the compiled passes are compiled for (column-major, strided and
        # read-only inputs would each compile them again after an install); the values are the same
        u2 = np.require(u if u.ndim == 2 else u.reshape(-1, 1), np.float64, ("C", "W"))
        if start is None:
            y = sections_apply(b, phi, steady, u2)
        else:
            u0 = np.ascontiguousarray(np.broadcast_to(np.asarray(start, dtype=np.float64), u2.shape[1:]))
            y = sections_apply_from(b, phi, steady, u2, u0)
        return y.reshape(u.shape)


def otolith_model(p: OtolithParams, dt_s: float) -> DiscreteModel:
    """The otolith model (Eq. 11) discretised for time step ``dt_s`` [s]."""
    num, _ = otolith_tf(p)
    return DiscreteModel.from_partial_fractions(partial_fractions(num, (p.tau_L_s, p.tau_S_s)), dt_s)


def canal_model(p: CanalParams, dt_s: float) -> DiscreteModel:
    """The semicircular canal model (Eq. 12) discretised for time step ``dt_s`` [s]."""
    num, _ = canal_tf(p)
    return DiscreteModel.from_partial_fractions(partial_fractions(num, (p.T_L_s, p.T_S_s, p.T_a_s)), dt_s)


@dataclass(frozen=True)
class Perceived:
    """Perceived motion of one pilot, body axes: ``f_mps2`` (N, 3) [m/s^2], ``omega_radps`` (N, 3) [rad/s]."""

    f_mps2: np.ndarray
    omega_radps: np.ndarray


FILTER_STARTS = ("steady", "rest")
"""Start states of the filters: the first sample's steady state, or a pilot at rest (see the module notes)."""

REST_F_MPS2 = (0.0, 0.0, -G0_MPS2)
"""Specific force of a pilot at rest, body axes [m/s^2] (standard gravity, z down)."""


class VestibularModel:
    """Both models discretised once for ``dt_s``; :meth:`perceive` applies them to whole traces."""

    def __init__(self, dt_s: float, params: VestibularParams | None = None) -> None:
        self.params = params if params is not None else VestibularParams()
        self.dt_s = float(dt_s)
        self.otolith = otolith_model(self.params.otolith, self.dt_s)
        self.canals = canal_model(self.params.canals, self.dt_s)

    def perceive(self, f_mps2: np.ndarray, omega_radps: np.ndarray, start: str = "steady") -> Perceived:
        """Perceived specific force and angular velocity for one pilot's head motion (N, 3) each.

        ``start``: ``"steady"`` (the first sample's steady state) or ``"rest"`` (:data:`FILTER_STARTS`).
        """
        f = _check_n3(f_mps2, "f_mps2")
        w = _check_n3(omega_radps, "omega_radps")
        if start not in FILTER_STARTS:
            raise ValueError(f"unknown filter start {start!r} (valid: {', '.join(FILTER_STARTS)})")
        rest = start == "rest"
        f_hat = self.otolith.apply(f, np.array(REST_F_MPS2) if rest else None)
        w_hat = self.canals.apply(w, np.zeros(3) if rest else None)
        th = self.params.thresholds
        if th is not None:
            f_hat, w_hat = apply_deadband(f_hat, w_hat, th)
        return Perceived(f_mps2=f_hat, omega_radps=w_hat)


class PerceptionStream:
    """One pilot's vestibular models fed chunk by chunk: the same bits as :meth:`VestibularModel.perceive` whole.

    The filters start in the steady state of the first sample of the first chunk, or at rest (``start="rest"``,
    :data:`FILTER_STARTS`).
    """

    def __init__(self, model: VestibularModel, start: str = "steady") -> None:
        if start not in FILTER_STARTS:
            raise ValueError(f"unknown filter start {start!r} (valid: {', '.join(FILTER_STARTS)})")
        self.model = model
        self._state: tuple[np.ndarray, np.ndarray] | None = None
        if start == "rest":
            self._state = (model.otolith.start(np.array(REST_F_MPS2)), model.canals.start(np.zeros(3)))

    def perceive(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> Perceived:
        """Perceived motion for the next samples (N, 3) each."""
        f = _check_n3(f_mps2, "f_mps2")
        w = _check_n3(omega_radps, "omega_radps")
        m = self.model
        if self._state is None:
            self._state = (m.otolith.start(f[0]), m.canals.start(w[0]))
        f_hat = m.otolith.run(f, self._state[0])
        w_hat = m.canals.run(w, self._state[1])
        th = m.params.thresholds
        if th is not None:
            f_hat, w_hat = apply_deadband(f_hat, w_hat, th)
        return Perceived(f_mps2=f_hat, omega_radps=w_hat)


def _check_n3(a: np.ndarray, name: str) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3 or a.shape[0] == 0:
        raise ValueError(f"{name} must have shape (N, 3) with N >= 1, got {a.shape}")
    return a
