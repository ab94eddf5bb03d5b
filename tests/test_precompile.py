"""The kernels compiled at install (washbench.numerics.precompile) are the ones the commands run.

The list of (function, argument types) is written by hand; these tests hold it to what the commands ask numba for:
in a fresh interpreter, a flight with every compiled washout, its recorded traces cued on a hexapod with a set-point
washout (the MPC) and the bound (cued whole: the bound is told the others' motions), streamed with the MPC alone,
and a parameter sweep request their kernels (another platform, the OMCT and a
suite's workers run the same ones: the platform is a branch of the block step), and every request
(numba's own per-dispatcher count of cache hits and misses) must be one the list compiles. With the list complete
and the cache filled (at install, or by the test session's warm-up, tests/warm_kernels.py) nothing is compiled.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from hostile import short

from washbench.numerics import precompile

#: Run in a fresh interpreter (no other test's calls in its dispatchers): the commands, then every washbench
#: dispatcher's requested signatures as JSON on stdout.
PROBE = r"""
import json, sys
from washbench.cli import main

def command(*args):
    try:
        status = main([*args, "--quiet"])
    except SystemExit as exc:
        status = exc.code
    if status not in (0, None):
        raise SystemExit(f"{args[0]}: status {status}")

out, m = sys.argv[1], sys.argv[2]
compiled = ["small-angle", "large-angle", "unrestricted", "adaptive", "adaptive-large-angle", "adaptive-unrestricted"]
command("run", m, "--out", f"{out}/run", "--no-figures", *[a for w in compiled for a in ("--washout", w)])
flight = f"{out}/run/c172p/short/flight.parquet"
from washbench.io.paths import DATA_DIR
command("cue", flight, "--out", f"{out}/cue", "--platform", f"{DATA_DIR}/hexapod.yaml", "--washout", "small-angle",
        "--washout", "mpc", "--washout", "bound", "--no-recording", "--no-figures")
command("cue", flight, "--out", f"{out}/cue-streamed", "--platform", f"{DATA_DIR}/hexapod.yaml", "--washout", "mpc",
        "--no-recording", "--no-figures")
command("sweep", m, "--set", "tilt.gain_per_s=1,2", "--out", f"{out}/sweep")

from numba.core.registry import CPUDispatcher
requested = {}
for name, module in list(sys.modules.items()):
    if not name.startswith("washbench"):
        continue
    for obj in list(vars(module).values()):
        if isinstance(obj, CPUDispatcher):
            key = f"{obj.py_func.__module__}.{obj.py_func.__name__}"
            sigs = requested.setdefault(key, {"hits": set(), "misses": set()})
            sigs["hits"].update(str(s) for s in obj._cache_hits)
            sigs["misses"].update(str(s) for s in obj._cache_misses)
print(json.dumps({k: {h: sorted(v) for h, v in d.items()} for k, d in requested.items()}))
"""


def _listed() -> dict[str, set[str]]:
    """The precompile list as {module.function: {str(argument types)}}, numba's own spelling of a signature."""
    from numba.core.sigutils import normalize_signature

    listed: dict[str, set[str]] = {}
    for lane in precompile.KERNELS:
        for module, name, signature in lane:
            args, _ = normalize_signature(signature)
            listed.setdefault(f"{module}.{name}", set()).add(str(tuple(args)))
    return listed


def test_every_kernel_a_command_asks_for_is_precompiled_and_none_is_compiled(tmp_path: Path) -> None:
    m = short(tmp_path, seconds=2)
    proc = subprocess.run([sys.executable, "-c", PROBE, str(tmp_path / "out"), str(m)], capture_output=True,
                          text=True, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    requested = json.loads(proc.stdout.strip().splitlines()[-1])
    listed = _listed()
    asked = {(k, s) for k, d in requested.items() for s in d["hits"] + d["misses"]}
    missing = sorted((k, s) for k, s in asked if s not in listed.get(k, set()))
    assert not missing, f"kernels the commands ask for that washbench.numerics.precompile does not compile: {missing}"
    # the probe measured something: the block step and the set-point paths (hexapod, MPC, streamed and whole), a
    # flight, an evaluation
    for key in ("washbench.cueing.kernel.bank_block", "washbench.cueing.kernel.setpoint_block",
                "washbench.cueing.kernel.setpoint_trace", "washbench.flight.stepper.flight_step",
                "washbench.analysis.evaluate.evaluate_batch"):  # fmt: skip
        assert requested.get(key, {}).get("hits"), (key, requested.get(key))
    compiled = sorted((k, s) for k, d in requested.items() for s in d["misses"])
    assert not compiled, f"compiled although the cache was filled: {compiled}"
    assert "compiling the numerical kernels" not in proc.stderr


def test_the_list_names_compiled_functions_with_types_numba_reads() -> None:
    """Each entry is a numba dispatcher (or a lazily compiled function) and its types parse, with no duplicates."""
    from numba.core.registry import CPUDispatcher
    from numba.core.sigutils import normalize_signature

    seen = set()
    for lane in precompile.KERNELS:
        for module, name, signature in lane:
            assert isinstance(precompile.dispatcher(module, name), CPUDispatcher), (module, name)
            args, ret = normalize_signature(signature)
            assert ret is None and args, signature
            assert (module, name, signature) not in seen
            seen.add((module, name, signature))


def test_the_stale_cache_stamp_sits_where_numba_caches_the_kernels(tmp_path: Path) -> None:
    """``drop_stale_cache`` keeps its stamp, and deletes stale files, in the folder numba caches a module's kernels in:
    the package's ``__pycache__``, or ``NUMBA_CACHE_DIR`` where one is set (a read-only install's user cache)."""
    code = (
        "import sys; from pathlib import Path; from washbench.cueing import kernel; "
        "from washbench.numerics.jitcache import _cache_dir; "
        "print(_cache_dir(Path(kernel.__file__).resolve())); print(kernel.bank_block._cache._cache_path)"
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    for environ in (env, {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}):
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=environ, timeout=120)
        assert proc.returncode == 0, proc.stderr
        stamp_dir, numba_dir = proc.stdout.split()
        assert Path(stamp_dir).resolve() == Path(numba_dir).resolve()
    assert Path(stamp_dir).name == "__pycache__"  # the second: numba's default, next to the sources
    assert (Path(numba_dir).parent / "kernel.py").is_file()
