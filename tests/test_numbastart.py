"""numba's light cache load (:mod:`washbench.numerics.numbastart`): the kernels a command loads from the cache give
the bits numba's own load gives, without its registries, and a compilation after a light load still works."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pyarrow.parquet as pq
import pytest

from washbench.numerics.numbastart import LIGHT_LOAD_VERSIONS

pytestmark = pytest.mark.skipif(
    not numba.__version__.startswith(LIGHT_LOAD_VERSIONS), reason=f"numba {numba.__version__} loads as it always does"
)

# a cue in a fresh process, with numba's cache loads as washbench makes them ("light") or with numba's whole context
# refreshed first, as its own cache load does ("full": the registries installed, so every later load finds them)
CUE = """
import hashlib, json, sys
mode, src, out = sys.argv[1:4]
if mode == "full":
    from numba.core.registry import cpu_target
    cpu_target.target_context.refresh()
from washbench.cli import main
status = main(["cue", src, "--out", out, "--no-recording", "--no-figures", "--quiet",
               "--washout", "small-angle", "--washout", "large-angle", "--washout", "unrestricted"])
# the whole-trace bank (bank_trace: one washout per thread, prange) on numba's threads
import numpy as np
from washbench.cueing import WASHOUT_NAMES, cue_trace, load_washout_params
from washbench.platform import load_platform_limits
t = np.arange(3000) / 120.0
f = np.column_stack([np.sin(t), 0.5 * np.cos(0.3 * t), -9.80665 + 0.2 * np.sin(2 * t)])
w = np.column_stack([0.2 * np.sin(t), 0.1 * np.cos(t), 0.05 * np.sin(0.5 * t)])
traces = cue_trace(f, w, 1 / 120.0, WASHOUT_NAMES, load_washout_params(None), load_platform_limits(None))
digest = hashlib.sha256()
for name in sorted(traces):
    for field in ("pos_m", "q", "head_f_mps2", "head_omega_radps"):
        digest.update(np.ascontiguousarray(getattr(traces[name], field)).tobytes())
import numba.np.ufunc.parallel as parallel
from numba.core import caching
print(json.dumps({"status": status, "light": getattr(caching.Cache.load_overload, "washbench_light", False),
                  "registries": "numba.np.npyimpl" in sys.modules, "parallel": digest.hexdigest(),
                  "threads": parallel.threading_layer()}))
"""


def _input(path: Path) -> Path:
    """20 s at 120 Hz of a manoeuvre-like motion: a pull-up, a roll and a yaw on level flight's 1 g."""
    t = np.arange(2400) / 120.0
    g = 9.80665
    pulse = np.exp(-(((t - 8.0) / 2.0) ** 2))
    cols = {
        "t_s": t,
        "f_x_mps2": 0.6 * np.tanh(t - 4.0),
        "f_y_mps2": 0.9 * np.sin(0.8 * t) * pulse,
        "f_z_mps2": -g * (1.0 + 0.8 * pulse),
        "omega_x_degps": 20.0 * np.sin(1.1 * t) * np.exp(-(((t - 12.0) / 3.0) ** 2)),
        "omega_y_degps": 6.0 * np.gradient(pulse, t),
        "omega_z_degps": 4.0 * pulse,
    }
    lines = [",".join(cols)] + [",".join(repr(float(v)) for v in row) for row in zip(*cols.values(), strict=True)]
    path.write_text("\n".join(lines) + "\n")
    return path


def _cue(mode: str, src: Path, out: Path) -> dict[str, object]:
    proc = subprocess.run([sys.executable, "-c", CUE, mode, str(src), str(out)], capture_output=True, text=True,
                          timeout=300, check=False)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_a_light_load_gives_the_bits_of_numbas_own_load_without_its_registries(tmp_path: Path) -> None:
    """A cue (the streamed bank, perception, metrics) and the whole-trace bank on numba's threads, in a process
    loading light and in one after numba's full refresh: the same bytes in every column, metrics.csv and digest."""
    src = _input(tmp_path / "in.csv")
    light = _cue("light", src, tmp_path / "light")
    full = _cue("full", src, tmp_path / "full")
    assert (light["status"], light["light"], light["registries"]) == (0, True, False)  # no registry loaded
    assert (full["status"], full["light"], full["registries"]) == (0, True, True)
    assert light["parallel"] == full["parallel"]  # the parallel kernel's traces
    assert light["threads"] == full["threads"] != ""  # it started numba's threading layer
    a, b = pq.read_table(tmp_path / "light" / "traces.parquet"), pq.read_table(tmp_path / "full" / "traces.parquet")
    assert a.column_names == b.column_names and a.num_rows == 2400
    for name in a.column_names:
        x, y = a[name].to_numpy(), b[name].to_numpy()
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), name
    assert (tmp_path / "light" / "metrics.csv").read_bytes() == (tmp_path / "full" / "metrics.csv").read_bytes()


COMPILE_AFTER = """
import numpy as np
from washbench.numerics.rotations import qmul
print(qmul((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0)))  # a cached kernel, loaded light
from numba import njit
@njit
def f(a):  # compiled now: numpy's array functions, which only the registries know
    return np.sum(np.cumsum(a)), np.linalg.norm(a)
print(f(np.arange(5.0)))
"""


def test_a_function_compiled_after_a_light_load_finds_the_registries() -> None:
    proc = subprocess.run([sys.executable, "-c", COMPILE_AFTER], capture_output=True, text=True, timeout=300,
                          check=False)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    loaded, compiled = proc.stdout.strip().splitlines()
    assert loaded == "(0.0, 1.0, 0.0, 0.0)"
    assert compiled == f"({float(np.sum(np.cumsum(np.arange(5.0))))}, {float(np.linalg.norm(np.arange(5.0)))})"

