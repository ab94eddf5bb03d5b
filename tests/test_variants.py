"""Washout variants and the paper's open choices as parameters: parsing, selection, errors, and what each does.

No flights: the open choices are checked on synthetic traces against independent expectations (set-point rates
from scipy's Rotation, the Eq. 8 estimator against scipy.signal.lsim).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import scipy.signal
from scipy.spatial.transform import Rotation

from washbench.cli import main
from washbench.cueing import cue_trace, load_washout_params
from washbench.cueing.variants import Washout, apply_overrides, parse_variant, select_washouts
from washbench.errors import WashbenchError
from washbench.io.paths import DATA_DIR
from washbench.platform import load_platform_limits

G = 9.80665
DT = 1.0 / 120.0
CW1 = load_washout_params()
LIMITS = load_platform_limits()


def test_parse_variant_and_dotted_keys() -> None:
    v = parse_variant(
        "sa_2=small-angle,tilt.gain_per_s=2,rotational.highpass_wn_radps.yaw=0.3,tilt.rate_limit_degps=off"
    )
    assert (v.name, v.kind) == ("sa_2", "small-angle")
    assert dict(v.overrides) == {
        "tilt.gain_per_s": 2,
        "rotational.highpass_wn_radps.yaw": 0.3,
        "tilt.rate_limit_degps": False,
    }
    p = apply_overrides(CW1, v.overrides, "--variant sa_2")
    assert p.tilt.gain_per_s == 2.0 and p.rotational.highpass_wn_radps.yaw == 0.3 and p.tilt.rate_limit_degps is None
    assert p.rotational.highpass_wn_radps.roll == CW1.rotational.highpass_wn_radps.roll  # the rest unchanged


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("a=small-angle,tilt.gainn_per_s=2", ["tilt.gainn_per_s", "did you mean 'tilt.gain_per_s'"]),
        ("a=small-angle,tilt.gain_per_s=-1", ["tilt.gain_per_s", "greater than 0"]),
        ("a=small-angle,tilt.gain_per_s=fast", ["tilt.gain_per_s", "expected a number"]),
        ("a=small-angle,tilt=2", ["tilt", "is a group"]),
        ("a=small-angle,tilt.rate_limit_mode=sideways", ["tilt.rate_limit_mode", "'norm' or 'axis'"]),
        ("a b=small-angle", ["'a b'", "letters, digits"]),
        ("a.b=small-angle", ["'a.b'", "letters, digits"]),
        ("small-angle=large-angle", ["reserved"]),
        ("aircraft=large-angle", ["reserved"]),
        ("a=medium-angle", ["unknown washout kind 'medium-angle'"]),
        ("a", ["NAME=KIND"]),
    ],
)
def test_bad_variants_are_one_line_naming_the_key(
    text: str, words: list[str], capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    flight = tmp_path / "in.csv"
    flight.write_text(
        "t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps\n"
        "0,0,0,-9.8,0,0,0\n0.01,0,0,-9.8,0,0,0\n"
    )
    assert main(["cue", str(flight), "--out", str(tmp_path / "out"), "--variant", text]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("washbench: error: --variant")
    for w in words:
        assert w in err
    assert not (tmp_path / "out").exists()


def test_selection_rules(tmp_path: Path) -> None:
    assert [w.name for w in select_washouts()] == ["small-angle", "large-angle", "unrestricted", "replay",
                                                   "replay-rotation", "still"]  # fmt: skip
    assert [w.name for w in select_washouts(["large-angle"])] == ["large-angle"]
    every = [w.name for w in select_washouts(["all"])]  # every built-in washout, the references and the bound
    assert every[:3] == ["small-angle", "large-angle", "unrestricted"] and every[-1] == "bound"
    assert {"optimal", "mpc", "mpc-unrestricted", "replay", "replay-rotation", "still"} <= set(every)
    assert len(every) == len(set(every)) == 13
    only = select_washouts(None, ["b=large-angle,tilt.gain_per_s=2"])
    assert [(w.name, w.kind) for w in only] == [("b", "large-angle")]  # with a variant, only the variants run ...
    both = select_washouts(["small-angle"], ["b=large-angle"])
    assert [w.name for w in both] == ["small-angle", "b"]  # ... plus the washouts named by --washout
    with pytest.raises(WashbenchError, match="listed twice"):
        select_washouts(None, ["b=large-angle", "b=small-angle"])
    text = (DATA_DIR / "cw1.yaml").read_text() + (
        "variants:\n"
        "  fast: {kind: large-angle, tilt.gain_per_s: 2}\n"
        "  free:\n"
        "    kind: unrestricted\n"
        "    tilt: {rate_limit_degps: off}\n"
    )
    path = tmp_path / "with_variants.yaml"
    path.write_text(text)
    got = select_washouts(None, ["cli=small-angle"], path)
    assert [(w.name, w.kind) for w in got] == [
        ("fast", "large-angle"),
        ("free", "unrestricted"),
        ("cli", "small-angle"),
    ]
    assert got[0].params.tilt.gain_per_s == 2.0 and got[1].params.tilt.rate_limit_degps is None
    assert load_washout_params(path) == CW1  # the base set is unchanged by its variants
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("tilt.gain_per_s: 2", "tilt.gain_per_s: two"))
    with pytest.raises(WashbenchError) as info:
        select_washouts(None, [], bad)
    line = text.splitlines().index("  fast: {kind: large-angle, tilt.gain_per_s: 2}") + 1
    assert str(info.value).startswith(f"{bad}:{line}: variants.fast.tilt.gain_per_s: expected a number")


def step_input(
    n: int,
    f_xy: tuple[float, float] = (0.0, 0.0),
    omega_degps: tuple[float, float, float] = (0, 0, 0),
    onset_s: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Level flight, then at onset a sustained specific-force step (m/s^2) and/or body rate (deg/s)."""
    f = np.tile([0.0, 0.0, -G], (n, 1))
    w = np.zeros((n, 3))
    k0 = int(onset_s / DT)
    f[k0:, 0], f[k0:, 1] = f_xy
    w[k0:] = np.radians(omega_degps)
    return f, w


def run(kind: str, f: np.ndarray, w: np.ndarray, **overrides: object):
    params = apply_overrides(CW1, overrides, "test")
    return cue_trace(f, w, DT, [Washout("x", kind, params)], None, LIMITS)["x"]


def body_rates_degps(q: np.ndarray) -> np.ndarray:
    """Body angular velocity (deg/s) between successive scalar-first quaternions, by scipy's Rotation."""
    r = Rotation.from_quat(q, scalar_first=True)
    return np.degrees((r[:-1].inv() * r[1:]).as_rotvec()) / DT


def test_defaults_are_todays_behaviour() -> None:
    f, w = step_input(1200, (2.0, 1.0), (5.0, 0.0, 10.0))
    explicit = {"tilt.rate_limit_mode": "norm", "tilt.lowpass_position": "auto", "head.rate_method": "auto"}
    for kind in ("small-angle", "large-angle", "unrestricted"):
        a, b = run(kind, f, w), run(kind, f, w, **explicit)
        assert np.array_equal(a.head_f_mps2, b.head_f_mps2) and np.array_equal(a.q, b.q)
    # auto = the paper's choice per washout, bit for bit
    for kind, position, method in (
        ("small-angle", "after_cross_product", "euler_estimator"),
        ("large-angle", "before_cross_product", "quaternion_difference"),
    ):
        a = run(kind, f, w)
        b = run(kind, f, w, **{"tilt.lowpass_position": position, "head.rate_method": method})
        assert np.array_equal(a.head_omega_radps, b.head_omega_radps) and np.array_equal(a.sp_q, b.sp_q)


def euler_rates_degps(q: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (ZYX Euler) angle rates (deg/s) of scalar-first quaternions, by scipy's Rotation."""
    zyx = Rotation.from_quat(q, scalar_first=True).as_euler("ZYX")
    return np.degrees(np.diff(zyx[:, ::-1], axis=0)) / DT


@pytest.mark.parametrize("kind", ["small-angle", "large-angle"])
def test_tilt_rate_limit_value_off_and_per_axis(kind: str) -> None:
    """The limit acts on the tilt's angular velocity (quaternion washouts) or its Euler-angle rates (small-angle)."""
    rates = euler_rates_degps if kind == "small-angle" else body_rates_degps
    f, w = step_input(1800, (3.0, 3.0))  # a diagonal sustained force: roll and pitch tilt at once
    limited = rates(run(kind, f, w, **{"tilt.gain_per_s": 2.0}).sp_q)
    assert np.linalg.norm(limited, axis=1).max() <= 3.0 * (1 + 1e-6) + 0.05  # on the norm
    free = run(kind, f, w, **{"tilt.gain_per_s": 2.0, "tilt.rate_limit_degps": "off"})
    assert not free.saturated["tilt_rate"].any()
    assert np.linalg.norm(rates(free.sp_q), axis=1).max() > 6.0
    axis = rates(run(kind, f, w, **{"tilt.gain_per_s": 2.0, "tilt.rate_limit_mode": "axis"}).sp_q)
    assert np.abs(axis[:, :2]).max() <= 3.0 * (1 + 1e-6) + 0.05  # each axis within the limit ...
    assert np.linalg.norm(axis, axis=1).max() > 3.0 * math.sqrt(2) * 0.95  # ... so the norm reaches sqrt(2) x 3


def test_tilt_gain_speeds_up_the_tilt() -> None:
    """With the limit off and the low-pass on f, the misalignment obeys d(alpha)/dt = -K sin(alpha): tan(alpha/2)
    decays as exp(-K t) once the low-pass has settled, so its log slope is -K for K = 0.4 and 2."""
    fx = 2.0
    f, w = step_input(2400, (fx, 0.0), onset_s=0.0)
    f[0] = [0.0, 0.0, -G]
    target = math.atan2(fx, G)
    for gain in (0.4, 2.0):
        tr = run("large-angle", f, w, **{"tilt.gain_per_s": gain, "tilt.rate_limit_degps": "off"})
        pitch = Rotation.from_quat(tr.sp_q, scalar_first=True).as_euler("ZYX")[:, 1]
        t = np.arange(len(pitch)) * DT
        sel = (t > 3.0) & (t < 3.0 + 2.5 / gain)  # the low-pass (double pole at 3 rad/s) has settled by 3 s
        slope = np.polyfit(t[sel], np.log(np.tan((target - pitch[sel]) / 2)), 1)[0]
        assert slope == pytest.approx(-gain, rel=0.05)  # the low-pass tail (1 + 3t) e^-3t is the rest


def test_lowpass_position_changes_the_path_not_the_end() -> None:
    f, w = step_input(3600, (1.5, 0.0))
    before = run("large-angle", f, w, **{"tilt.lowpass_position": "before_cross_product"})
    after = run("large-angle", f, w, **{"tilt.lowpass_position": "after_cross_product"})
    p_before = Rotation.from_quat(before.sp_q, scalar_first=True).as_euler("ZYX")[:, 1]
    p_after = Rotation.from_quat(after.sp_q, scalar_first=True).as_euler("ZYX")[:, 1]
    assert np.abs(p_before - p_after).max() > 1e-4  # a different path ...
    assert p_before[-1] == pytest.approx(math.atan2(1.5, G), abs=2e-3)  # ... to the same sustained tilt
    assert p_after[-1] == pytest.approx(math.atan2(1.5, G), abs=2e-3)


def test_rotational_saturation_value_and_off() -> None:
    f, w = step_input(600, omega_degps=(50.0, 0.0, 0.0))
    on = run("unrestricted", f, w)
    off = run("unrestricted", f, w, **{"rotational.saturation_degps": "off"})
    assert on.saturated["rot_rate"].any() and not off.saturated["rot_rate"].any()
    assert np.abs(body_rates_degps(on.sp_q)[200:, 0]).max() <= 32.2 + 3.0 + 0.05  # + the tilt's own rate
    assert np.abs(body_rates_degps(off.sp_q)[200:, 0]).max() > 45.0


def test_head_rate_method_estimator_lags_the_quaternion_difference_as_eq8_says() -> None:
    """For a yaw-only motion the Euler estimator's rate is the true rate through w2/(s + w2) (Eq. 8)."""
    n = 600
    f = np.tile([0.0, 0.0, -G], (n, 1))
    w = np.zeros((n, 3))
    t = np.arange(n) * DT
    w[:, 2] = np.radians(10.0) * np.sin(2.0 * t)
    q = run("large-angle", f, w)
    e = run("large-angle", f, w, **{"head.rate_method": "euler_estimator"})
    w2 = CW1.head.derivative_wn_radps
    _, lagged, _ = scipy.signal.lsim(([w2], [1.0, w2]), q.head_omega_radps[:, 2], t)
    assert np.abs(e.head_omega_radps[:, 2] - lagged).max() < 0.02 * np.abs(lagged).max()
    assert np.abs(e.head_omega_radps[:, 2] - q.head_omega_radps[:, 2]).max() > 0.05 * np.abs(lagged).max()
