"""How the pilot model adapts to a motion condition: the optimal-control criterion (pure functions).

Rule (docs/pilot-model.md, "Adaptation"): in each condition the pilot takes the visual gain ``K_v``, the visual
lead ``T_L`` and the vestibular gain ``K_m`` that minimise

    J = var(e) + w_u var(u_eq),        u_eq = g_c u,  g_c = |j H_c(j 1)|  (the attitude rate per unit control at
                                                                           1 rad/s, so J is in rad^2 for any
                                                                           aircraft's control power)

predicted in the frequency domain (:mod:`washbench.pilot.frequency`) for the task's forcing functions, the measured
controlled element ``H_c`` and the condition's motion filter ``H_mf`` (measured, :mod:`washbench.pilot.response`),
with the perception noises of :mod:`washbench.pilot.params` (they keep ``K_m`` finite: without them only the
product ``K_m H_mf`` matters), the delays as the discrete model realises them, over stable closed loops only
(Nyquist's criterion). The delays and the neuromuscular dynamics keep their published values: pilots adapt gain and
equalisation to motion, the cited compilation found (Pool et al. 2011), while their delays are limits of
perception. Minimised from a coarse grid (100 points) with Nelder-Mead from its two best: deterministic.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from washbench.perception.vestibular import canal_tf
from washbench.pilot import frequency as fq
from washbench.pilot.multimodal import realised_delays
from washbench.pilot.params import ADAPTABLE, AdaptParams, MultimodalParams

Response = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class LoopSetting:
    """What the pilot adapts to: the forcing functions (frequencies, rad/s; amplitudes: target in rad, disturbance
    in control units), the controlled element ``plant`` and the motion filter ``motion`` (callables of frequency),
    the canal model ``canals`` (callable), the time step and the perceived motion's lag (samples)."""

    w_target: np.ndarray
    a_target: np.ndarray
    w_disturbance: np.ndarray
    a_disturbance: np.ndarray
    plant: Response
    motion: Response
    canals: Response
    dt_s: float
    motion_lag_samples: int = 1

    def path(self, w: np.ndarray) -> np.ndarray:
        """P = H_scc H_mf jw: what the canals report per unit attitude."""
        return self.canals(w) * self.motion(w) * (1j * w)

    @functools.cached_property
    def grids(self) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """(w, plant, path) on the frequencies :func:`predict` uses, computed once: the stability grid, the noise
        grid, the target's and the disturbance's frequencies."""
        out = {}
        for name, w in (
            ("stability", _STABILITY_GRID),
            ("noise", fq.noise_grid(self.dt_s, 400)),
            ("target", np.asarray(self.w_target)),
            ("disturbance", np.asarray(self.w_disturbance)),
        ):
            out[name] = (w, self.plant(w), self.path(w))
        return out

    @functools.cached_property
    def control_scale(self) -> float:
        """g_c = |j H_c(j 1)|, (rad/s) per control unit."""
        return float(abs(1j * self.plant(np.array([1.0]))[0]))


@dataclass(frozen=True)
class Prediction:
    """The model's prediction for one set of parameters: variances of the error (rad^2) and the control (control
    units^2) at the target's frequencies, the disturbance's and from the noises (the remnant), the open loops'
    crossovers at the forcing frequencies, stability and the criterion J."""

    error_target: float
    error_disturbance: float
    error_remnant: float
    control_target: float
    control_disturbance: float
    control_remnant: float
    target: fq.Crossover
    disturbance: fq.Crossover
    stable: bool
    cost: float

    @property
    def error_variance(self) -> float:
        return self.error_target + self.error_disturbance + self.error_remnant

    @property
    def control_variance(self) -> float:
        return self.control_target + self.control_disturbance + self.control_remnant


_STABILITY_GRID = np.geomspace(1e-3, 1e3, 2000)
_UPPER = {"visual_gain": 1.0e3, "lead_s": 10.0, "vestibular_gain": 1.0e3}
"""The adapted parameters' upper bounds (:class:`washbench.pilot.params.MultimodalParams`)."""
_UNSTABLE = 1e6


def _delays(p: MultimodalParams, s: LoopSetting) -> tuple[float, float]:
    nv, nm = realised_delays(p, s.dt_s)
    return nv * s.dt_s, max(nm, s.motion_lag_samples) * s.dt_s


def predict(p: MultimodalParams, s: LoopSetting, control_weight_s2: float = 0.0) -> Prediction:
    """The prediction of pilot ``p`` in setting ``s`` (module docstring; ``control_weight_s2``: w_u)."""
    delays = _delays(p, s)
    g = s.grids
    whole = fq.loop(*g["stability"][:1], p, *g["stability"][1:], delays)
    ok = fq.stable(g["stability"][0], whole.disturbance_open_loop)
    lt = fq.loop(g["target"][0], p, *g["target"][1:], delays)
    ld = fq.loop(g["disturbance"][0], p, *g["disturbance"][1:], delays)
    noise_w = g["noise"][0]
    ln = fq.loop(noise_w, p, *g["noise"][1:], delays)
    vv, vm = p.visual_noise_rad2s, p.vestibular_noise_rad2ps
    e_t = fq.sine_variance(lt.error_from_target(), s.a_target)
    e_d = fq.sine_variance(ld.error_from_disturbance(), s.a_disturbance)
    e_n = fq.noise_variance(noise_w, ln.error_from_visual_noise(), vv)
    e_n += fq.noise_variance(noise_w, ln.error_from_vestibular_noise(), vm)
    u_t = fq.sine_variance(lt.control_from_target(), s.a_target)
    u_d = fq.sine_variance(ld.control_from_disturbance(), s.a_disturbance)
    u_n = fq.noise_variance(noise_w, ln.control_from_visual_noise(), vv)
    u_n += fq.noise_variance(noise_w, ln.control_from_vestibular_noise(), vm)
    cost = e_t + e_d + e_n + control_weight_s2 * s.control_scale**2 * (u_t + u_d + u_n)
    return Prediction(
        error_target=e_t, error_disturbance=e_d, error_remnant=e_n,
        control_target=u_t, control_disturbance=u_d, control_remnant=u_n,
        target=fq.crossover(s.w_target, lt.target_open_loop),
        disturbance=fq.crossover(s.w_disturbance, ld.disturbance_open_loop),
        stable=ok, cost=cost if ok else _UNSTABLE,
    )  # fmt: skip


def adapt(p: MultimodalParams, s: LoopSetting, settings: AdaptParams) -> tuple[MultimodalParams, Prediction]:
    """The parameters the rule chooses in setting ``s`` from ``p`` (``settings.rule`` ``none``: ``p`` as it is)
    and their prediction. With no motion (the motion filter zero at every forcing frequency) ``K_m`` is 0: nothing
    to respond to."""
    w = settings.control_weight_s2
    if settings.rule == "none":
        return p, predict(p, s, w)
    names = [n for n in ADAPTABLE if n in settings.adapt]
    moving = bool(np.any(np.abs(s.motion(np.concatenate([s.w_target, s.w_disturbance]))) > 0.0))
    if not moving and "vestibular_gain" in names:
        names.remove("vestibular_gain")
        p = p.model_copy(update={"vestibular_gain": 0.0})
    if not names:
        return p, predict(p, s, w)
    scale = np.array([max(getattr(p, n), 0.05) for n in names])

    def params(x: np.ndarray) -> MultimodalParams:
        values = zip(names, x, scale, strict=True)
        return p.model_copy(update={n: float(min(abs(v) * c, _UPPER[n])) for n, v, c in values})

    def cost(x: np.ndarray) -> float:
        return predict(params(x), s, w).cost

    # a coarse grid first (the criterion can have a local minimum at K_m = 0 beside a better one), then
    # Nelder-Mead from the two best points of it
    grid = list(itertools.product(*(_GRID[n] for n in names)))
    values = np.array([cost(np.array(g) / scale) for g in grid])
    best = None
    for i in np.argsort(values, kind="stable")[:2]:
        r = minimize(cost, np.array(grid[i]) / scale + 1e-3, method="Nelder-Mead",
                     options={"xatol": 1e-4, "fatol": 1e-12, "maxiter": 600 * len(names)})  # fmt: skip
        if best is None or r.fun < best.fun:
            best = r
    chosen = params(best.x)  # type: ignore[union-attr]
    return chosen, predict(chosen, s, w)


_GRID = {
    "visual_gain": (0.5, 1.0, 2.0, 4.0, 8.0),
    "lead_s": (0.0, 0.1, 0.2, 0.4, 0.8),
    "vestibular_gain": (0.0, 0.1, 0.3, 0.9),
}
"""The coarse grid the adaptation starts from (control units per rad, s, control units per rad/s): 100 points."""


def canal_response(canals: object) -> Response:
    """The canal model of :mod:`washbench.perception.vestibular` (its ``CanalParams``) as a callable of w."""
    num, den = canal_tf(canals)  # type: ignore[arg-type]

    def h(w: np.ndarray) -> np.ndarray:
        s = 1j * np.asarray(w, dtype=float)
        return np.polyval(num, s) / np.polyval(den, s)

    return h
