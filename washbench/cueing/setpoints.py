"""Running a Python washout algorithm (:mod:`washbench.cueing.algorithm`) on the bench, with its output checked.

:class:`SetPointSource` makes the algorithm from a :class:`washbench.cueing.variants.Washout`, starts it, steps it
and checks every set point it returns: a tuple (pos_m, q) of 3 and 4 finite numbers, q not zero (it is normalised
here). Anything else, or an exception raised inside the algorithm, becomes one line naming the washout, the plugin,
the step and the time (:class:`washbench.errors.WashbenchError`), so no command shows a traceback or writes a
result made of a plugin's garbage. With the set points come the algorithm's own limit flags (``flags()``, or a block
form's ``block_tilt()``) and the tilt rate it commanded (``tilt_rate()``; NaN without one), checked alike.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from washbench.cueing import registry
from washbench.cueing.algorithm import WashoutContext
from washbench.errors import WashbenchError
from washbench.io.plugin_guard import plugin_call
from washbench.io.plugin_guard import read_only as _ro
from washbench.platform.model import planning_limits


class SetPointSource:
    """One Python washout on one recording: :meth:`start`, then :meth:`step` per sample (or :meth:`trace`)."""

    def __init__(self, washout: Any, limits: Any, dt_s: float, filter_start: str) -> None:
        self.name = washout.name
        self.kind = washout.kind
        algo = registry.get(washout.kind, washout.source)
        self.source = algo.source
        params = washout.params
        section = algo.make_params(params.sections.get(washout.kind), f"washout {self.name}")
        self.context = WashoutContext(
            dt_s=dt_s,
            gravity_mps2=params.gravity_mps2,
            limits=planning_limits(limits),
            filter_start=filter_start,
            head_offset_m=tuple(params.head.offset_m),
            platform=limits,
        )
        self.dt_s = dt_s
        self.k = -1  # the step being computed (-1: start)
        where = self._where("making it")
        self.algo = plugin_call(where, lambda: algo.factory(section, self.context))

        def methods() -> tuple[bool, ...]:  # attribute look-ups run the plugin's code too (__getattr__)
            missing = [m for m in ("start", "step") if not callable(getattr(self.algo, m, None))]
            if missing:
                raise WashbenchError(f"{where}: the algorithm has no {missing[0]}() method")
            whole = registry.needs_whole(algo.factory, params.sections.get(washout.kind))
            return (*(callable(getattr(self.algo, m, None)) for m in ("flags", "trace", "steps", "tilt_rate",
                                                                         "block_tilt")), whole)  # fmt: skip

        has = plugin_call(where, methods)
        self.has_flags, self.has_trace, self.has_steps, self.has_tilt, self.has_block_tilt, whole = has
        self.whole_only = whole and self.has_trace
        self.tilted = self.has_tilt or self.has_block_tilt
        """Whether the algorithm reports the tilt rate it commanded (``tilt_rate()`` or ``block_tilt()``)."""
        self.considers = self.whole_only and plugin_call(where, lambda: callable(getattr(self.algo, "consider", None)))
        """Whether the algorithm is told the run's other motions before its trace (``consider``, an
        :class:`washbench.cueing.algorithm.Alongside`; its start is then asked after its trace)."""

    def consider(self, alongside: Any) -> None:
        """Give the algorithm ``alongside`` (:class:`washbench.cueing.algorithm.Alongside`) inside the guard."""
        plugin_call(self._where("consider()"), lambda: self.algo.consider(alongside))

    def _where(self, what: str | None = None) -> str:
        label = self.name if self.source == "built-in" else f"{self.name} ({self.source})"
        if what is None:
            what = "start" if self.k < 0 else f"step {self.k} (t = {self.k * self.dt_s:.6g} s)"
        return f"washout {label}: {what}"

    def report(self) -> dict[str, float | int] | None:
        """What the algorithm reports of itself (its ``report()``: name -> number), None without one; called and
        converted inside the guard."""

        def converted() -> dict[str, float | int] | None:
            fn = getattr(self.algo, "report", None)
            if not callable(fn):
                return None
            try:
                return {str(k): _number(v) for k, v in dict(fn()).items()}
            except (TypeError, ValueError, OverflowError) as exc:
                raise WashbenchError(f"{self._where('report()')}: not a mapping of names to numbers: {exc}") from None

        return plugin_call(self._where("report()"), converted)

    def _check(self, out: Any) -> tuple[np.ndarray, np.ndarray]:
        if not isinstance(out, tuple | list) or len(out) != 2:
            raise WashbenchError(f"{self._where()}: returned {type(out).__name__}, expected a tuple (pos_m, q)")
        try:
            pos = np.asarray(out[0], dtype=np.float64).reshape(-1)
            q = np.asarray(out[1], dtype=np.float64).reshape(-1)
        except (TypeError, ValueError) as exc:
            raise WashbenchError(f"{self._where()}: set point is not numbers: {exc}") from None
        if pos.shape != (3,) or q.shape != (4,):
            raise WashbenchError(f"{self._where()}: set point shapes {pos.shape} and {q.shape}, expected (3,) and (4,)")
        p0, p1, p2 = pos.tolist()
        q0, q1, q2, q3 = q.tolist()
        nq = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
        if not (math.isfinite(p0 + p1 + p2) and math.isfinite(nq)):
            raise WashbenchError(f"{self._where()}: set point is not finite: pos_m={pos.tolist()}, q={q.tolist()}")
        if nq < 1e-6:
            raise WashbenchError(f"{self._where()}: attitude set point q is zero")
        q /= nq
        return pos, q

    def _flags(self) -> tuple[int, int]:
        if not self.has_flags:
            return 0, 0

        def flags() -> tuple[int, int]:  # called and converted inside the guard (an array, a raising __bool__)
            out = self.algo.flags()
            try:
                a, b = out
                return int(bool(a)), int(bool(b))
            except (TypeError, ValueError) as exc:
                raise WashbenchError(f"{self._where()}: flags() returned {_shown(out)}, expected two booleans "
                                     f"(tilt, rotational): {type(exc).__name__}: {exc}") from None  # fmt: skip

        return plugin_call(f"{self._where()}: flags()", flags)

    def _tilt(self) -> float:
        """The tilt rate the algorithm commanded on the last step (its ``tilt_rate()``), rad/s; NaN without one."""
        if not self.has_tilt:
            return math.nan

        def tilt() -> float:  # called and converted inside the guard
            out = self.algo.tilt_rate()
            try:
                rate = float(out)
            except (TypeError, ValueError) as exc:
                raise WashbenchError(f"{self._where()}: tilt_rate() returned {_shown(out)}, expected a number "
                                     f"(rad/s) or NaN: {type(exc).__name__}: {exc}") from None  # fmt: skip
            if not (math.isnan(rate) or (math.isfinite(rate) and rate >= 0.0)):
                raise WashbenchError(f"{self._where()}: tilt_rate() returned {rate!r}, expected a rate >= 0 (rad/s) "
                                     "or NaN")  # fmt: skip
            return rate

        return plugin_call(f"{self._where()}: tilt_rate()", tilt)

    def start(self, f0: np.ndarray, om0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The start set point, from the first sample (or rest, with ``filter_start="rest"``)."""
        self.k = -1
        if self.context.filter_start == "rest":
            f0 = np.array([0.0, 0.0, -self.context.gravity_mps2])
            om0 = np.zeros(3)
        return plugin_call(self._where(), lambda: self._check(self.algo.start(_ro(f0), _ro(om0))))

    def step(self, f: np.ndarray, om: np.ndarray) -> tuple[np.ndarray, np.ndarray, int, int, float]:
        """The next set point, the algorithm's two limit flags and the tilt rate it commanded (rad/s, or NaN)."""
        self.k += 1
        pos, q = plugin_call(self._where(), lambda: self._check(self.algo.step(_ro(f), _ro(om))))
        return pos, q, *self._flags(), self._tilt()

    def run(self, f: np.ndarray, om: np.ndarray, whole: bool = False
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
        """Set points for samples f, om (M, 3) in order: pos (M, 3), q (M, 4), flags (M, 2) int64, tilt rates (M,)
        rad/s (NaN: none). ``whole``: these are all the samples there will be (the algorithm's ``trace`` form may then
        be used)."""
        m = f.shape[0]
        pos = np.empty((m, 3))
        q = np.empty((m, 4))
        flags = np.zeros((m, 2), dtype=np.int64)
        tilt = np.full(m, math.nan)
        if whole and self.has_trace and self.k == -1 and m > 0:
            return self._block(f, om, "trace")
        if self.has_steps and m > 0:
            return self._block(f, om, "steps")
        for i in range(m):
            pos[i], q[i], flags[i, 0], flags[i, 1], tilt[i] = self.step(f[i], om[i])
        return pos, q, flags, tilt

    def _block(self, f: np.ndarray, om: np.ndarray, method: str
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
        """The algorithm's block form: ``trace`` (the whole recording from its start) or ``steps`` (the next M
        samples from where it is), checked as :meth:`step` checks one set point; its tilt rates and tilt-rate flags
        from ``block_tilt()`` (:meth:`_block_tilt`), else NaN and zeros; no rotational flags (zeros)."""
        first = 0 if method == "trace" else self.k + 1
        self.k = first
        m = f.shape[0]
        where = self._where(method)

        def converted() -> tuple[np.ndarray, np.ndarray]:  # called and converted inside the guard
            out = getattr(self.algo, method)(_ro(f), _ro(om))
            if not isinstance(out, tuple | list) or len(out) != 2:
                raise WashbenchError(f"{where}: returned {type(out).__name__}, expected a tuple (pos_m, q)")
            try:
                return np.array(out[0], dtype=np.float64), np.array(out[1], dtype=np.float64)
            except (TypeError, ValueError) as exc:
                raise WashbenchError(f"{where}: set points are not numbers: {exc}") from None

        pos, q = plugin_call(where, converted)
        if pos.shape != (m, 3) or q.shape != (m, 4):
            raise WashbenchError(f"{where}: set point shapes {pos.shape} and {q.shape}, expected ({m}, 3) and ({m}, 4)")
        bad = ~(np.isfinite(pos).all(axis=1) & np.isfinite(q).all(axis=1))
        norms = np.sqrt((q * q).sum(axis=1))
        bad |= ~(norms >= 1e-6)
        if bad.any():
            self.k = first + int(np.argmax(bad))
            raise WashbenchError(f"{self._where()}: set point is not finite or q is zero")
        self.k = first + m - 1
        flags = np.zeros((m, 2), dtype=np.int64)
        tilt = np.full(m, math.nan)
        if self.has_block_tilt:
            tilt[:], flags[:, 0] = self._block_tilt(m, method)
        return pos, q / norms[:, None], flags, tilt

    def _block_tilt(self, m: int, method: str) -> tuple[np.ndarray, np.ndarray]:
        """The tilt rates (M,) rad/s and tilt-rate flags (M,) 0/1 of the last block form call (``block_tilt()``),
        checked: M rates each NaN or finite >= 0, M flags."""
        where = self._where(f"block_tilt() after {method}")

        def converted() -> tuple[np.ndarray, np.ndarray]:  # called and converted inside the guard
            out = self.algo.block_tilt()
            try:
                rate, at = out
                rate = np.array(rate, dtype=np.float64)
                at = np.array(at, dtype=bool).astype(np.int64)
            except (TypeError, ValueError) as exc:
                raise WashbenchError(f"{where}: returned {_shown(out)}, expected (tilt rates (M,), flags (M,)): "
                                     f"{type(exc).__name__}: {exc}") from None  # fmt: skip
            if rate.shape != (m,) or at.shape != (m,):
                raise WashbenchError(f"{where}: shapes {rate.shape} and {at.shape}, expected ({m},) and ({m},)")
            bad = ~(np.isnan(rate) | (np.isfinite(rate) & (rate >= 0.0)))
            if bad.any():
                raise WashbenchError(f"{where}: tilt rate {rate[np.argmax(bad)]!r} at its sample "
                                     f"{int(np.argmax(bad))}, expected a rate >= 0 (rad/s) or NaN")  # fmt: skip
            return rate, at

        return plugin_call(where, converted)


def _number(v: object) -> float | int:
    """A reported statistic as a JSON number: a whole number as int (a count), else float."""
    x = float(v)  # type: ignore[arg-type]
    return int(x) if x.is_integer() and abs(x) < 2**53 else x


def _shown(value: Any) -> str:
    """``repr(value)`` shortened to 60 characters (``...`` if its ``__repr__`` raises)."""
    try:
        text = repr(value)
    except Exception:
        return "..."
    return text if len(text) <= 60 else text[:57] + "..."


__all__ = ["SetPointSource"]
