"""Property-based hostility: mutated manoeuvre files and extreme cue inputs end cleanly, never in a traceback or a hang.

Bounded so each costs a few seconds: a fixed number of examples, a deadline per example, no shrinking database.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hostile import SHORT
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from washbench.cueing import WASHOUT_NAMES, cue_trace, load_washout_params
from washbench.errors import WashbenchError
from washbench.flight.fly import FlightResult, fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.motion_file import read_motion
from washbench.io.paths import MANOEUVRES_DIR
from washbench.platform import load_platform_limits

BUNDLED = sorted(MANOEUVRES_DIR.glob("*/*.yaml"))
SETTINGS = {
    "database": None,
    "derandomize": True,
    "suppress_health_check": [HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
}

#: Hostile scalars: extremes, wrong types, odd text.
SCALARS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1e300, -1e300, 5e-324, 3.4e38, 2**63, -(2**64), 360, 361, 1e-3]),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.text(max_size=8),
    st.sampled_from(["", "..", "/tmp", ".", "a\x00b", "x" * 300, "c172p", "liftoff", "touchdown"]),
    st.booleans(),
    st.none(),
)
VALUES = st.one_of(SCALARS, st.lists(SCALARS, max_size=3), st.dictionaries(st.text(max_size=6), SCALARS, max_size=2))


def _paths(data: Any, here: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every path to a value in ``data`` (mappings and lists)."""
    found = [here] if here else []
    if isinstance(data, dict):
        for k, v in data.items():
            found += _paths(v, (*here, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            found += _paths(v, (*here, i))
    return found


def _mutate(data: Any, path: tuple[Any, ...], how: str, value: Any) -> Any:
    data = copy.deepcopy(data)
    parent = data
    for part in path[:-1]:
        parent = parent[part]
    key = path[-1]
    if how == "replace":
        parent[key] = value
    elif how == "delete":
        del parent[key]
    elif how == "wrap":
        parent[key] = [parent[key]]
    elif how == "add" and isinstance(parent, dict):
        parent[f"{key}x"] = value
    elif how == "add":
        parent.append(value)
    return data


#: Values a careless but not hostile author writes: numbers of about the right size, flags, event names.
PLAUSIBLE = st.one_of(
    st.floats(min_value=-100.0, max_value=15000.0),
    st.integers(min_value=-10, max_value=400),
    st.booleans(),
    st.sampled_from(["liftoff", "stall", "phi_deg", "max_abs", "light"]),
)


@st.composite
def mutations(draw: st.DrawFn, base: Any, keep: tuple[str, ...] = (), values: st.SearchStrategy[Any] = VALUES) -> Any:
    paths = [p for p in _paths(base) if not any(str(part) in keep for part in p)]
    path = draw(st.sampled_from(paths))
    how = draw(st.sampled_from(["replace", "replace", "replace", "delete", "wrap", "add"]))
    return _mutate(base, path, how, draw(values))


@st.composite
def tweaks(draw: st.DrawFn, base: Any, keep: tuple[str, ...] = ()) -> Any:
    """Change one number to another of about its size (most such files are valid and fly)."""
    paths = [p for p in _paths(base) if not any(str(part) in keep for part in p)]
    numeric = []
    for p in paths:
        node = base
        for part in p:
            node = node[part]
        if isinstance(node, int | float) and not isinstance(node, bool):
            numeric.append((p, float(node)))
    path, old = draw(st.sampled_from(numeric))
    new = draw(st.floats(min_value=-2 * abs(old) - 100, max_value=3 * abs(old) + 100))
    return _mutate(base, path, "replace", new)


def _write(path: Path, data: Any) -> None:
    path.write_text(yaml.safe_dump(data, allow_unicode=True, sort_keys=False))


@settings(max_examples=40, deadline=2000, **SETTINGS)
@given(data=st.data())
def test_mutated_bundled_manoeuvres_load_or_fail_cleanly(tmp_path: Path, data: st.DataObject) -> None:
    source = data.draw(st.sampled_from(BUNDLED))
    base = yaml.safe_load(source.read_text())
    mutated = data.draw(mutations(base))
    path = tmp_path / "mutated.yaml"
    _write(path, mutated)
    try:
        load_manoeuvre(path)
    except WashbenchError as exc:
        assert all(p.startswith(f"{path}") for p in exc.problems), exc.problems
        assert all("\n" not in p for p in exc.problems)


SHORT_BASE = yaml.safe_load(SHORT.format(name="short", seconds=1, extra=""))


@settings(max_examples=16, deadline=30000, **SETTINGS)
@given(data=st.data())
def test_mutated_short_manoeuvres_fly_to_a_clean_end(tmp_path: Path, data: st.DataObject) -> None:
    """Every mutation that loads flies to an end (ok or failed, with a reason) or fails with one located line.

    The phase length is not mutated (a mutation may validly ask for an hour of flight; that is not a hang).
    """
    keep = ("until", "rate_hz")
    mutated = data.draw(st.one_of(tweaks(SHORT_BASE, keep), mutations(SHORT_BASE, keep, st.one_of(PLAUSIBLE, VALUES))))
    path = tmp_path / "short.yaml"
    _write(path, mutated)
    try:
        m = load_manoeuvre(path)
    except WashbenchError:
        event("refused when loaded")
        return
    try:
        result = fly(m)
    except WashbenchError as exc:
        event("refused in flight")
        assert str(exc).startswith(f"{path}:"), exc  # a flight-time error names the file and the field
        return
    event(f"flown: {result.status}")
    assert isinstance(result, FlightResult) and result.status in ("ok", "failed")
    assert result.ok or result.reason
    assert result.duration_s <= 1.0 + 1e-9


#: Mostly values a recording can hold (up to the accepted +-1e5 m/s^2 and +-1e5 deg/s), sometimes absurd ones.
EXTREMES = st.one_of(
    st.floats(min_value=-99999.0, max_value=99999.0),
    st.sampled_from([0.0, 5e-324, -5e-324, 2.2e-308, 99999.999, -99999.999, 9.81, -9.81]),
    st.sampled_from([1e300, -1e300, 3.4028235e38, 1e35]),
)
STEPS = st.sampled_from([1e-21, 5e-324, 1e-7, 1e-4, 1 / 1000, 1 / 120, 1 / 120, 1 / 50, 0.5, 8.3, 8.3e6, 8e307])


@settings(max_examples=20, deadline=10000, **SETTINGS)
@given(n=st.integers(min_value=2, max_value=40), dt=STEPS, data=st.data())
def test_extreme_cue_inputs_give_a_clean_error_or_output_within_every_limit(
    tmp_path: Path, n: int, dt: float, data: st.DataObject
) -> None:
    absurd = data.draw(st.booleans())  # half the traces hold an absurd number somewhere
    values = EXTREMES if absurd else st.one_of(EXTREMES.branches[0], EXTREMES.branches[1])
    f = np.array(data.draw(st.lists(values, min_size=3 * n, max_size=3 * n))).reshape(n, 3)
    w = np.array(data.draw(st.lists(values, min_size=3 * n, max_size=3 * n))).reshape(n, 3)
    rows = ["t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps"]
    rows += [",".join(repr(float(x)) for x in (k * dt, *f[k], *w[k])) for k in range(n)]
    path = tmp_path / "extreme.csv"
    path.write_text("\n".join(rows) + "\n")
    params, limits = load_washout_params(), load_platform_limits()
    try:
        motion = read_motion(path)
        traces = cue_trace(motion.f_mps2, motion.omega_radps, motion.dt_s, WASHOUT_NAMES, params, limits)
    except WashbenchError as exc:
        event("refused: " + str(exc).split(": ", 2)[-1][:40])
        assert "\n" not in str(exc)
        return
    event("cued")
    t = limits.translation
    w_max = math.radians(limits.rotation.rate_limit_degps)
    for tr in traces.values():
        for name in ("pos_m", "vel_mps", "acc_mps2", "q", "omega_radps", "head_f_mps2", "wheel_radps"):
            assert np.isfinite(getattr(tr, name)).all(), name
        assert np.all(np.abs(tr.pos_m) <= np.array(t.position_limit_m.xyz))
        assert np.all(np.abs(tr.vel_mps) <= np.array(t.velocity_limit_mps.xyz))
        assert np.all(np.abs(tr.acc_mps2) <= np.array(t.acceleration_limit_mps2.xyz))
        om = tr.omega_radps
        assert np.all(np.sqrt(om[:, 0] * om[:, 0] + om[:, 1] * om[:, 1] + om[:, 2] * om[:, 2]) <= w_max)


@pytest.mark.parametrize("path", BUNDLED[:1])
def test_the_mutation_machinery_changes_the_file(path: Path) -> None:
    base = yaml.safe_load(path.read_text())
    assert _mutate(base, ("name",), "replace", "..")["name"] == ".." and base["name"] != ".."
    assert "aircraft" not in _mutate(base, ("aircraft",), "delete", None)
