"""``washbench replay A.rrd B.rrd``: two recordings of one manoeuvre written into one comparison recording."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from test_rerun_log import WASHOUTS, make_data

from washbench.cli import main
from washbench.errors import WashbenchError
from washbench.review.compare import write_comparison
from washbench.review.rerun_log import MotionSeries, perceived_path, write_recording
from washbench.review.rrd_read import read_component, read_scalar_series, read_static, read_text_documents


@pytest.fixture(scope="module")
def pair(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    root = tmp_path_factory.mktemp("cmp")
    a, b = root / "a.rrd", root / "b.rrd"
    data_a = make_data(n=240, seed=1)
    data_b = make_data(n=240, seed=2)
    data_b = type(data_b)(**{**data_b.__dict__, "aircraft": data_a.aircraft})  # same flight, other washouts
    write_recording(a, data_a, {"params_name": "CW1"})
    write_recording(b, data_b, {"params_name": "CW1-soft"})
    out = root / "comparison.rrd"
    write_comparison(a, b, out)
    return a, b, out


def test_both_recordings_in_one_panel_per_dof(pair):
    a, b, out = pair
    sa, sb, sc = read_scalar_series(a), read_scalar_series(b), read_scalar_series(out)
    names = read_static(out, "SeriesLines:names")[perceived_path("roll")]
    assert names == [*(f"CW1: {w}" for w in WASHOUTS), *(f"CW1-soft: {w}" for w in WASHOUTS), "aircraft"]  # on top
    for dof in ("surge", "heave", "yaw"):
        t, v = sc[perceived_path(dof)]
        (t_a, v_a), (t_b, v_b) = sa[perceived_path(dof)], sb[perceived_path(dof)]
        np.testing.assert_array_equal(t, np.union1d(t_a, t_b))  # both's recorded times
        k_a, k_b = np.searchsorted(t, t_a), np.searchsorted(t, t_b)
        np.testing.assert_array_equal(v[k_a, :3], v_a[:, :3])  # A's washouts, exact at A's samples
        np.testing.assert_array_equal(v[k_b, 3:6], v_b[:, :3])  # then B's
        np.testing.assert_array_equal(v[k_a, 6], v_a[:, 3])  # the aircraft once, last
        for j, i in zip((0, 1, 2, 6), range(4), strict=True):  # between its samples each line is its recording's
            np.testing.assert_allclose(v[:, j], np.interp(t, t_a, v_a[:, i]), rtol=1e-12, atol=1e-12)
    colours = read_static(out, "SeriesLines:colors")[perceived_path("roll")]
    assert len(set(colours)) == 7  # B's washouts in their own (washed) shades
    _, usage = sc["/envelope/position"]
    assert usage.shape[1] == 6
    assert read_component(out, "StateChange:state")["/lanes/phase"][1].tolist() == ["entry", "hold", "exit"]
    assert set(read_text_documents(out)) == {"/metrics/a", "/metrics/b"}


def _smooth(data, gain: float, aircraft_gain: float = 0.3):
    """``data`` with slow sines as motion: the recordings keep a few per cent of the steps, each its own."""
    t = data.t_s
    f = np.column_stack([np.sin(0.3 * t), 0.2 * np.cos(0.5 * t), -9.80665 + 0.1 * np.sin(0.2 * t)])
    w = np.column_stack([0.05 * np.sin(0.4 * t), 0.02 * np.sin(0.25 * t), 0.01 * np.cos(0.1 * t)])

    def m(g: float) -> MotionSeries:
        return MotionSeries(g * f, g * w, g * f, g * w, data.aircraft.q)

    return type(data)(**{**data.__dict__, "aircraft": m(aircraft_gain), "washouts": {x: m(gain) for x in WASHOUTS}})


def test_thinned_recordings_share_the_aircraft_only_when_it_agrees(tmp_path):
    base = make_data(n=2400)
    a, b, c = tmp_path / "a.rrd", tmp_path / "b.rrd", tmp_path / "c.rrd"
    write_recording(a, _smooth(base, 0.6), {"params_name": "one"})
    write_recording(b, _smooth(base, 1.0), {"params_name": "two"})
    write_recording(c, _smooth(base, 1.0, aircraft_gain=0.33), {"params_name": "three"})
    t_a, t_b = read_scalar_series(a)[perceived_path("surge")][0], read_scalar_series(b)[perceived_path("surge")][0]
    assert t_a.size < 240 and not np.array_equal(t_a, t_b)  # thinned, each at its own times
    write_comparison(a, b, tmp_path / "ab.rrd")
    write_comparison(a, c, tmp_path / "ac.rrd")
    assert read_static(tmp_path / "ab.rrd", "SeriesLines:names")[perceived_path("surge")][-1] == "aircraft"
    assert read_static(tmp_path / "ac.rrd", "SeriesLines:names")[perceived_path("surge")][-2:] == [
        "one: aircraft",
        "three: aircraft",
    ]  # 10 % more motion: two lines


def test_different_time_axes_are_refused(pair, tmp_path):
    a, _, _ = pair
    other = tmp_path / "short.rrd"
    write_recording(other, make_data(n=120))
    with pytest.raises(WashbenchError, match=r"time axis .* differs"):
        write_comparison(a, other, tmp_path / "x.rrd")
    assert not (tmp_path / "x.rrd").exists()


def test_cli_errors_are_one_line_before_any_viewer_starts(pair, tmp_path, capsys):
    a, b, _ = pair
    other = tmp_path / "short.rrd"
    write_recording(other, make_data(n=120))
    for args in ([a, other], [a, b, a]):  # a missing or broken file: see test_replay.py
        assert main(["replay", "--web", *map(str, args)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("washbench: error:"), err


def test_an_atlas_and_a_hexapod_compare_on_what_both_hold(pair, tmp_path):
    """Issue 52, item 7: a hexapod's recording (no wheels) against an Atlas's ended in ``KeyError:
    '/envelope/wheels'``; now both are compared on what both hold, and what one lacks is said."""
    a, _, _ = pair
    base = make_data(n=240, seed=3)
    no_wheels = dataclasses.replace(base.envelope, wheel_radps=None)
    hexapod = tmp_path / "hexapod.rrd"
    write_recording(hexapod, dataclasses.replace(base, envelope=no_wheels), {"platform.name": "a hexapod"})
    assert "/envelope/wheels" in read_scalar_series(a) and "/envelope/wheels" not in read_scalar_series(hexapod)
    for first, second in ((a, hexapod), (hexapod, a)):
        out = tmp_path / f"{first.stem}-{second.stem}.rrd"
        notes = write_comparison(first, second, out)
        assert notes == [f"{hexapod} (a hexapod) has no wheels envelope panel, which {a} (its platform) has: "
                         "compared without it"]  # fmt: skip
        series = read_scalar_series(out)
        assert "/envelope/wheels" not in series
        assert {"/envelope/position", "/envelope/velocity", "/envelope/acceleration"} <= set(series)
        _, usage = series["/envelope/position"]
        assert usage.shape[1] == 6  # both recordings' washouts
