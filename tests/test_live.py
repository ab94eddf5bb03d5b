"""``washbench live`` and ``washbench send`` on loopback: every source format, faults, sink, signals, real JSBSim.

Each test picks free ports, sends from a thread (or a real JSBSim, or a ``washbench send``) and lets the live session
stop by itself (``--idle-timeout``). The live result is compared with ``washbench cue`` on the saved input
(traces.parquet tables and metrics.csv equal), and the saved input with what was sent (exactly for float64
formats, to float32 for X-Plane's), and X-Plane's and JSBSim's conversions with washbench's file readers of the
same numbers.
"""

from __future__ import annotations

import json
import math
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from washbench.cli import main
from washbench.cueing.variants import DEFAULT_WASHOUTS
from washbench.errors import WashbenchError
from washbench.io.readers import read_samples
from washbench.live import commands, packets
from washbench.live.link import HIST_MAX_US, LatencyStats, Link
from washbench.runs.cue import CueOptions, run_cue
from washbench.runs.live import INPUT_FILE, LiveOptions, run_live
from washbench.runs.options import load_options
from washbench.runs.outputs import Outputs

DT = 1.0 / 120.0
N = 360
REPO = Path(__file__).resolve().parents[1]


def motion(n: int = N, t0: float = 0.0) -> list[tuple[float, ...]]:
    """Six-axis motion on the 120 Hz grid t = t0 + k dt: sines of different frequencies (m/s^2, deg/s)."""
    k = np.arange(n, dtype=np.float64)
    t = t0 + k * DT
    f = np.column_stack([1.5 * np.sin(2.1 * t), 0.8 * np.sin(3.3 * t + 1), -9.80665 + 1.2 * np.sin(1.7 * t)])
    w = np.column_stack([12 * np.sin(2.9 * t), 7 * np.sin(1.3 * t + 0.5), 4 * np.sin(0.9 * t + 2)])
    return [tuple(r) for r in np.column_stack([t, f, w]).tolist()]


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_listening(sock: socket.socket, timeout_s: float = 60.0) -> None:
    """Block until something listens at the address ``sock`` is connected to: a 1-byte probe a closed port
    answers with ICMP (ConnectionRefusedError here). Exactly one probe reaches the listener (a foreign packet)."""
    end = time.monotonic() + timeout_s
    sock.settimeout(0.02)
    while time.monotonic() < end:
        try:
            sock.send(b"?")
            time.sleep(0.02)
            sock.recv(1)
        except ConnectionRefusedError:
            continue
        except TimeoutError:
            return
    raise AssertionError("washbench live did not start listening")


def in_thread(fn: Callable[[], None]) -> threading.Thread:
    th = threading.Thread(target=fn, daemon=True)
    th.start()
    return th


def live(tmp_path: Path, fmt: str, port: int, name: str = "live", washouts: list[str] | None = None,
         **kw: object) -> tuple[int, Path]:  # fmt: skip
    outputs = Outputs(recording=bool(kw.pop("recording", False)), figures=False)
    opts = LiveOptions(listen=("127.0.0.1", port), fmt=fmt, out=tmp_path / name, idle_timeout_s=0.6, viewer=False,
                       **kw)  # type: ignore[arg-type]  # fmt: skip
    return run_live(opts, load_options(outputs=outputs, washouts=washouts)), tmp_path / name


def assert_equals_cue(out: Path, tmp_path: Path, folders: tuple[str, ...] = ("",)) -> None:
    """Each result folder equals ``washbench cue`` of the saved input, bit for bit."""
    ref = tmp_path / "cue_of_saved"
    resample = run_json(out, folders[0])["live"]["resample_hz"]
    run_cue(out / INPUT_FILE, ref, CueOptions(resample_hz=resample), load_options(outputs=Outputs(False, False)))
    for f in folders:
        a = pq.read_table(out / f / "traces.parquet")
        b = pq.read_table(ref / f / "traces.parquet")
        assert a.column_names == b.column_names
        assert a.equals(b)
        assert (out / f / "metrics.csv").read_text() == (ref / f / "metrics.csv").read_text()


def run_json(out: Path, folder: str = "") -> dict:
    return json.loads((out / folder / "run.json").read_text())


def saved(out: Path) -> np.ndarray:
    s = read_samples(out / INPUT_FILE)
    return np.column_stack([s.t_s, s.f_mps2, s.omega_degps])


# --------------------------------------------------------------------------- link and latency, no sockets


def test_link_holds_gaps_drops_duplicates_and_reordered_and_splits_restarts() -> None:
    m = motion(100)
    link = Link(dt_s=DT)
    # duplicate 9, lose 10-12, swap 20 and 21, then restart (back by 0.8 s, more than the 0.5 s a reorder may be)
    order = [*range(0, 10), 9, *range(13, 20), 21, 20, *range(22, 100), *range(0, 10)]
    outs = []
    for i in order:
        outs += link.push(m[i])
    c = link.counts
    assert (c.duplicate, c.reordered, c.restarts) == (1, 1, 1)
    assert c.lost == 3 + 1  # 10, 11, 12 and 20 (its slot was held before it arrived)
    first = outs[:100]
    assert [o.held for o in first].count(True) == 4
    held = [o for o in first if o.held]
    assert held[0].sample[1:] == m[9][1:]  # the last sample's values held ...
    assert held[0].sample[0] == pytest.approx(m[10][0], abs=1e-12)  # ... at the missing time
    assert [o.new_segment for o in outs].count(True) == 2 and outs[100].new_segment
    times = [o.sample[0] for o in first]
    assert np.all(np.diff(times) > 0) and len(outs) == 110


def test_link_measures_the_step_and_shifts_jsbsim_lag() -> None:
    m = motion(20)
    link = Link(lag_shift=True)
    outs = []
    for s in m:
        outs += link.push(s)
    outs += link.flush()
    assert link.dt_s == pytest.approx(DT, rel=1e-12)
    assert len(outs) == 19 and link.counts.unshifted == 0
    for k, o in enumerate(outs):  # sample k: time and rates of frame k, specific force of frame k + 1
        assert o.sample[0] == m[k][0] and o.sample[4:] == m[k][4:] and o.sample[1:4] == m[k + 1][1:4]


def test_latency_percentiles_match_numpy() -> None:
    rng = np.random.default_rng(3)
    lat_ns = (rng.gamma(2.0, 60.0, 5000) * 1000).astype(np.int64)  # microseconds-scale latencies
    stats = LatencyStats()
    for v in lat_ns:
        stats.add(int(v), DT)
    for q in (50.0, 99.0):
        exact = np.percentile(lat_ns / 1e6, q, method="inverted_cdf")
        assert abs(stats.percentile_ms(q) - exact) <= 0.0011  # 1 us bins
    assert stats.summary()["latency_max_ms"] == lat_ns.max() / 1e6
    stats.add(HIST_MAX_US * 2000, DT)
    assert stats.percentile_ms(100.0) == HIST_MAX_US * 2 / 1e3 and stats.late == 1


def test_xplane_and_jsbsim_packets_convert_as_the_file_readers(tmp_path: Path) -> None:
    """The UDP decoders give the numbers washbench cue reads from X-Plane's Data.txt and JSBSim's CSV."""
    m = motion(5)
    rows = []
    dec = packets.XPlaneDecoder()
    for s in m:
        data = packets.encode_xplane(0, s)
        got = dec.decode(data)
        r = {i: v for i, *v in (packets._XP_ROW.unpack_from(data, 5 + 36 * j) for j in range(3))}
        rows.append((r[1][0], r[1][1], r[4][4], r[4][5], r[4][6], r[16][0], r[16][1], r[16][2], got))
    heads = ["_real,_time", "_totl,_time", "Gload,norml", "Gload,axial", "Gload,_side", "____Q,rad/s",
             "____P,rad/s", "____R,rad/s"]  # fmt: skip
    text = "|".join(h.rjust(10) for h in heads) + "|\n"
    text += "".join("|".join(repr(float(v)) for v in r[:8]) + "|\n" for r in rows)
    (tmp_path / "Data.txt").write_text(text)
    s = read_samples(tmp_path / "Data.txt")
    got = np.array([r[8] for r in rows])
    np.testing.assert_array_equal(got[:, 0], s.t_s)
    np.testing.assert_allclose(got[:, 1:4], s.f_mps2, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(got[:, 4:7], s.omega_degps, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(got[:, 1:], np.array(m)[:, 1:], rtol=2e-7, atol=2e-6)  # float32 of what was sent

    jd = packets.JsbsimDecoder()
    jd.decode(packets.encode_jsbsim_labels())
    link = Link(lag_shift=True)
    outs = []
    lines = []
    for s in m:
        line = packets.encode_jsbsim(0, s)
        lines.append(line.decode())
        outs += link.push(jd.decode(line))
    outs += link.flush()
    hdr = "Time, accelerations/a-pilot-x-ft_sec2, accelerations/a-pilot-y-ft_sec2, accelerations/a-pilot-z-ft_sec2, " \
          "P (deg/s), Q (deg/s), R (deg/s)\n"  # fmt: skip
    (tmp_path / "jsb.csv").write_text(hdr + "".join(lines))
    s = read_samples(tmp_path / "jsb.csv")
    got = np.array([o.sample for o in outs])
    np.testing.assert_array_equal(got, np.column_stack([s.t_s, s.f_mps2, s.omega_degps]))


def test_command_packet_layout() -> None:
    from washbench.cueing.kernel import NFIELDS, O_POS, O_Q, O_SAT

    rows = np.arange(2 * NFIELDS, dtype=np.float64).reshape(2, NFIELDS)
    rows[:, O_SAT:] = 0.0
    rows[1, O_SAT + 2] = 1.0
    data = commands.encode_binary(7, 1.25, commands.FLAG_HELD, rows)
    assert len(data) == 24 + 2 * 112 and data[:4] == b"WBPC" and data[4] == 1
    doc = commands.decode_binary(data)
    assert doc["seq"] == 7 and doc["t_s"] == 1.25 and doc["flags"] == 1
    assert doc["washouts"][1]["pos_m"] == list(rows[1, O_POS : O_POS + 3])
    assert doc["washouts"][1]["q"] == list(rows[1, O_Q : O_Q + 4])
    assert doc["washouts"][1]["saturated"] == ["acc"] and doc["washouts"][0]["saturated"] == []
    line = json.loads(commands.encode_json(7, 1.25, 0, rows, ["a", "b"]))
    assert line["washouts"]["b"]["saturated"] == ["acc"] and line["seq"] == 7


# --------------------------------------------------------------------------- sessions on loopback


def _send_samples(port: int, fmt: str, samples: list[tuple[float, ...]], extra: Callable | None = None) -> Callable:
    def go() -> None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.connect(("127.0.0.1", port))
            wait_listening(s)
            if fmt == "jsbsim":
                s.send(packets.encode_jsbsim_labels())
            enc = packets.ENCODERS[fmt]
            for k, smp in enumerate(samples):
                s.send(enc(k, smp))
                if k % 20 == 19:
                    time.sleep(0.002)

    return go


def _rref_xplane(xp: socket.socket, samples: list[tuple[float, ...]], seen: dict) -> Callable:
    """The test plays X-Plane: wait for the subscriptions, answer them, record the cancellations."""

    def go() -> None:
        xp.settimeout(60.0)
        subs: dict[int, int] = {}
        paths = [p for p, _ in packets.RREF_DATAREFS]
        while len(subs) < len(paths):
            data, addr = xp.recvfrom(2048)
            freq, rid, path = packets.parse_rref_request(data)
            assert freq > 0
            subs[rid] = paths.index(path)
        for smp in samples:
            v = packets.rref_values(smp)
            xp.sendto(packets.encode_rref([(rid, v[j]) for rid, j in subs.items()]), addr)
            time.sleep(0.0003)
        xp.settimeout(5.0)
        cancelled = set()
        while len(cancelled) < len(paths):
            freq, rid, _ = packets.parse_rref_request(xp.recvfrom(2048)[0])
            if freq == 0:
                cancelled.add(rid)
        seen["cancelled"] = cancelled

    return go


@pytest.mark.parametrize("fmt", packets.FORMATS)
def test_each_source_format_gives_the_cue_result(tmp_path: Path, fmt: str) -> None:
    m = motion()
    port = free_udp_port()
    seen: dict = {}
    kw: dict = {}
    if fmt == "xplane-rref":
        xp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        xp.bind(("127.0.0.1", 0))
        kw["xplane"] = xp.getsockname()
        th = in_thread(_rref_xplane(xp, m, seen))
    else:
        th = in_thread(_send_samples(port, fmt, m))
    status, out = live(tmp_path, fmt, port, **kw)
    th.join(10)
    assert status == 0
    doc = run_json(out)
    c = doc["live"]["counts"]
    n = N - 1 if fmt == "jsbsim" else N  # JSBSim's lag shift drops the last frame, as for its CSV
    assert c["cued"] == n and c["received"] == N and c["lost_held"] == c["duplicate"] == c["reordered"] == 0
    assert c["foreign"] == (0 if fmt == "xplane-rref" else 1)  # the test's one probe
    assert doc["steps"] == n and doc["live"]["format"] == fmt
    lat = doc["live"]["latency"]
    assert lat["commands"] > 0 and 0 < lat["latency_median_ms"] <= lat["latency_p99_ms"] <= lat["latency_max_ms"]
    assert_equals_cue(out, tmp_path)
    got = saved(out)
    sent = np.array(m)
    if fmt == "jsbsim":
        sent = np.column_stack([sent[:-1, 0], sent[1:, 1:4], sent[:-1, 4:]])  # what JSBSim's lag shift gives back
    exact = fmt == "washbench"
    tol = dict(rtol=0, atol=0) if exact else dict(rtol=2e-7, atol=4e-6)  # X-Plane's float32
    if fmt in ("flightgear", "jsbsim"):
        tol = dict(rtol=1e-15, atol=1e-14)  # ft/s^2 and rad/s there and back
    np.testing.assert_allclose(got, sent, **tol)
    if fmt == "xplane-rref":
        assert seen["cancelled"] == {packets.RREF_ID0 + i for i in range(len(packets.RREF_DATAREFS))}


@pytest.mark.parametrize("washouts", [None, ["mpc", "mpc-unrestricted"]], ids=["default", "mpc"])
def test_washbench_format_result_equals_cue_of_the_original_file(tmp_path: Path, washouts: list[str] | None) -> None:
    """float64 end to end: the live result is also ``washbench cue`` of the file that was sent. With the MPC
    washouts: stepped live, sample by sample as packets arrive, they give what ``cue`` gives with their
    whole-recording form (``trace``), bit for bit."""
    m = motion()
    src = tmp_path / "flight.csv"
    src.write_text("t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps\n"
                   + "".join(",".join(repr(v) for v in r) + "\n" for r in m))  # fmt: skip
    port = free_udp_port()
    th = in_thread(_send_samples(port, "washbench", m))
    status, out = live(tmp_path, "washbench", port, washouts=washouts)
    th.join(10)
    assert status == 0
    run = load_options(outputs=Outputs(recording=False, figures=False), washouts=washouts)
    run_cue(src, tmp_path / "orig", run=run)
    a = pq.read_table(out / "traces.parquet")
    b = pq.read_table(tmp_path / "orig" / "traces.parquet")
    if washouts:
        assert any(c.startswith("mpc-unrestricted.") for c in b.column_names)
    assert a.drop_columns(["live_held"]).equals(b)
    assert (out / "metrics.csv").read_text() == (tmp_path / "orig" / "metrics.csv").read_text()


def test_faults_are_counted_and_the_result_still_equals_cue(tmp_path: Path) -> None:
    m = motion(300)
    m2 = motion(200)  # the sender restarts: time from 0 again
    enc = packets.encode_washbench
    bad_nan = enc(0, (1.0, math.nan, 0.0, -9.8, 0.0, 0.0, 0.0))
    port = free_udp_port()

    def go() -> None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.connect(("127.0.0.1", port))
            wait_listening(s)
            for k in range(300):
                if k in (50, 51, 52):  # lost
                    continue
                if k == 100:  # 101 before 100: reordered
                    s.send(enc(101, m[101]))
                    s.send(enc(100, m[100]))
                    continue
                if k == 101:
                    continue
                s.send(enc(k, m[k]))
                if k in (150, 200):  # duplicated
                    s.send(enc(k, m[k]))
                if k == 160:  # another program's packets, truncated and corrupt ones
                    for junk in (b"hello world", bytes(range(40)), b"\x00" * 68):
                        s.send(junk)
                    for junk in (enc(k, m[k])[:40], enc(k, m[k]) + b"x", bad_nan):
                        s.send(junk)
                if k % 20 == 0:
                    time.sleep(0.002)
            for k in range(200):
                s.send(enc(k, m2[k]))
                if k % 20 == 0:
                    time.sleep(0.002)

    th = in_thread(go)
    status, out = live(tmp_path, "washbench", port, rate_hz=120.0)
    th.join(10)
    assert status == 0
    c = run_json(out, "segment_1")["live"]["counts"]
    assert c["lost_held"] == 4  # 50, 51, 52 and 100 (held before it came, then dropped as reordered)
    assert c["reordered"] == 1 and c["duplicate"] == 2 and c["restarts"] == 1 and c["segments"] == 2
    assert c["foreign"] == 3 + 1 and c["malformed"] == 3
    assert c["cued"] == 300 + 200
    t1 = pq.read_table(out / "segment_1" / "traces.parquet")
    held = t1.column("live_held").to_numpy()
    assert held.sum() == 4 and list(np.flatnonzero(held)) == [50, 51, 52, 100]
    f_x = t1.column("aircraft.f_x_mps2").to_numpy()
    assert f_x[52] == m[49][1] and f_x[100] == m[99][1]  # held values
    assert pq.read_table(out / "segment_2" / "traces.parquet").num_rows == 200
    assert_equals_cue(out, tmp_path, ("segment_1", "segment_2"))


def test_commands_reach_the_sink_and_match_the_result(tmp_path: Path) -> None:
    m = motion()
    port = free_udp_port()
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sink.bind(("127.0.0.1", 0))
    sink.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    sink.settimeout(0.2)
    got: list[bytes] = []

    def collect() -> None:
        end = time.monotonic() + 60
        while time.monotonic() < end and len(got) < N:
            try:
                got.append(sink.recv(65536))
            except TimeoutError:
                continue

    collector = in_thread(collect)
    th = in_thread(_send_samples(port, "washbench", m))
    status, out = live(tmp_path, "washbench", port, sink=sink.getsockname(), rate_hz=120.0)
    th.join(10)
    collector.join(10)
    assert status == 0 and len(got) == N
    docs = [commands.decode_binary(d) for d in got]
    assert [d["seq"] for d in docs] == list(range(N))
    t = pq.read_table(out / "traces.parquet").to_pydict()
    for i, name in enumerate(("small-angle", "large-angle", "unrestricted")):
        pos = np.array([d["washouts"][i]["pos_m"] for d in docs])
        q = np.array([d["washouts"][i]["q"] for d in docs])
        np.testing.assert_array_equal(pos, np.column_stack([t[f"{name}.pos_{a}_m"] for a in "xyz"]))
        np.testing.assert_array_equal(q, np.column_stack([t[f"{name}.q_{a}"] for a in "wxyz"]))
    assert run_json(out)["live"]["counts"]["sink_sent"] == N


def test_json_sink_and_a_sink_that_does_not_listen(tmp_path: Path) -> None:
    m = motion(120)
    port, dead = free_udp_port(), free_udp_port()
    th = in_thread(_send_samples(port, "washbench", m))
    status, out = live(tmp_path, "washbench", port, sink=("127.0.0.1", dead), sink_format="json")
    th.join(10)
    assert status == 0
    c = run_json(out)["live"]["counts"]
    assert c["sink_errors"] > 0 and c["sink_sent"] + c["sink_errors"] == c["commands"] == 120
    assert (out / "traces.parquet").exists()


def test_port_in_use_is_one_line_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as busy:
        busy.bind(("127.0.0.1", 0))
        port = busy.getsockname()[1]
        status = main(["live", "--listen", f"127.0.0.1:{port}", "--format", "xplane", "--out", str(tmp_path / "o"),
                       "--no-viewer"])  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "already in use" in err[0] and f":{port}" in err[0]
    assert not (tmp_path / "o").exists()
    with pytest.raises(WashbenchError, match="--sink: port"):
        from washbench.live.endpoints import parse_address

        parse_address("udp://host:port", "--sink")


def test_send_command_to_the_live_command(tmp_path: Path) -> None:
    """``washbench send FILE`` (a bundled format reader's input) into ``washbench live`` through the CLI."""
    m = motion(240)
    src = tmp_path / "in.csv"
    src.write_text("t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps\n"
                   + "".join(",".join(repr(v) for v in r) + "\n" for r in m))  # fmt: skip
    port = free_udp_port()

    def go() -> None:
        from washbench.runs.send import run_send

        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.connect(("127.0.0.1", port))
            wait_listening(s)
        run_send("flightgear", ("127.0.0.1", port), src, speed=4.0)

    th = in_thread(go)
    out = tmp_path / "live"
    status = main(["live", "--listen", f"127.0.0.1:{port}", "--format", "flightgear", "--out", str(out),
                   "--idle-timeout", "0.6", "--no-viewer", "--no-recording", "--no-figures", "--washout", "large-angle",
                   "--vestibular", "telban-cardullo", "--rank-by", "false-cue", "--filter-start", "rest"])  # fmt: skip
    th.join(10)
    assert status == 0
    doc = run_json(out)
    assert doc["live"]["counts"]["cued"] == 240
    # the run's options as washbench cue takes them, in the final cue's result
    prov = doc["provenance"]
    assert prov["vestibular"]["model"] == "telban-cardullo" and prov["ranking"]["by"] == "false-cue"
    assert doc["filter_start"] == "rest" and list(doc["saturations"]) == ["large-angle"]
    assert not (out / "recording.rrd").exists() and not (out / "figures").exists()
    wall = doc["live"]["wall_s"]
    assert wall > 240 * DT / 4.0  # paced: 2 s of flight at 4 x real time take at least 0.5 s
    np.testing.assert_allclose(saved(out), np.array(m), rtol=1e-15, atol=1e-14)


def test_send_fly_a_real_jsbsim_flight(tmp_path: Path) -> None:
    port = free_udp_port()

    def go() -> None:
        from washbench.runs.send import run_send

        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.connect(("127.0.0.1", port))
            wait_listening(s)
        run_send("washbench", ("127.0.0.1", port), fly_path=Path("c172/elevator_doublet"), speed=40.0)

    th = in_thread(go)
    status, out = live(tmp_path, "washbench", port)
    th.join(30)
    assert status == 0
    doc = run_json(out)
    n = doc["live"]["counts"]["cued"]
    assert n == doc["steps"] and n > 32 * 120  # 32.2 s flown at 120 Hz
    assert doc["live"]["counts"]["lost_held"] == 0
    s = saved(out)
    assert s[0, 3] == pytest.approx(-9.81, abs=0.3)  # level flight: f_z about -g
    assert np.min(s[:, 5]) < -3 and np.max(s[:, 5]) > 3  # the doublet's pitch rates (deg/s), as its checks say


def test_real_jsbsim_socket_output(tmp_path: Path) -> None:
    """JSBSim's own ``<output type="SOCKET" protocol="UDP">`` into washbench live."""
    os.environ.setdefault("JSBSIM_DEBUG", "0")
    import jsbsim

    port = free_udp_port()
    directive = tmp_path / "out.xml"
    directive.write_text(f'<output name="127.0.0.1" type="SOCKET" protocol="UDP" port="{port}" rate="120" '
                         'precision="12"><rates>ON</rates><property>accelerations/a-pilot-x-ft_sec2</property>'
                         '<property>accelerations/a-pilot-y-ft_sec2</property>'
                         '<property>accelerations/a-pilot-z-ft_sec2</property></output>')  # fmt: skip
    ref: list[tuple[float, ...]] = []

    def go() -> None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.connect(("127.0.0.1", port))
            wait_listening(s)
        fdm = jsbsim.FGFDMExec(jsbsim.get_default_root_dir())
        fdm.set_debug_level(0)
        fdm.load_model("c172p")
        fdm.set_output_directive(str(directive))
        fdm.set_dt(DT)
        fdm["ic/h-sl-ft"], fdm["ic/vc-kts"] = 4000.0, 100.0
        fdm.run_ic()
        for k in range(240):
            fdm.run()
            ref.append((fdm["simulation/sim-time-sec"], fdm["accelerations/a-pilot-z-ft_sec2"],
                        fdm["velocities/q-rad_sec"]))  # fmt: skip
            if k % 20 == 19:
                time.sleep(0.002)

    th = in_thread(go)
    status, out = live(tmp_path, "jsbsim", port)
    th.join(30)
    assert status == 0
    s = saved(out)
    assert s.shape[0] >= 230
    r = {round(t, 9): (az, q) for t, az, q in ref}
    for row in s[5:50]:
        az, q = r[round(row[0], 9)]
        assert row[5] == pytest.approx(math.degrees(q), rel=1e-9, abs=1e-9)
        assert abs(row[3] - az * 0.3048) < 0.5  # a-pilot of the next frame (the lag shift), within a frame's change
    assert_equals_cue(out, tmp_path)


def test_ctrl_c_and_sigterm_write_every_sample(tmp_path: Path) -> None:
    """Two sessions at once (start-up is the slow part): one stopped by SIGINT (exit 130), one by SIGTERM (143)."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    runs = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        port, out = free_udp_port(), tmp_path / f"live{int(sig)}"
        cmd = [sys.executable, "-m", "washbench", "live", "--listen", f"127.0.0.1:{port}", "--format", "washbench",
               "--out", str(out), "--no-viewer", "--no-recording", "--no-figures"]  # fmt: skip
        if sig == signal.SIGTERM:
            cmd.append("--realtime")  # taken (as root) or refused in one line: the session is the same
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        runs.append((sig, port, out, proc))
    try:
        for _, port, _, _ in runs:
            _send_samples(port, "washbench", motion(200))()
        time.sleep(0.3)
        for sig, _, _, proc in runs:
            proc.send_signal(sig)
        for sig, _, out, proc in runs:
            stdout, stderr = proc.communicate(timeout=60)
            if sig == signal.SIGTERM:
                assert ("real-time priority: SCHED_FIFO" in stdout) != ("cannot take a real-time priority" in stderr)
            assert proc.returncode == (130 if sig == signal.SIGINT else 143), stderr
            assert "holds every sample received" in stderr
            doc = run_json(out)
            assert doc["live"]["counts"]["cued"] == 200 == doc["steps"]
            assert doc["live"]["stop"].startswith("interrupted" if sig == signal.SIGINT else "terminated")
            assert not (out / (INPUT_FILE + ".part")).exists()
    finally:
        for *_, proc in runs:
            if proc.poll() is None:
                proc.kill()


@pytest.mark.parametrize("fmt", packets.FORMATS)
def test_decoders_never_crash_on_garbage(fmt: str) -> None:
    """Random datagrams, truncations and bit flips of real ones: a sample, nothing, or PacketError; never more."""
    rng = np.random.default_rng(7)
    dec = packets.decoder(fmt)
    good = {
        "washbench": packets.encode_washbench(0, motion(1)[0]),
        "xplane": packets.encode_xplane(0, motion(1)[0]),
        "xplane-rref": packets.encode_rref([(packets.RREF_ID0 + i, 1.0) for i in range(7)]),
        "flightgear": packets.encode_flightgear(0, motion(1)[0]),
        "jsbsim": packets.encode_jsbsim(0, motion(1)[0]),
    }[fmt]
    if fmt == "jsbsim":
        dec.decode(packets.encode_jsbsim_labels())
    datagrams = [rng.bytes(int(rng.integers(0, 300))) for _ in range(500)]
    datagrams += [good[: int(rng.integers(0, len(good)))] for _ in range(200)]
    for _ in range(500):
        b = bytearray(good)
        b[int(rng.integers(0, len(b)))] ^= 1 << int(rng.integers(0, 8))
        datagrams.append(bytes(b))
    kinds = {"sample": 0, "none": 0, "foreign": 0, "malformed": 0}
    for d in datagrams:
        try:
            s = dec.decode(d)
        except packets.PacketError as exc:
            kinds[exc.kind] += 1
            continue
        kinds["sample" if s is not None else "none"] += 1
        if s is not None:
            assert len(s) == 7 and all(math.isfinite(v) for v in s)
    assert kinds["foreign"] + kinds["malformed"] > 0


def test_no_samples_before_the_duration_is_one_line_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    """--duration stops a session; with nothing received it says so (exit 2) and leaves no folder; the viewer,
    asked for without a display, is off with one line."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    port = free_udp_port()
    status = main(["live", "--listen", f"127.0.0.1:{port}", "--format", "jsbsim", "--out", str(tmp_path / "o"),
                   "--duration", "0.3"])  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2
    assert any("no display" in line and "viewer is off" in line for line in err)
    assert "0 sample(s) received (--duration 0.3 s): nothing to cue" in err[-1]
    assert not (tmp_path / "o").exists()


def test_a_source_off_the_grid_is_resampled_as_washbench_cue_advises(tmp_path: Path) -> None:
    """Frame stamps with 1 ms jitter (a simulator's frames): cued with the --resample washbench cue would advise."""
    rng = np.random.default_rng(5)
    m = [(s[0] + float(rng.uniform(-1e-3, 1e-3)), *s[1:]) for s in motion()]
    port = free_udp_port()
    th = in_thread(_send_samples(port, "washbench", m))
    status, out = live(tmp_path, "washbench", port)
    th.join(10)
    assert status == 0
    doc = run_json(out)
    assert doc["live"]["resample_hz"] == 120.0 and any("resampled to 120 Hz" in n for n in doc["conversions"])
    np.testing.assert_array_equal(saved(out)[:, 0], [s[0] for s in m])  # the stamps are saved as they came
    assert_equals_cue(out, tmp_path)


def test_a_viewer_closed_while_running(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                       capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """The viewer's process ends mid-session (the user closed it): noticed once, logging stops, the session goes on.
    The viewer is a short-lived process and a recording stream written to a file (no display here)."""
    import rerun as rr

    from washbench.live import viewer as viewer_mod

    made: list[viewer_mod.LiveViewer] = []

    rrd = tmp_path / "viewer.rrd"

    def fake_open(names: list[str], limits: object, filter_start: str) -> viewer_mod.LiveViewer:
        rec = rr.RecordingStream("washbench-live-test")
        rec.save(rrd)  # a file instead of a viewer's gRPC port: what the viewer would have got
        rec.send_blueprint(viewer_mod.live_blueprint(names))
        v = viewer_mod.LiveViewer(names, subprocess.Popen(["sleep", "60"]), rec)
        made.append(v)
        return v

    monkeypatch.setattr(viewer_mod, "open_viewer", fake_open)
    m = motion(360)
    port = free_udp_port()

    def go() -> None:  # 360 samples over about a second: the user closes the viewer half-way
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.connect(("127.0.0.1", port))
            wait_listening(s)
            for k, smp in enumerate(m):
                s.send(packets.encode_washbench(k, smp))
                time.sleep(0.003)
                if k == 180:
                    made[0].proc.kill()
                    made[0].proc.wait()  # ended before the next sample, however loaded the machine

    th = in_thread(go)
    opts = LiveOptions(listen=("127.0.0.1", port), fmt="washbench", out=tmp_path / "o", idle_timeout_s=0.6,
                       viewer=True, rate_hz=120.0)  # fmt: skip
    status = run_live(opts, load_options(outputs=Outputs(recording=False, figures=False)))
    th.join(10)
    assert status == 0 and made and made[0].closed
    assert capsys.readouterr().err.count("the viewer was closed") == 1
    doc = run_json(tmp_path / "o")
    assert doc["live"]["viewer"] == "closed" and doc["live"]["counts"]["cued"] == 360
    # what the viewer got before it closed: the recording's entity paths, the aircraft last (drawn on top, as in a
    # recording), the sample's values
    from washbench.review.rerun_log import read_scalar_series

    series = read_scalar_series(rrd)
    t, surge = series["/raw/surge"]
    # at most 30 rows a second, none after the close; the default washouts and the aircraft
    assert 1 <= len(t) < 180 and surge.shape == (len(t), 1 + len(DEFAULT_WASHOUTS))
    assert t[-1] <= m[200][0]  # seen ended at the next sample (rows at most 30 a second)
    # the values at each logged time are those of the result (the same step, the same filters chunk by chunk)
    table = pq.read_table(tmp_path / "o" / "traces.parquet").to_pydict()
    row_of = {round(v, 9): i for i, v in enumerate(table["t_s"])}
    names = (*DEFAULT_WASHOUTS, "aircraft")
    tp, perceived = series["/perceived/surge"]
    np.testing.assert_array_equal(tp, t)
    for ti, raw, felt in zip(t, surge, perceived, strict=True):
        k = row_of[round(ti, 9)]
        assert list(raw) == [table[f"{n}.f_x_mps2"][k] for n in names]
        assert list(felt) == [table[f"{n}.perceived_f_x_mps2"][k] for n in names]
    assert "/platform/small-angle/position/axes" in series


def test_send_plays_xplane_for_rref(tmp_path: Path) -> None:
    """``washbench send --format xplane-rref`` answers washbench live's subscription as X-Plane would."""
    m = motion(240)
    src = tmp_path / "in.csv"
    src.write_text("t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps\n"
                   + "".join(",".join(repr(v) for v in r) + "\n" for r in m))  # fmt: skip
    port, xport = free_udp_port(), free_udp_port()
    from washbench.runs.send import run_send

    th = in_thread(lambda: run_send("xplane-rref", None, src, speed=8.0, listen=("127.0.0.1", xport)))
    time.sleep(0.5)  # the sender binds X-Plane's port (live subscribes again every 2 s until answered)
    status, out = live(tmp_path, "xplane-rref", port, xplane=("127.0.0.1", xport))
    th.join(10)
    assert status == 0
    c = run_json(out)["live"]["counts"]
    assert c["cued"] == 240 and c["foreign"] == 0
    np.testing.assert_allclose(saved(out), np.array(m), rtol=2e-7, atol=4e-6)
    assert not th.is_alive()  # the sender stopped when live cancelled its subscriptions
