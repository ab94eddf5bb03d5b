"""Start-up and whole-command wall time of ``washbench`` commands against a bare JSBSim process.

Each command runs as its own process (as a user starts it), several times; the minimum is printed
(the machine may be shared). The baseline, measured in the same run, is a bare Python process that
imports JSBSim, loads c172p, initialises it and runs the same number of ``fdm.run()`` steps as the
command's flight (0 for ``validate`` and ``cue``): what any JSBSim-based tool pays at least.

    .venv/bin/python bench/startup_bench.py [--repeat 5]

Commands: ``washbench validate`` (one bundled file), ``washbench cue`` on a 2 s 120 Hz CSV,
``washbench run`` and ``washbench run --no-recording`` on a 2 s level flight (c172p, trimmed), one
``washbench run`` of the bundled c172 takeoff (10,668 steps), ``cue`` and ``run`` also with neither the recording nor
the figures (``--no-recording --no-figures``), and the imports each pulls in
(``python -X importtime``, the slowest top-level packages). Wall and CPU time are both printed: on a
shared machine the CPU time is the steadier figure.
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
LEAN = ("--no-recording", "--no-figures")
"""The outputs' switches: "neither" = no recording.rrd and no figures."""
SHORT = """\
name: short
description: 2 s of level flight (start-up benchmark)
aircraft: c172p
start:
  air: {altitude_ft: 4000, airspeed_kts: 95, heading_deg: 90}
phases:
  - name: level
    hold: {wings_level: true, altitude_ft: 4000, airspeed_kts: 95}
    until: {duration_s: 2}
checks:
  - {name: altitude held, signal: altitude_ft, stat: max_deviation, max: 60}
"""
BARE = """\
import os, sys
os.environ["JSBSIM_DEBUG"] = "0"
import jsbsim
fdm = jsbsim.FGFDMExec(jsbsim.get_default_root_dir())
fdm.load_model("c172p")
fdm.set_dt(1.0 / 120.0)
fdm["ic/h-sl-ft"] = 4000.0
fdm["ic/vc-kts"] = 95.0
fdm.run_ic()
for _ in range(int(sys.argv[1])):
    fdm.run()
"""


def wall(cmd: list[str], repeat: int, cwd: Path) -> tuple[float, float]:
    """Minimum wall time and minimum CPU time (user + system) of ``cmd`` over ``repeat`` runs."""
    best, best_cpu = float("inf"), float("inf")
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        done = subprocess.run(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        best = min(best, time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        best_cpu = min(best_cpu, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
        if done.returncode not in (0, 1):
            raise SystemExit(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()}")
    return best, best_cpu


def top_imports(args: list[str], cwd: Path, n: int = 6) -> str:
    """The ``n`` top-level packages with the largest cumulative import time (from ``-X importtime``)."""
    done = subprocess.run([sys.executable, "-X", "importtime", "-m", "washbench", *args], cwd=cwd,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)  # fmt: skip
    cumulative: dict[str, int] = {}
    for line in done.stderr.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        _, cum, name = line.split("|")
        if name.startswith("  "):  # a nested import: counted in its parent
            continue
        try:
            cumulative[name.strip()] = int(cum)
        except ValueError:
            continue
    total = sum(cumulative.values())
    best = sorted(cumulative.items(), key=lambda kv: -kv[1])[:n]
    return f"imports {total / 1e6:.2f} s: " + ", ".join(f"{k} {v / 1e6:.2f}" for k, v in best)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per command; the minimum is printed")
    args = parser.parse_args()
    exe = [sys.executable, "-m", "washbench"]
    env_ok = os.environ.get("JSBSIM_DEBUG")
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        (tmp / "short.yaml").write_text(SHORT)
        (tmp / "bare.py").write_text(BARE)
        lines = ["t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps"]
        for k in range(240):
            t = k / 120.0
            lines.append(f"{t!r},{math.sin(t)!r},0.0,-9.80665,{math.cos(t)!r},0.0,0.0")
        (tmp / "short.csv").write_text("\n".join(lines) + "\n")
        takeoff = str(HERE.parent / "manoeuvres" / "c172" / "takeoff.yaml")
        validate_file = takeoff
        cases = [
            ("validate", ["validate", validate_file], 0),
            ("cue, 2 s at 120 Hz", ["cue", "short.csv", "--out", "cue_out"], 0),
            ("cue, 2 s, neither", ["cue", "short.csv", "--out", "cue_out2", *LEAN], 0),
            ("run, 2 s flight", ["run", "short.yaml", "--out", "run_out", "--quiet"], 240),
            ("run --no-recording, 2 s", ["run", "short.yaml", "--out", "run_out2", "--quiet", "--no-recording"], 240),
            ("run, 2 s, neither", ["run", "short.yaml", "--out", "run_out4", "--quiet", *LEAN], 240),
            ("run, c172 takeoff (89 s)", ["run", takeoff, "--out", "run_out3", "--quiet"], 10668),
            ("run, takeoff, neither", ["run", takeoff, "--out", "run_out5", "--quiet", *LEAN], 10668),
        ]
        # compile or load the numba cache once, so the first timed run is not the one that compiles
        subprocess.run([*exe, "cue", "short.csv", "--out", "warm"], cwd=tmp, stdout=subprocess.DEVNULL, check=True)
        bare = {steps: wall([sys.executable, "bare.py", str(steps)], args.repeat, tmp) for steps in (0, 240, 10668)}
        print("bare JSBSim process (import, load c172p, run_ic, N steps), wall / CPU s: "
              + ", ".join(f"N={n}: {w:.3f} / {c:.3f}" for n, (w, c) in bare.items()))  # fmt: skip
        print(f"(minimum of {args.repeat} runs each; CPU = user + system of the process; JSBSIM_DEBUG={env_ok!r})")
        print(f"{'command':28s} {'wall s':>7s} {'x bare':>6s} {'CPU s':>7s} {'x bare':>6s}   slowest imports (s)")
        for label, cmd, steps in cases:
            missing = [o for o in ("--no-recording", "--no-figures") if o in cmd and o not in _help(exe, tmp)]
            if missing:
                print(f"{label:28s} {'n/a':>8s}   (this version has no {missing[0]})")
                continue
            w, c = wall([*exe, *cmd], args.repeat, tmp)
            bw, bc = bare[steps]
            print(f"{label:28s} {w:7.3f} {w / bw:6.2f} {c:7.3f} {c / bc:6.2f}   {top_imports(cmd, tmp)}")


def _help(exe: list[str], cwd: Path) -> str:
    return subprocess.run([*exe, "run", "--help"], cwd=cwd, capture_output=True, text=True).stdout


if __name__ == "__main__":
    main()
