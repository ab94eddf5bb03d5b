"""The public cueing API: :class:`CueingBank` (streaming), :func:`cue_trace` (whole trace), :class:`WashoutTrace`.

A bank runs one or more washouts side by side on the same aircraft motion, each with its own kinematic
Atlas platform and simulator head motion. Both ways in call the same compiled step
(:mod:`washbench.cueing.kernel`), so they give identical results bit for bit.

Units and frames: inputs are the specific force at the aircraft pilot's head (aircraft body axes, m/s^2,
[0, 0, -g] at rest) and the aircraft body angular velocity (rad/s). Outputs are listed in
:data:`CueingBank.FIELDS`: platform position/velocity/acceleration (inertial NED, m, m/s, m/s^2),
attitude (body->inertial quaternion, scalar first), body angular velocity (rad/s), specific force (m/s^2)
and angular velocity (rad/s) at the simulator pilot's head in simulator body axes, omni-wheel speeds
(rad/s), the washout's set points, 0/1 saturation flags per limit kind for the step, and the tilt-coordination
rate the washout commanded (rad/s, after its tilt-rate limit; NaN for a washout outside the compiled kernel unless
it reports one: ``tilt_rate()``, :mod:`washbench.cueing.algorithm`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from washbench.cueing import filters
from washbench.cueing.algorithm import Alongside
from washbench.cueing.kernel import (
    C_ADAPT,
    C_ALPHA,
    C_AMAX,
    C_CATCH,
    C_COSMIN,
    C_DT,
    C_FREEFALL,
    C_G,
    C_GEO,
    C_GK,
    C_GP,
    C_HEAD_EULER,
    C_JAC,
    C_KHI,
    C_KIND,
    C_KLO,
    C_LA,
    C_LP_BEFORE,
    C_LV,
    C_P0,
    C_PHI,
    C_PLAT,
    C_PLO,
    C_PMAX,
    C_R,
    C_REST,
    C_RIG,
    C_ROT_SAT,
    C_SF,
    C_SW,
    C_TILT_AXIS,
    C_TILT_K,
    C_TILT_RATE,
    C_VMAX,
    C_WF,
    C_WKG,
    C_WMAX,
    C_WPG,
    C_WV,
    C_WW,
    C_WX,
    F_EULER_D,
    F_OMEGA_D,
    F_ROT_HP,
    F_TILT_LP,
    F_TRANS_HP,
    FIELDS,
    KIND_LARGE,
    KIND_SETPOINT,
    KIND_SMALL,
    KIND_UNRESTRICTED,
    NCFG,
    NFIELDS,
    NFILT,
    NSTATE,
    O_ACC,
    O_HEAD_F,
    O_HEAD_OMEGA,
    O_LEG,
    O_OMEGA,
    O_POS,
    O_Q,
    O_SAT,
    O_SP_POS,
    O_SP_Q,
    O_TILT,
    O_VEL,
    O_WHEEL,
    PLAT_HEXAPOD,
    PLAT_IDEAL,
    PLAT_RIG,
    S_COST,
    S_GK,
    S_GP,
    S_GRAD,
    S_PSP,
    S_QSP,
    SAT_KINDS,
    bank_block,
    bank_step,
    bank_trace,
    setpoint_block,
    setpoint_step,
    setpoint_trace,
)
from washbench.cueing.params import ADAPTIVE_KINDS, FILTER_STARTS, WashoutParams, check_filter_start  # noqa: F401
from washbench.cueing.setpoints import SetPointSource
from washbench.cueing.variants import Washout, as_washouts, check_platform
from washbench.errors import WashbenchError
from washbench.io.motion import DT_RANGE_S
from washbench.numerics.jitcache import announce_compile
from washbench.platform.hexapod import CATCH_UP_FRACTION, RATE_MARGIN
from washbench.platform.limits import wheel_jacobian
from washbench.platform.model import PlatformContext, PlatformModel, platform_kind
from washbench.platform.plugins import PlatformRun

_KINDS = {
    "small-angle": KIND_SMALL,
    "large-angle": KIND_LARGE,
    "unrestricted": KIND_UNRESTRICTED,
    "adaptive": KIND_SMALL,
    "adaptive-large-angle": KIND_LARGE,
    "adaptive-unrestricted": KIND_UNRESTRICTED,
}
"""Compiled kinds -> the kernel's structure; any other kind is a Python algorithm (KIND_SETPOINT)."""


def _check_dt(dt_s: float) -> float:
    dt = float(dt_s)
    lo, hi = DT_RANGE_S
    if not (math.isfinite(dt) and lo <= dt <= hi):
        raise WashbenchError(f"time step must be a positive number of seconds, {lo:g}..{hi:g} s, got {dt_s!r}")
    return dt


def _off(limit: float | None) -> float:
    """A limit in deg/s as rad/s; ``None`` (off) as infinity."""
    return math.inf if limit is None else math.radians(limit)


def washout_arrays(washout: Washout, limits: PlatformModel, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One washout's row of the compiled configuration (NCFG,) and its discretised filters (NFILT, 9), all SI.

    ``dt`` (s) is already checked (:func:`_check_dt`).
    """
    params, kind = washout.params, _KINDS.get(washout.kind, KIND_SETPOINT)
    cfg = np.zeros(NCFG)
    cfg[C_KIND] = kind
    cfg[C_DT] = dt
    cfg[C_G] = params.gravity_mps2
    cfg[C_SF] = params.scale.specific_force
    cfg[C_SW] = params.scale.angular_velocity
    cfg[C_TILT_K] = params.tilt.gain_per_s
    cfg[C_TILT_RATE] = _off(params.tilt.rate_limit_degps)
    cfg[C_TILT_AXIS] = 1.0 if params.tilt.rate_limit_mode == "axis" else 0.0
    cfg[C_ROT_SAT] = _off(params.rotational.saturation_degps)
    cfg[C_COSMIN] = params.small_angle.min_cos_pitch
    cfg[C_FREEFALL] = params.free_fall_threshold_mps2
    cfg[C_R : C_R + 3] = params.head.offset_m
    _platform_cfg(cfg, limits)
    # the paper's choices ("auto"): small-angle filters the tilt rate after the cross product and estimates the
    # head rate from Euler angles (Eq. 8); the quaternion washouts filter f before it and difference quaternions
    position = params.tilt.lowpass_position
    before = position == "before_cross_product" or (position == "auto" and kind != KIND_SMALL)
    cfg[C_LP_BEFORE] = 1.0 if before else 0.0
    method = params.head.rate_method
    cfg[C_HEAD_EULER] = 1.0 if method == "euler_estimator" or (method == "auto" and kind == KIND_SMALL) else 0.0
    if washout.kind in ADAPTIVE_KINDS:
        _adaptive_cfg(cfg, washout)

    coef = np.zeros((NFILT, filters.NCOEF))
    for j, wn in enumerate(params.translational_highpass_wn_radps.xyz):
        coef[F_TRANS_HP + j] = filters.discretise(filters.translational_highpass(wn), dt)
    derivative = filters.discretise(filters.derivative_estimator(params.head.derivative_wn_radps), dt)
    coef[F_EULER_D : F_EULER_D + 3] = derivative
    coef[F_OMEGA_D : F_OMEGA_D + 3] = derivative
    lp = params.tilt.lowpass_wn_radps
    rot = params.rotational.highpass_wn_radps
    # on f (before the cross product) the low-pass filters f_x, f_y, f_z with the surge, sway, heave wn; on the
    # tilt rate (after it) the roll rate is made by f_y (sway wn), the pitch rate by f_x (surge wn), yaw: heave wn
    tilt_wn = (lp.x, lp.y, lp.z) if before else (lp.y, lp.x, lp.z)
    rot_wn = (0.0, 0.0, 0.0) if kind == KIND_UNRESTRICTED else (rot.roll, rot.pitch, rot.yaw)
    for j in range(3):
        coef[F_TILT_LP + j] = filters.discretise(filters.tilt_lowpass(tilt_wn[j]), dt)
        coef[F_ROT_HP + j] = filters.discretise(filters.rotational_highpass(rot_wn[j]), dt)
    return cfg, coef


def _platform_cfg(cfg: np.ndarray, platform: PlatformModel) -> None:
    """The platform's kind, limits and geometry into a configuration row (SI)."""
    kind = platform_kind(platform)
    if kind == "hexapod":
        cfg[C_PLAT] = PLAT_HEXAPOD
        geo = platform.geometry()  # type: ignore[union-attr]
        cfg[C_GEO : C_GEO + len(geo)] = geo
        cfg[C_LV] = platform.leg_velocity_limit_mps * (1.0 - RATE_MARGIN)  # type: ignore[union-attr]
        cfg[C_LA] = platform.leg_acceleration_limit_mps2 * (1.0 - RATE_MARGIN)  # type: ignore[union-attr]
        cfg[C_CATCH] = CATCH_UP_FRACTION
        return
    if kind not in ("atlas", "hexapod", "rig"):  # a plugin's: the washout's pass (its set points) tracked ideally
        cfg[C_PLAT] = PLAT_IDEAL
        return
    if kind == "rig":
        cfg[C_PLAT] = PLAT_RIG
        cfg[C_RIG : C_RIG + 12] = platform.limits_array()  # type: ignore[union-attr]
        cfg[C_CATCH] = platform.catch_up_fraction  # type: ignore[union-attr]
        return
    lim = platform.translation  # type: ignore[union-attr]
    cfg[C_PMAX : C_PMAX + 3] = lim.position_limit_m.xyz
    cfg[C_VMAX : C_VMAX + 3] = lim.velocity_limit_mps.xyz
    cfg[C_AMAX : C_AMAX + 3] = lim.acceleration_limit_mps2.xyz
    cfg[C_WMAX] = math.radians(platform.rotation.rate_limit_degps)  # type: ignore[union-attr]
    cfg[C_ALPHA] = math.radians(platform.rotation.acceleration_limit_degps2)  # type: ignore[union-attr]
    cfg[C_CATCH] = platform.rotation.catch_up_fraction  # type: ignore[union-attr]
    cfg[C_JAC : C_JAC + 9] = wheel_jacobian(platform).ravel()  # type: ignore[arg-type]


def _adaptive_cfg(cfg: np.ndarray, washout: Washout) -> None:
    """The adaptive washout's rates, weights and bounds into its configuration row (checked consistent)."""
    params = washout.params
    a = params.adaptive
    p, k = a.translational_gain, a.tilt_gain_per_s
    where = f"washout {washout.name}: adaptive"
    if not p.min <= p.initial <= p.max:
        raise WashbenchError(
            f"{where}.translational_gain: need min <= initial <= max, got {p.min}, {p.initial}, {p.max}"
        )
    if not k.min <= params.tilt.gain_per_s <= k.max or k.min <= 0.0:
        raise WashbenchError(
            f"{where}.tilt_gain_per_s: need 0 < min <= tilt.gain_per_s ({params.tilt.gain_per_s}) <= max, "
            f"got {k.min}..{k.max}"
        )
    cfg[C_ADAPT] = 1.0
    cfg[C_GP] = a.rate_translational
    cfg[C_GK] = a.rate_tilt
    cfg[C_WF] = a.weight_specific_force
    cfg[C_WW] = a.weight_angular_velocity
    cfg[C_WX] = a.weight_position
    cfg[C_WV] = a.weight_velocity
    cfg[C_WPG] = a.weight_gain_translational
    cfg[C_WKG] = a.weight_gain_tilt
    cfg[C_P0] = p.initial
    cfg[C_PLO] = p.min
    cfg[C_PHI] = p.max
    cfg[C_KLO] = k.min
    cfg[C_KHI] = k.max


def build_arrays(
    washouts: Sequence[Washout], limits: PlatformModel, dt: float, filter_start: str = "steady"
) -> tuple[np.ndarray, np.ndarray]:
    """The compiled bank's configuration (n, NCFG) and filters (n, NFILT, 9) for checked washouts and dt.

    ``filter_start``: the start state of every washout (:data:`FILTER_STARTS`). A washout that cannot drive the
    platform is refused (:func:`check_platform`)."""
    check_platform(washouts, limits)
    rows = [washout_arrays(w, limits, dt) for w in washouts]
    cfg = np.stack([r[0] for r in rows])
    cfg[:, C_REST] = 1.0 if check_filter_start(filter_start) == "rest" else 0.0
    return cfg, np.stack([r[1] for r in rows])


@dataclass(frozen=True)
class WashoutTrace:
    """Everything one washout did over a recording (N samples), float64 arrays.

    pos_m, vel_mps, acc_mps2 (N, 3): platform translation, inertial NED. q (N, 4): platform attitude,
    body->inertial, scalar first. omega_radps (N, 3): platform body angular velocity. head_f_mps2,
    head_omega_radps (N, 3): simulator pilot-head specific force and angular velocity, simulator body axes.
    wheel_radps (N, 3): the Atlas's omni-wheel speeds ((N, 0) on another platform). sp_pos_m (N, 3), sp_q (N, 4):
    the washout's set points. saturated: limit kind -> bool (N,) (kinds in ``SAT_KINDS``); saturation_counts: kind
    -> steps at it. leg_m (N, 6): a hexapod's leg lengths, m ((N, 0) on another platform). tilt_rate_radps (N,): the
    tilt-coordination rate the washout commanded, after its tilt-rate limit and measured as that limit measures it
    (the norm, or the largest axis with ``rate_limit_mode: axis``; the ``mpc`` washout: the larger of its roll and
    pitch tilt rates), rad/s; NaN where the bench knows none (a washout outside the compiled kernel that reports none:
    the references, the bound, ``optimal``, ``mpc-unrestricted``).
    """

    pos_m: np.ndarray
    vel_mps: np.ndarray
    acc_mps2: np.ndarray
    q: np.ndarray
    omega_radps: np.ndarray
    head_f_mps2: np.ndarray
    head_omega_radps: np.ndarray
    wheel_radps: np.ndarray
    sp_pos_m: np.ndarray
    sp_q: np.ndarray
    saturated: dict[str, np.ndarray]
    saturation_counts: dict[str, int]
    leg_m: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    tilt_rate_radps: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @classmethod
    def from_rows(cls, rows: np.ndarray, copy: bool = True, platform: str = "atlas") -> WashoutTrace:
        """Build from output rows (N, N_FIELDS) of :meth:`CueingBank.step` for one washout (columns copied, or
        with ``copy=False`` views into ``rows``: valid only as long as ``rows`` is not overwritten); ``platform``:
        the platform's kind (which of its own fields the trace has)."""
        rows = np.asarray(rows, dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != NFIELDS:
            raise ValueError(f"rows must have shape (N, {NFIELDS}), got {rows.shape}")

        def cols(start: int, n: int) -> np.ndarray:
            view = rows[:, start : start + n]
            return np.ascontiguousarray(view) if copy else view

        saturated = {k: rows[:, O_SAT + j] != 0.0 for j, k in enumerate(SAT_KINDS)}
        return cls._build(cols, saturated, platform)

    @classmethod
    def from_fields(cls, block: np.ndarray, platform: str = "atlas") -> WashoutTrace:
        """Build from a field-major block (N_FIELDS, N) of one washout (no copy: the arrays are views, (N, k)
        in column-major order, each column contiguous)."""
        if block.ndim != 2 or block.shape[0] != NFIELDS:
            raise ValueError(f"block must have shape ({NFIELDS}, N), got {block.shape}")

        def cols(start: int, n: int) -> np.ndarray:
            return block[start : start + n].T

        saturated = {k: block[O_SAT + j] != 0.0 for j, k in enumerate(SAT_KINDS)}
        return cls._build(cols, saturated, platform)

    @classmethod
    def _build(cls, cols, saturated: dict[str, np.ndarray], platform: str = "atlas") -> WashoutTrace:
        return cls(
            pos_m=cols(O_POS, 3),
            vel_mps=cols(O_VEL, 3),
            acc_mps2=cols(O_ACC, 3),
            q=cols(O_Q, 4),
            omega_radps=cols(O_OMEGA, 3),
            head_f_mps2=cols(O_HEAD_F, 3),
            head_omega_radps=cols(O_HEAD_OMEGA, 3),
            wheel_radps=cols(O_WHEEL, 3 if platform == "atlas" else 0),
            sp_pos_m=cols(O_SP_POS, 3),
            sp_q=cols(O_SP_Q, 4),
            saturated=saturated,
            saturation_counts={k: int(v.sum()) for k, v in saturated.items()},
            leg_m=cols(O_LEG, 6 if platform == "hexapod" else 0),
            tilt_rate_radps=cols(O_TILT, 1)[:, 0],
        )


_step_ready = False


def _warm_up() -> None:
    """Compile (or load from the numba cache) the streaming step once, then forbid other signatures.

    With compilation disabled, a call with an unexpected argument type raises TypeError at once instead
    of compiling a new specialisation; :meth:`CueingBank.step` then converts the inputs and retries.
    """
    global _step_ready
    _step_ready = True
    if bank_step.signatures:
        return
    announce_compile(bank_step)
    cfg = np.zeros((0, NCFG))
    bank_step(
        np.zeros(3),
        np.zeros(3),
        cfg,
        np.zeros((0, NFILT, filters.NCOEF)),
        np.zeros((0, NSTATE)),
        np.zeros((0, len(SAT_KINDS)), dtype=np.int64),
        np.zeros((0, NFIELDS)),
    )
    bank_step.disable_compile()


def warm_up_block() -> None:
    """Load (or compile) the block step :meth:`CueingBank.steps` calls, with the argument types it passes, on no
    samples: for a process that forks workers (the suite's process server), so no worker loads it again."""
    if bank_block.signatures:
        return
    announce_compile(bank_block)
    bank_block(
        np.zeros((0, 3)),
        np.zeros((0, 3)),
        np.zeros((0, NCFG)),
        np.zeros((0, NFILT, filters.NCOEF)),
        np.zeros((0, NSTATE)),
        np.zeros((0, len(SAT_KINDS)), dtype=np.int64),
        np.zeros((0, 0, NFIELDS)),
    )


class CueingBank:
    """Washouts + Atlas platform + head motion, one sample in, one row per washout out (streaming).

    ``step`` returns a (n_washouts, N_FIELDS) float64 array that is REUSED: the next call overwrites it,
    so copy it (e.g. into a preallocated buffer) if you keep it. The first call initialises every filter
    to the steady state of that sample (``filter_start="rest"``: of rest, see :data:`FILTER_STARTS`).
    ``f_mps2`` and ``omega_radps`` are best given as float64 arrays
    of shape (3,) (anything else is converted, more slowly). Non-finite input raises ValueError.

    ``future``: the whole input (f (N, 3), omega (N, 3)) when it is known before the first step (a recorded flight,
    ``washbench cue``). Washouts that need the whole recording (``whole_only``, e.g. the oracle bound) compute
    their set points from it at once and the bank then tracks them sample by sample like any other's; without
    ``future`` such a washout is refused (WashbenchError).
    """

    FIELDS: tuple[str, ...] = FIELDS
    SAT_KINDS: tuple[str, ...] = SAT_KINDS

    def __init__(
        self,
        washouts: Sequence[str | Washout],
        params: WashoutParams | None,
        limits: PlatformModel,
        dt_s: float,
        filter_start: str = "steady",
        future: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> None:
        self.specs = as_washouts(washouts, params)
        self.platform = platform_kind(limits)
        """The platform's kind (``atlas``, ``hexapod``, ``rig``): :meth:`WashoutTrace.from_rows` of its rows."""
        self.washouts = tuple(w.name for w in self.specs)
        self.dt_s = _check_dt(dt_s)
        self._cfg, self._coef = build_arrays(self.specs, limits, self.dt_s, filter_start)
        n = len(self.washouts)
        self._state = np.zeros((n, NSTATE))
        self._counts = np.zeros((n, len(SAT_KINDS)), dtype=np.int64)
        self._out = np.zeros((n, NFIELDS))
        self._py = python_sources(self.specs, limits, self.dt_s, filter_start)
        self._plugin = PluginPass(limits, len(self.washouts), self.dt_s, filter_start, self.specs)
        self._limits, self._filter_start = limits, filter_start
        self._started = False
        self._k = 0  # samples stepped so far
        self._whole = self._whole_setpoints(future)
        self._sources = self._py  # every Python washout (its report())
        self._tilted = {i: src.tilted for i, src in self._py}  # those that report a tilt rate (the row's field)
        self._py = [(i, src) for i, src in self._py if i not in self._whole]

    def _whole_setpoints(self, future: tuple[np.ndarray, np.ndarray] | None) -> dict[int, tuple[np.ndarray, ...]]:
        """index -> (start pos, start q, pos (N, 3), q (N, 4), flags (N, 2), tilt rates (N,)) of every whole-only
        washout, and, given
        the whole recording (``future``), of every Python washout with a whole-trace form (``trace()``: used for
        recorded files, as the interface promises, in :func:`cue_trace` and here alike). A washout that considers the
        others (``consider``) is told none here (a stream does not fly the others first: :func:`cue_trace` does) and
        asked its start after its trace."""
        out: dict[int, tuple[np.ndarray, ...]] = {}
        for i, src in self._py:
            if not (src.whole_only or (future is not None and src.has_trace)):
                continue
            if future is None:
                raise WashbenchError(f"washout {src.name}: needs the whole recording before its first step (a "
                                     "recorded flight), not a live or lockstep stream")  # fmt: skip
            f = np.ascontiguousarray(future[0], dtype=np.float64)
            w = np.ascontiguousarray(future[1], dtype=np.float64)
            if f.ndim != 2 or f.shape[1] != 3 or w.shape != f.shape or not len(f):
                raise ValueError(f"future: f and omega must both be (N, 3), N > 0, got {f.shape} and {w.shape}")
            if src.considers:
                src.consider(Alongside({}, flyer(self.specs[i], self._limits, self.dt_s, self._filter_start)))
                planned = src.run(f, w, whole=True)
                out[i] = (*src.start(f[0], w[0]), *planned)
                continue
            p0, q0 = src.start(f[0], w[0])
            out[i] = (p0, q0, *src.run(f, w, whole=True))
        return out

    def _whole_block(self, m: int) -> None:
        if self._k + m > len(next(iter(self._whole.values()))[2]):
            raise ValueError(f"more samples stepped ({self._k + m}) than the future given to the bank holds")

    def _start(self, f: np.ndarray, om: np.ndarray) -> None:
        """Start the Python washouts on the first sample (their start set point into the state)."""
        for i, src in self._py:
            _set_start(self._state[i], *src.start(f, om))
        for i, (p0, q0, *_) in self._whole.items():
            _set_start(self._state[i], p0, q0)
        self._started = True

    def step(self, f_mps2: np.ndarray, omega_radps: np.ndarray) -> np.ndarray:
        """Advance all washouts by one sample; return the reused (n_washouts, N_FIELDS) output array."""
        if not _step_ready:  # loaded on first use: block-only users (steps, the lockstep, cue) do not pay for it
            _warm_up()
        try:
            bank_step(f_mps2, omega_radps, self._cfg, self._coef, self._state, self._counts, self._out)
        except TypeError:
            f = np.ascontiguousarray(f_mps2, dtype=np.float64).reshape(-1)
            w = np.ascontiguousarray(omega_radps, dtype=np.float64).reshape(-1)
            bank_step(f, w, self._cfg, self._coef, self._state, self._counts, self._out)
        if self._py or self._whole:
            f = np.asarray(f_mps2, dtype=np.float64).reshape(-1)
            w = np.asarray(omega_radps, dtype=np.float64).reshape(-1)
            if not self._started:
                self._start(f, w)
            for i, src in self._py:
                pos, q, ft, fr, tilt = src.step(f, w)
                c, st = self._cfg[i], self._state[i]
                setpoint_step(pos, q, ft, fr, c, self._coef[i], st, self._counts[i], self._out[i])
                if self._tilted[i]:
                    self._out[i, O_TILT] = tilt
            if self._whole:
                self._whole_block(1)
            for i, (_, _, pos_a, q_a, fl, tilt_a) in self._whole.items():
                k = self._k
                c, st = self._cfg[i], self._state[i]
                setpoint_step(pos_a[k], q_a[k], int(fl[k, 0]), int(fl[k, 1]), c, self._coef[i], st, self._counts[i],
                              self._out[i])  # fmt: skip
                if self._tilted[i]:
                    self._out[i, O_TILT] = tilt_a[k]
        if self._plugin:
            for i in range(len(self.washouts)):
                self._plugin.rows(i, self._out[i : i + 1], self._cfg[i], self._coef[i])
        self._k += 1
        return self._out

    def steps(self, f_mps2: np.ndarray, omega_radps: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Advance all washouts by the next M samples, f and omega (M, 3); return (n_washouts, M, N_FIELDS).

        The same compiled step as :meth:`step`, looped in compiled code: a block of samples gives the same
        bits as M calls of :meth:`step`, at a fraction of the per-call cost (one dispatch per block). Calls
        of both may be mixed. Non-finite input raises ValueError. ``out``: a float64 C-contiguous array of that
        shape to fill and return (reused chunk after chunk), else a new one.
        """
        f = np.ascontiguousarray(f_mps2, dtype=np.float64)
        w = np.ascontiguousarray(omega_radps, dtype=np.float64)
        if f.ndim != 2 or f.shape[1] != 3 or w.shape != f.shape:
            raise ValueError(f"f and omega must both be (M, 3), got {f.shape} and {w.shape}")
        if not (np.isfinite(f).all() and np.isfinite(w).all()):
            raise ValueError("cueing input: non-finite specific force or angular velocity")
        shape = (len(self.washouts), f.shape[0], NFIELDS)
        if out is None:
            out = np.empty(shape)
        elif out.shape != shape or out.dtype != np.float64 or not out.flags.c_contiguous:
            raise ValueError(f"out must be a C-contiguous float64 array of shape {shape}")
        announce_compile(bank_block)
        bank_block(f, w, self._cfg, self._coef, self._state, self._counts, out)
        m = f.shape[0]
        if (self._py or self._whole) and m:
            if not self._started:
                self._start(f[0], w[0])
            for i, src in self._py:
                pos, q, flags, tilt = src.run(f, w)
                setpoint_block(pos, q, flags, self._cfg[i], self._coef[i], self._state[i], self._counts[i], out[i])
                if self._tilted[i]:
                    out[i, :, O_TILT] = tilt
            if self._whole:
                self._whole_block(m)
            k = self._k
            for i, (_, _, pos, q, flags, tilt) in self._whole.items():
                setpoint_block(np.ascontiguousarray(pos[k : k + m]), np.ascontiguousarray(q[k : k + m]),
                               np.ascontiguousarray(flags[k : k + m]), self._cfg[i], self._coef[i], self._state[i],
                               self._counts[i], out[i])  # fmt: skip
                if self._tilted[i]:
                    out[i, :, O_TILT] = tilt[k : k + m]
        if self._plugin and m:
            for i in range(len(self.washouts)):
                self._plugin.rows(i, out[i], self._cfg[i], self._coef[i])
        if m:
            self._out[:] = out[:, -1]
        self._k += m
        return out

    def adaptation(self) -> dict[str, dict[str, np.ndarray | float]]:
        """The adaptive washouts' state after the last sample: name -> ``p`` (3,) translational gains per inertial
        axis, ``k`` (3,) tilt gains per body axis (1/s), ``grad_p``, ``grad_k`` (3,) the cost's gradient the last
        step descended, ``cost`` J of the last step (docs/washouts.md)."""
        out: dict[str, dict[str, np.ndarray | float]] = {}
        for i, w in enumerate(self.specs):
            if w.kind in ADAPTIVE_KINDS:
                st = self._state[i]
                out[w.name] = {
                    "p": st[S_GP : S_GP + 3].copy(),
                    "k": st[S_GK : S_GK + 3].copy(),
                    "grad_p": st[S_GRAD : S_GRAD + 3].copy(),
                    "grad_k": st[S_GRAD + 3 : S_GRAD + 6].copy(),
                    "cost": float(st[S_COST]),
                }
        return out

    def algorithm_reports(self) -> dict[str, dict[str, float | int]]:
        """washout -> what a Python washout reports of itself so far (its algorithm's ``report()``, e.g. the MPC's
        solves, fallbacks, brakes and solver iterations; numbers only); washouts without ``report()`` are absent."""
        out: dict[str, dict[str, float | int]] = {}
        for _, src in self._sources:
            reported = src.report()
            if reported is not None:
                out[src.name] = reported
        return out

    def saturation_counts(self) -> dict[str, dict[str, int]]:
        """washout -> limit kind -> number of steps at that limit so far."""
        counts = self._plugin.counts if self._plugin else self._counts
        return {
            name: {k: int(counts[i, j]) for j, k in enumerate(SAT_KINDS)} for i, name in enumerate(self.washouts)
        }


def cue_trace(
    f_mps2: np.ndarray,
    omega_radps: np.ndarray,
    dt_s: float,
    washouts: Sequence[str | Washout],
    params: WashoutParams | None,
    limits: PlatformModel,
    filter_start: str = "steady",
    fields_out: np.ndarray | None = None,
    reports: dict[str, dict[str, float | int]] | None = None,
    motions: Mapping[str, WashoutTrace] | None = None,
    scoring: object | None = None,
) -> dict[str, WashoutTrace]:
    """Whole-trace form: run the washouts over arrays f (N, 3) m/s^2 and omega (N, 3) rad/s sampled every dt_s.

    ``washouts``: built-in names (with ``params``) or :class:`Washout` variants. Uses the same compiled step as
    :class:`CueingBank` and gives identical results. Raises WashbenchError for wrong shapes or non-finite samples
    (naming the first bad sample) and for a step outside ``washbench.io.motion.DT_RANGE_S``. Magnitudes are not
    limited here (the platform stays within its limits whatever the input); the readers refuse physically
    absurd recordings at the file edge.
    ``filter_start``: see :data:`FILTER_STARTS`. ``fields_out``: for one washout, a (N_FIELDS, N) float64 array to
    write its outputs into (the traces are views of it). ``reports``: filled with what the Python washouts report of
    themselves (:meth:`CueingBank.algorithm_reports`), when given.

    A washout that considers the others (``consider``, e.g. the bound) is cued after every other and told their
    traces: ``motions`` (washouts flown before this call on the same recording, e.g. a flight's lockstep) and those
    of this call, with ``scoring`` (how the run scores a motion, :class:`washbench.cueing.algorithm.Alongside`).
    """
    specs = as_washouts(washouts, params)
    names = [w.name for w in specs]
    dt = _check_dt(dt_s)
    f = np.ascontiguousarray(f_mps2, dtype=np.float64)
    w = np.ascontiguousarray(omega_radps, dtype=np.float64)
    if f.ndim != 2 or f.shape[1] != 3 or w.shape != f.shape:
        raise WashbenchError(f"specific force and angular velocity must both be (N, 3), got {f.shape} and {w.shape}")
    bad = ~(np.isfinite(f).all(axis=1) & np.isfinite(w).all(axis=1))
    if bad.any():
        raise WashbenchError(f"non-finite specific force or angular velocity at sample {int(np.argmax(bad))}")
    cfg, coef = build_arrays(specs, limits, dt, filter_start)
    state = np.zeros((len(names), NSTATE))
    counts = np.zeros((len(names), len(SAT_KINDS)), dtype=np.int64)
    out = np.empty((len(names), NFIELDS, f.shape[0]))
    if fields_out is not None:  # one washout's field-major outputs written where the caller wants them
        if len(names) != 1 or fields_out.shape != out.shape[1:]:
            raise ValueError("fields_out needs one washout and shape (NFIELDS, N)")
        out = fields_out[None]
    announce_compile(bank_trace)
    bank_trace(f, w, cfg, coef, state, counts, out)
    kind = platform_kind(limits)
    if len(f):
        sources = python_sources(specs, limits, dt, filter_start)
        considering = {i for i, src in sources if src.considers}
        for i, src in sorted(sources, key=lambda s: s[0] in considering):  # those that consider the others last
            if i in considering:
                flown = {**(motions or {}), **{names[j]: WashoutTrace.from_fields(out[j], kind)
                                               for j in range(len(names)) if j not in considering}}  # fmt: skip
                src.consider(Alongside(flown, flyer(specs[i], limits, dt, filter_start), scoring))
                pos, q, flags, tilt = src.run(f, w, whole=True)
                _set_start(state[i], *src.start(f[0], w[0]))
            else:
                _set_start(state[i], *src.start(f[0], w[0]))
                pos, q, flags, tilt = src.run(f, w, whole=True)
            setpoint_trace(pos, q, flags, cfg[i], coef[i], state[i], counts[i], out[i])
            if src.tilted:  # (the kernel's row has NaN: it knows no tilt rate of a set-point washout)
                out[i][O_TILT] = tilt
            reported = src.report() if reports is not None else None
            if reported is not None:
                reports[src.name] = reported
    plugin = PluginPass(limits, len(names), dt, filter_start, specs)
    if plugin and len(f):
        for i in range(len(names)):
            rows = np.ascontiguousarray(out[i].T)
            plugin.rows(i, rows, cfg[i], coef[i])
            out[i][:] = rows.T
    return {name: WashoutTrace.from_fields(out[i], kind) for i, name in enumerate(names)}


def flyer(washout: Washout, limits: PlatformModel, dt_s: float, filter_start: str = "steady"
          ) -> Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], WashoutTrace]:  # fmt: skip
    """``fly(start_pos (3,), start_q (4,), pos (N, 3), q (N, 4))`` -> the :class:`WashoutTrace` of set points flown
    from that start set point through the platform ``limits`` with ``washout``'s configuration (its head, gravity,
    the filters' start ``filter_start``): the same compiled steps, the same bits, as :func:`cue_trace` makes of a
    Python washout that returns them (a plugin's platform included)."""
    dt = _check_dt(dt_s)
    cfg, coef = build_arrays([washout], limits, dt, filter_start)
    kind = platform_kind(limits)

    def fly(start_pos: np.ndarray, start_q: np.ndarray, pos: np.ndarray, q: np.ndarray) -> WashoutTrace:
        n = len(pos)
        state = np.zeros(NSTATE)
        counts = np.zeros(len(SAT_KINDS), dtype=np.int64)
        _set_start(state, np.asarray(start_pos, dtype=np.float64), np.asarray(start_q, dtype=np.float64))
        out = np.empty((NFIELDS, n))
        setpoint_trace(np.ascontiguousarray(pos, dtype=np.float64), np.ascontiguousarray(q, dtype=np.float64),
                       np.zeros((n, 2), dtype=np.int64), cfg[0], coef[0], state, counts, out)  # fmt: skip
        plugin = PluginPass(limits, 1, dt, filter_start, [washout])
        if plugin and n:
            rows = np.ascontiguousarray(out.T)
            plugin.rows(0, rows, cfg[0], coef[0])
            out[:] = rows.T
        return WashoutTrace.from_fields(out, kind)

    return fly


def python_sources(
    specs: Sequence[Washout], limits: PlatformModel, dt: float, filter_start: str
) -> list[tuple[int, SetPointSource]]:
    """(index, source) of every washout of ``specs`` that is a Python algorithm (not compiled)."""
    return [(i, SetPointSource(w, limits, dt, filter_start)) for i, w in enumerate(specs) if w.kind not in _KINDS]


class PluginPass:
    """A plugin platform (:mod:`washbench.platform.plugins`) behind the washouts: the kernel has tracked each
    washout's set points ideally (``PLAT_IDEAL``); :meth:`rows` gives those set points to the plugin (one instance per
    washout), then runs the same compiled head-motion step on the poses it reached (its own state rows), and puts the
    washout's set points and the plugin's flags back into the rows. Empty (false) on a built-in platform."""

    def __init__(
        self, platform: PlatformModel, n: int, dt_s: float, filter_start: str, specs: Sequence[Washout]
    ) -> None:
        self.runs: list[PlatformRun] = []
        if platform_kind(platform) in ("atlas", "hexapod", "rig"):
            return
        g = specs[0].params.gravity_mps2 if specs else 9.80665
        context = PlatformContext(dt_s=dt_s, gravity_mps2=g, filter_start=filter_start)
        self.runs = [PlatformRun(platform, context) for _ in range(n)]  # type: ignore[arg-type]
        self.state = np.zeros((n, NSTATE))
        self.counts = np.zeros((n, len(SAT_KINDS)), dtype=np.int64)
        self.started = [False] * n

    def __bool__(self) -> bool:
        return bool(self.runs)

    def rows(self, i: int, rows: np.ndarray, cfg: np.ndarray, coef: np.ndarray) -> None:
        """Washout i's output rows (M, NFIELDS), C-contiguous, rewritten in place with the plugin's motion."""
        if not len(rows):
            return
        sp = rows[:, O_SP_POS : O_SP_POS + 3].copy()
        sq = rows[:, O_SP_Q : O_SP_Q + 4].copy()
        tilt = rows[:, O_TILT].copy()
        own = rows[:, O_SAT + 5 : O_SAT + 7].astype(np.int64)  # the washout's tilt-rate and rotational flags
        run = self.runs[i]
        if not self.started[i]:
            _set_start(self.state[i], *run.start(sp[0], sq[0]))
            self.started[i] = True
        pos, q, flags = run.run(sp, sq)
        setpoint_block(np.ascontiguousarray(pos), np.ascontiguousarray(q), np.ascontiguousarray(own), cfg, coef,
                       self.state[i], self.counts[i], rows)  # fmt: skip
        rows[:, O_SP_POS : O_SP_POS + 3] = sp
        rows[:, O_SP_Q : O_SP_Q + 4] = sq
        rows[:, O_TILT] = tilt
        rows[:, O_SAT : O_SAT + 5] = flags
        self.counts[i, :5] += flags.sum(axis=0)


def _number(v: object) -> float | int:
    """A reported statistic as a JSON number: a whole number as int (a count), else float."""
    x = float(v)  # type: ignore[arg-type]
    return int(x) if x.is_integer() and abs(x) < 2**53 else x


def _set_start(state: np.ndarray, pos: np.ndarray, q: np.ndarray) -> None:
    """A set-point washout's start set point into its state row."""
    state[S_PSP : S_PSP + 3] = pos
    state[S_QSP : S_QSP + 4] = q
