"""``washbench replay A.rrd B.rrd``: two recordings of one manoeuvre written into one comparison recording."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_rerun_log import WASHOUTS, make_data

from washbench.cli import main
from washbench.errors import WashbenchError
from washbench.review.compare import write_comparison
from washbench.review.rerun_log import perceived_path, write_recording
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
    assert names == ["aircraft", *(f"CW1: {w}" for w in WASHOUTS), *(f"CW1-soft: {w}" for w in WASHOUTS)]
    for dof in ("surge", "heave", "yaw"):
        t, v = sc[perceived_path(dof)]
        np.testing.assert_array_equal(t, sa[perceived_path(dof)][0])
        np.testing.assert_array_equal(v[:, :4], sa[perceived_path(dof)][1])  # aircraft once, then A's washouts
        np.testing.assert_array_equal(v[:, 4:], sb[perceived_path(dof)][1][:, 1:])  # then B's
    colours = read_static(out, "SeriesLines:colors")[perceived_path("roll")]
    assert len(set(colours)) == 7  # B's washouts in their own (washed) shades
    _, usage = sc["/envelope/position"]
    assert usage.shape == (240, 6)
    assert read_component(out, "StateChange:state")["/lanes/phase"][1].tolist() == ["entry", "hold", "exit"]
    assert set(read_text_documents(out)) == {"/metrics/a", "/metrics/b"}


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
