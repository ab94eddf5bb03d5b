"""``washbench live`` in real time: a 30-minute flight replayed through loopback at 120 Hz and at 1 kHz.

    .venv/bin/python bench/live_bench.py [--minutes 30] [--rates 120 1000] [--speed 1] [--washout NAME ...]
    .venv/bin/python bench/live_bench.py --quick            # 1 minute at each rate, for a quick check

For each rate: a six-axis flight of ``--minutes`` is sent by this process in washbench's packet format, paced to
``--speed`` times real time, to a ``washbench live`` process (its own process, as a user runs it: no viewer, no
recording or figures, commands to a sink in this process that counts them). Printed: the session's latency from a
datagram's arrival to its command's send (median, 99th percentile, maximum), jitter, packets lost, late (command
sent more than one step after arrival) and reordered, commands received by the sink, and the CPU share of the
live process during the session (its CPU seconds over the session's wall seconds: a fraction of one core) against
bare JSBSim ``fdm.run()`` for the same number of steps (c172p in the air, CPU time, this process): the ratio says
what running washbench live beside a simulator costs compared with the flight model itself. The live process's
resident memory is sampled every second: start, end and maximum (the samples stream to disk: it stays flat).
The aim: 99th-percentile latency under 1 ms at 120 Hz for the three classical washouts, and no packet dropped by
washbench itself (lost = 0: every datagram sent was received and cued).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from baseline import c172p_in_air, run_cpu_s

from washbench.live.packets import encode_washbench
from washbench.runs.send import Pacer


def flight(n: int, dt: float) -> np.ndarray:
    """A six-axis flight of n samples (m/s^2, deg/s) on the grid k dt."""
    t = np.arange(n) * dt
    return np.column_stack([
        t,
        1.5 * np.sin(0.3 * t) + 0.3 * np.sin(7.1 * t),
        0.8 * np.sin(0.17 * t + 1.0),
        -9.80665 * (1.0 + 0.3 * np.sin(0.11 * t)),
        15.0 * np.sin(0.5 * t),
        5.0 * np.sin(0.23 * t + 0.4),
        3.0 * np.sin(0.07 * t),
    ])  # fmt: skip


def rss_kib(pid: int) -> int | None:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    except OSError:
        return None
    return None


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def one_rate(rate_hz: float, minutes: float, speed: float, washouts: list[str], folder: Path, realtime: bool) -> dict:
    dt = 1.0 / rate_hz
    n = round(minutes * 60.0 * rate_hz) + 1
    rows = flight(n, dt).tolist()
    port = free_port()
    sink = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sink.bind(("127.0.0.1", 0))
    sink.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 23)
    sink.settimeout(0.2)
    got = [0]
    done = threading.Event()

    def drain() -> None:
        while not done.is_set():
            try:
                sink.recv(65536)
                got[0] += 1
            except TimeoutError:
                continue

    threading.Thread(target=drain, daemon=True).start()
    out = folder / f"live_{rate_hz:g}"
    cmd = [sys.executable, "-m", "washbench", "live", "--listen", f"127.0.0.1:{port}", "--format", "washbench",
           "--out", str(out), "--no-viewer", "--no-recording", "--no-figures", "--idle-timeout", "1",
           "--rate-hz", f"{rate_hz:g}", "--sink", f"udp://127.0.0.1:{sink.getsockname()[1]}"]  # fmt: skip
    for w in washouts:
        cmd += ["--washout", w]
    if realtime:
        cmd.append("--realtime")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    rss: list[int] = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.connect(("127.0.0.1", port))
        s.settimeout(0.02)
        while True:  # until it listens (a closed port answers the probe with ConnectionRefusedError)
            try:
                s.send(b"?")
                time.sleep(0.05)
                s.recv(1)
            except ConnectionRefusedError:
                continue
            except TimeoutError:
                break
        pacer = Pacer(speed)
        next_rss = time.monotonic()
        for k, r in enumerate(rows):
            pacer.wait(r[0])
            s.send(encode_washbench(k, tuple(r)))
            if time.monotonic() >= next_rss:
                v = rss_kib(proc.pid)
                if v is not None:
                    rss.append(v)
                next_rss += 1.0
    sent_wall = time.perf_counter() - pacer.start
    _, stderr = proc.communicate(timeout=3600)
    done.set()
    if proc.returncode != 0:
        raise SystemExit(f"washbench live failed ({proc.returncode}): {stderr.strip()[-500:]}")
    doc = json.loads((out / "run.json").read_text())["live"]
    return {"rate_hz": rate_hz, "n": n, "sent_wall_s": sent_wall, "live": doc, "sink_got": got[0], "rss": rss}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--rates", type=float, nargs="+", default=[120.0, 1000.0])
    ap.add_argument("--speed", type=float, default=1.0, help="times real time (1: as a simulator sends)")
    ap.add_argument("--washout", action="append", default=[], help="default: the three classical washouts")
    ap.add_argument("--quick", action="store_true", help="1 minute at each rate")
    ap.add_argument("--realtime", action="store_true", help="washbench live --realtime (SCHED_FIFO; needs root)")
    args = ap.parse_args()
    minutes = 1.0 if args.quick else args.minutes
    print(f"washbench live: {minutes:g} min at {', '.join(f'{r:g}' for r in args.rates)} Hz, "
          f"{args.speed:g} x real time, loopback, {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.1f}{', --realtime' if args.realtime else ''}")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        for rate in args.rates:
            r = one_rate(rate, minutes, args.speed, args.washout, Path(tmp), args.realtime)
            live, c, lat = r["live"], r["live"]["counts"], r["live"]["latency"]
            fdm = c172p_in_air(dt_s=1.0 / rate)
            jsb = min(run_cpu_s(fdm, r["n"]) for _ in range(1))
            cpu, wall = live["active_cpu_s"], live["active_wall_s"]
            share = cpu / wall
            rss = r["rss"]
            print(f"\n{rate:g} Hz: {r['n']:,} samples sent in {r['sent_wall_s']:.1f} s; received {c['received']:,}, "
                  f"cued {c['cued']:,}, lost {c['lost_held']}, reordered {c['reordered']}, late {lat['late']}, "
                  f"commands at the sink {r['sink_got']:,}")  # fmt: skip
            print(f"  latency median {lat['latency_median_ms']:.3f} ms, p99 {lat['latency_p99_ms']:.3f} ms, "
                  f"max {lat['latency_max_ms']:.3f} ms; jitter mean {lat['jitter_mean_ms']:.3f} ms, "
                  f"max {lat['jitter_max_ms']:.3f} ms")  # fmt: skip
            print(f"  CPU: live {cpu:.2f} s over the {wall:.1f} s of the session = {100 * share:.1f} % of a core; bare "
                  f"JSBSim for as many steps {jsb:.2f} s CPU: ratio {cpu / jsb:.2f}")  # fmt: skip
            if rss:
                print(f"  memory (resident): start {rss[0] / 1024:.1f} MiB, end {rss[-1] / 1024:.1f} MiB, "
                      f"max {max(rss) / 1024:.1f} MiB ({len(rss)} samples, one a second)")  # fmt: skip
            verdict = "met" if lat["latency_p99_ms"] < 1.0 and c["lost_held"] == 0 else "NOT met"
            if math.isclose(rate, 120.0):
                print(f"  aim (p99 < 1 ms at 120 Hz, nothing lost): {verdict}")


if __name__ == "__main__":
    main()
