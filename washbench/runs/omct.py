"""``washbench omct``: the Objective Motion Cueing Test of each washout; omct.csv, Bode plots, report.md.

A list of :class:`washbench.cueing.variants.Washout` (name, kind, parameters) drives it, so a built-in washout
and a variant (``--variant``, a ``variants:`` section of ``--params``) go through the same code. For every test
and frequency the input is generated once (:func:`washbench.analysis.omct.input_spec`, the same sine
``washbench signal`` writes) and all washouts run on it in ONE ``washbench.cueing.cue_trace`` call, side by side
as the compiled bank runs them. The analysis is :mod:`washbench.analysis.omct`.

Perceived motion (the issue's "beyond the standard"): the vestibular models are linear, so at the test
frequency the perceived response is the model's own discrete frequency response at the run's step
(:func:`washbench.analysis.omct.discrete_frequency_response` of the discretised sections that
``washbench cue`` applies) times the measured head response; the aircraft pilot's likewise, from the
aircraft's own motion. This is the periodic steady state of those filters without the canal's 30 s
adaptation transient to wait for (checked against filtering a long sine in the tests).
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from washbench.analysis import omct
from washbench.analysis.omct_boundaries import BoundaryFile
from washbench.analysis.signals import SignalSpec, amplitude_unit, canonical_axis, generate
from washbench.cueing import registry
from washbench.cueing.variants import Washout, check_platform, default_on, select_washouts
from washbench.errors import WashbenchError, printable
from washbench.io import cost
from washbench.io.atomic import write_text_atomic
from washbench.io.budget import check_samples
from washbench.io.csv_numbers import csv_number
from washbench.io.motion_file import write_motion
from washbench.io.outfolder import result_set
from washbench.io.progress import Progress
from washbench.io.result_files import REPORT_FILE
from washbench.io.yamlio import load_yaml_model
from washbench.perception.vestibular import VestibularModel, VestibularParams
from washbench.platform.model import PlatformModel, load_platform_model, platform_kind
from washbench.review.bode import write_bode_plots
from washbench.review.omct_report import report_text

CSV_FILE = "omct.csv"
CSV_COLUMNS: tuple[str, ...] = (
    "washout", "test", "input", "output", "frequency_radps", "amplitude", "amplitude_unit", "gain", "phase_deg",
    "linear", "distortion", "saturated", "gain_inside", "phase_inside",
    "perceived_gain", "perceived_phase_deg", "aircraft_perceived_gain", "aircraft_perceived_phase_deg",
    "estimator_gain", "estimator_phase_deg",
)  # fmt: skip


@dataclass(frozen=True)
class OmctPoint:
    """One test of one washout at one frequency. Phases in degrees, continuous along frequency.

    ``gain``/``phase_deg``: the platform's own motion at the pilot's head
    (:func:`washbench.analysis.omct.platform_head_motion`). ``estimator_*``: the same test on the head motion
    ``washbench cue`` estimates (the paper's Eq. 8 derivative estimator for the small-angle washout, the quaternion
    difference of Eqs. 18-19 for the others), shown for comparison only, never the test's result.
    ``saturated``: limit kinds that bound during the run; ``gain_inside``/``phase_inside``: None where no
    boundary covers the point; ``*_phase_deg``: NaN where the gain is 0 (the aircraft pilot of a tilt test).
    """

    washout: str
    test: str
    input: str
    output: str
    frequency_radps: float
    amplitude: float
    amplitude_unit: str
    gain: float
    phase_deg: float
    linear: bool
    distortion: float
    saturated: tuple[str, ...]
    gain_inside: bool | None
    phase_inside: bool | None
    perceived_gain: float
    perceived_phase_deg: float
    aircraft_perceived_gain: float
    aircraft_perceived_phase_deg: float
    estimator_gain: float = math.nan
    estimator_phase_deg: float = math.nan


@dataclass(frozen=True)
class OmctSettings:
    """How the runs were made: sample rate [Hz], settle time [s], slowest decay [1/s], amplitude scale."""

    rate_hz: float
    settle_s: float
    slowest_decay_radps: float
    amplitude_scale: float = 1.0


def _phase(h: complex) -> float:
    return math.degrees(math.atan2(h.imag, h.real)) if h != 0 else math.nan


def slowest_decay(entries: Sequence[Washout]) -> float:
    """The slowest linearised decay rate [1/s] over the washouts (one settle time for all, same input)."""
    rates = []
    for e in entries:
        p = e.params
        rot = p.rotational.highpass_wn_radps
        rates.append(
            omct.slowest_decay_radps(
                e.kind,
                p.tilt.gain_per_s,
                (rot.roll, rot.pitch, rot.yaw),
                p.translational_highpass_wn_radps.xyz,
                p.tilt.lowpass_wn_radps.xyz,
                p.head.derivative_wn_radps,
            )
        )
    return min(rates)


def measure(
    entries: Sequence[Washout],
    limits: PlatformModel,
    rate_hz: float = 120.0,
    tests: Sequence[omct.OmctTest] = omct.TESTS,
    frequencies_radps: Sequence[float] = omct.FREQUENCIES_RADPS,
    boundaries: dict[str, omct.Bounds] | None = None,
    vestibular: VestibularParams | None = None,
    amplitude_scale: float = 1.0,
    progress: bool = False,
) -> tuple[list[OmctPoint], OmctSettings]:
    """Run every test at every frequency for every washout; points ordered washout, test, frequency.

    ``progress``: show the test points done and the expected end on standard error (:mod:`washbench.io.progress`).

    ``amplitude_scale`` multiplies every input amplitude (1: the amplitudes of :func:`omct.amplitude`), to
    probe where a washout stops being linear.
    """
    from washbench.cueing import cue_trace  # deferred: numba

    if not entries:
        raise WashbenchError("no washout selected")
    if not (math.isfinite(rate_hz) and rate_hz > 0.0):
        raise WashbenchError(f"--rate-hz must be a positive number, got {rate_hz!r}")
    if not (math.isfinite(amplitude_scale) and amplitude_scale > 0.0):
        raise WashbenchError(f"--amplitude-scale must be a positive number, got {amplitude_scale!r}")
    top = max(frequencies_radps)
    if top >= math.pi * rate_hz:
        raise WashbenchError(f"--rate-hz {rate_hz}: {top:.4g} rad/s is at or above the Nyquist frequency")
    dt = 1.0 / rate_hz
    sigma = slowest_decay(entries)
    longest_s = max(omct.timing(w, sigma).duration_s for w in frequencies_radps)
    check_samples(longest_s * rate_hz * len(entries), f"--rate-hz {rate_hz:g}: {len(entries)} washout(s) x "
                  f"the longest OMCT run ({longest_s:.4g} s)")  # fmt: skip
    _estimate(entries, limits, tests, frequencies_radps, rate_hz, sigma)
    model = VestibularModel(dt, vestibular)
    raw: dict[tuple[str, str], list[tuple[float, float, str, complex, float, tuple[str, ...], complex, complex]]] = {}
    shown = Progress("omct", len(tests) * len(frequencies_radps), "test points") if progress else None
    for i, (test, w) in enumerate((t, w) for t in tests for w in frequencies_radps):
        tm = omct.timing(w, sigma)
        spec = omct.input_spec(test, w, rate_hz, tm.duration_s, amplitude_scale)
        sig = generate(spec)
        ref = omct.reference_fit(test, sig.f_mps2, sig.omega_radps, dt, w, tm.periods)
        aircraft = omct.response(test, ref, sig.f_mps2, sig.omega_radps, dt, w, tm.periods, _g(entries[0]))
        with cost.announced():  # (the runs' cost is announced once, above)
            traces = cue_trace(sig.f_mps2, sig.omega_radps, dt, entries, None, limits)
        for m in entries:
            tr = traces[m.name]
            head = omct.platform_head_motion(tr.pos_m, tr.q, tr.omega_radps, m.params.head.offset_m, dt, _g(m))
            r = omct.platform_response(test, ref, head, dt, w, tm.periods, _g(m))
            est = omct.response(test, ref, tr.head_f_mps2, tr.head_omega_radps, dt, w, tm.periods, _g(m))
            sat = omct.saturated_kinds(tr.saturation_counts)
            raw.setdefault((m.name, test.name), []).append(
                (w, spec.amplitude, amplitude_unit(test.input_axis), r.h, r.distortion, sat, aircraft.h, est.h)
            )
        if shown is not None:
            shown.update(i + 1, test.name)
    if shown is not None:
        shown.close()
    points: list[OmctPoint] = []
    for e in entries:
        for test in tests:
            points += _points(e.name, test, raw[(e.name, test.name)], model, dt, (boundaries or {}).get(test.name))
    return points, OmctSettings(rate_hz, omct.settle_time_s(sigma), sigma, amplitude_scale)


def _run_cost(entry: Washout, limits: PlatformModel, dt_s: float) -> Callable[[int], cost.Estimate] | None:
    """For a washout whose cost grows with a run's length or with its parameters (the bound; the MPC washouts), its
    cost on a run of n samples (:mod:`washbench.io.cost`); None for the others (a few microseconds a sample)."""
    if entry.kind == "bound":
        return lambda n: cost.bound(n, dt_s, with_ceiling=False)  # (OMCT computes no ceiling)
    if entry.kind not in ("mpc", "mpc-unrestricted"):
        return None
    p = registry.get(entry.kind).make_params(entry.params.sections.get(entry.kind), f"washout {entry.name}")
    horizon = cost.horizon_intervals(p.horizon_steps, p.preview_s, p.prediction_step_s)
    hexapod = platform_kind(limits) == "hexapod"
    made = cost.mpc(entry.kind, horizon, dt_s, hexapod=hexapod)
    step = cost.mpc_step_s(entry.kind, horizon, hexapod)
    return lambda n: dataclasses.replace(made, seconds=made.seconds + n * step)  # made anew for each run


def _estimate(
    entries: Sequence[Washout], limits: PlatformModel, tests: Sequence[omct.OmctTest],
    frequencies_radps: Sequence[float], rate_hz: float, sigma: float,
) -> None:  # fmt: skip
    """With a washout among ``entries`` whose cost grows with a run's length or its parameters (:func:`_run_cost`):
    what all the runs will cost, from :mod:`washbench.io.cost`'s models before any run starts; refused in one line
    when the longest run would not fit (the washouts of a run side by side, their peaks added), announced on stderr
    when it takes long."""
    dt = 1.0 / rate_hz
    costly = [(e, fn) for e in entries if (fn := _run_cost(e, limits, dt)) is not None]
    if not costly:
        return
    lengths = [round(omct.timing(w, sigma).duration_s * rate_hz) + 1 for _ in tests for w in frequencies_radps]
    longest = [fn(max(lengths)) for _, fn in costly]
    peak = max(longest, key=lambda e: e.memory_bytes)
    names = ", ".join(e.name for e, _ in costly)
    est = cost.Estimate(
        what=f"omct: washout {names}", size=f"{len(lengths)} runs, {sum(lengths):,} samples in all",
        memory_bytes=sum(e.memory_bytes for e in longest),
        seconds=sum(fn(n).seconds for _, fn in costly for n in lengths),
        peak=f"the longest run, {max(lengths):,} samples: {peak.what}, {peak.peak}",
        remedy="a lower --rate-hz, fewer washouts, or " + (peak.remedy or "smaller parameters"),
    )  # fmt: skip
    cost.check(est)


def _g(entry: Washout) -> float:
    return float(entry.params.gravity_mps2)


def _points(
    washout: str,
    test: omct.OmctTest,
    rows: list[tuple[float, float, str, complex, float, tuple[str, ...], complex, complex]],
    model: VestibularModel,
    dt: float,
    bounds: omct.Bounds | None,
) -> list[OmctPoint]:
    """One washout's points of one test, phases unwrapped along frequency, boundaries checked."""
    vest = model.canals if test.output_kind == "omega" else model.otolith
    rows = sorted(rows, key=lambda r: r[0])
    v = [omct.discrete_frequency_response(vest.b, vest.phi, r[0], dt) for r in rows]
    phase = omct.unwrap_phase_deg([_phase(r[3]) for r in rows])
    p_phase = omct.unwrap_phase_deg([_phase(vi * r[3]) for vi, r in zip(v, rows, strict=True)])
    a_phase = omct.unwrap_phase_deg([_phase(vi * r[6]) for vi, r in zip(v, rows, strict=True)])
    e_phase = omct.unwrap_phase_deg([_phase(r[7]) for r in rows])
    out = []
    for i, (w, amp, unit, h, dist, sat, h_ac, h_est) in enumerate(rows):
        gain_in, phase_in = omct.check_bounds(bounds, w, abs(h), phase[i])
        out.append(
            OmctPoint(
                washout=washout,
                test=test.name,
                input=test.input_axis,
                output=test.output_axis,
                frequency_radps=w,
                amplitude=amp,
                amplitude_unit=unit,
                gain=abs(h),
                phase_deg=phase[i],
                linear=omct.is_linear(dist, sat),
                distortion=dist,
                saturated=sat,
                gain_inside=gain_in,
                phase_inside=phase_in,
                perceived_gain=abs(v[i] * h),
                perceived_phase_deg=p_phase[i],
                aircraft_perceived_gain=abs(v[i] * h_ac),
                aircraft_perceived_phase_deg=a_phase[i],
                estimator_gain=abs(h_est),
                estimator_phase_deg=e_phase[i],
            )
        )
    return out


# ---------------------------------------------------------------- files


def _flag(x: bool | None) -> str:
    return "" if x is None else ("true" if x else "false")


def csv_text(points: Sequence[OmctPoint]) -> str:
    """omct.csv: one row per point, numbers in full precision (repr), NaN/None as empty fields."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for p in points:
        w.writerow(
            [
                p.washout, p.test, p.input, p.output, csv_number(p.frequency_radps), csv_number(p.amplitude),
                p.amplitude_unit, csv_number(p.gain), csv_number(p.phase_deg), _flag(p.linear),
                csv_number(p.distortion), ";".join(p.saturated), _flag(p.gain_inside), _flag(p.phase_inside),
                csv_number(p.perceived_gain), csv_number(p.perceived_phase_deg),
                csv_number(p.aircraft_perceived_gain), csv_number(p.aircraft_perceived_phase_deg),
                csv_number(p.estimator_gain), csv_number(p.estimator_phase_deg),
            ]
        )  # fmt: skip
    return buf.getvalue()


def load_boundaries(path: str | Path) -> BoundaryFile:
    """Read and check a boundary file; WashbenchError ``file:line: field: problem`` on bad input."""
    return load_yaml_model(Path(path), BoundaryFile)


def run_omct(
    out_dir: Path,
    washouts: Sequence[str] | None = None,
    params_path: Path | None = None,
    platform_path: Path | None = None,
    boundaries_path: Path | None = None,
    rate_hz: float = 120.0,
    amplitude_scale: float = 1.0,
    plots: bool = True,
    variants: Sequence[str] = (),
    progress: bool = False,
) -> list[OmctPoint]:
    """The ``washbench omct`` command: the washouts of ``--washout``, ``--variant`` and ``--params``.

    (:func:`washbench.cueing.variants.select_washouts`: by default the three built-in washouts.) Writes
    ``omct.csv``, ``bode_<test>.png`` (with ``plots``) and ``report.md`` into ``out_dir``; bad input raises
    WashbenchError before anything is written.
    """
    entries = select_washouts(washouts, variants, params_path)
    limits = load_platform_model(platform_path)
    if washouts is None and not variants:  # the default set: those that can drive this platform, never silently
        kept, left_out = default_on(entries, limits)
        entries = list(kept)
        if left_out:
            print(f"washbench: note: {left_out}", file=sys.stderr)
    check_platform(entries, limits)
    boundary = load_boundaries(boundaries_path) if boundaries_path is not None else None
    return run_entries(
        out_dir, entries, limits, boundary, rate_hz=rate_hz, amplitude_scale=amplitude_scale, plots=plots,
        progress=progress,
    )  # fmt: skip


def run_entries(
    out_dir: Path,
    entries: Sequence[Washout],
    limits: PlatformModel,
    boundary: BoundaryFile | None,
    rate_hz: float = 120.0,
    amplitude_scale: float = 1.0,
    plots: bool = True,
    progress: bool = False,
) -> list[OmctPoint]:
    """Measure ``entries`` and write the results (the part of :func:`run_omct` a variant list can call)."""
    out_dir = Path(out_dir)
    bounds = boundary.bounds() if boundary else None
    with result_set(out_dir, "omct") as stage:  # the whole set replaces the previous one at once
        points, settings = measure(
            entries, limits, rate_hz=rate_hz, boundaries=bounds, amplitude_scale=amplitude_scale, progress=progress
        )
        files: dict[str, str] = {}
        if plots:
            files = write_bode_plots(stage, points, boundary.bounds() if boundary else {}, [e.name for e in entries])
        write_text_atomic(stage / CSV_FILE, csv_text(points))
        write_text_atomic(stage / REPORT_FILE, report_text(points, settings, entries, boundary, files))
    n_bad = sum(1 for p in points if not p.linear)
    print(
        f"OMCT: {len(entries)} washout{'s' if len(entries) != 1 else ''} x {len({p.test for p in points})} tests x "
        f"{len({p.frequency_radps for p in points})} frequencies at {settings.rate_hz:g} Hz; "
        f"{n_bad} non-linear points"
    )
    if boundary is not None:
        n_out = sum(1 for p in points if p.gain_inside is False or p.phase_inside is False)
        print(f"  boundaries {boundary.name}: {n_out} points outside")
    wrote = f"{printable(str(out_dir / CSV_FILE))}, {printable(str(out_dir / REPORT_FILE))}"
    print(f"wrote {wrote}" + (f" and {len(files)} Bode plots" if files else ""))
    return points


def signal_command(
    kind: str,
    axis: str,
    amplitude: float,
    frequency_hz: float | None,
    duration_s: float,
    rate_hz: float,
    start_s: float,
    out: Path,
) -> int:
    """The ``washbench signal`` command: generate a test signal and write it as a ``washbench cue`` input."""
    given, axis = axis, canonical_axis(axis)  # surge/sway/heave (the metrics' names) or f_x/f_y/f_z
    spec = SignalSpec(kind, axis, amplitude, frequency_hz, duration_s, rate_hz, start_s)
    sig = generate(spec)
    write_motion(out, sig.t_s, sig.f_mps2, sig.omega_radps)
    freq = "" if frequency_hz is None or kind == "step" else f" at {frequency_hz:g} Hz"
    named = axis if given == axis else f"{given} ({axis})"
    print(
        f"wrote {printable(str(out))}: {kind} on {named}, amplitude {amplitude:g} {amplitude_unit(axis)}{freq}, "
        f"{sig.t_s.shape[0]} samples at {rate_hz:g} Hz"
    )
    return 0
