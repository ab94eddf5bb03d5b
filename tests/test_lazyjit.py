"""numerics.lazyjit: a module's compiled functions without numba at import, compiled together at the first call."""

from __future__ import annotations

import subprocess
import sys

import numpy as np


def test_the_chain_imports_without_numba_and_compiles_at_the_first_call() -> None:
    code = (
        "import sys\n"
        "import numpy as np\n"
        "import washbench.runs.chain, washbench.perception.svc as svc, washbench.perception.sickness as sk\n"
        "print('numba' in sys.modules)\n"
        "sk.head_msdv(np.full(600, -9.80665) + np.sin(np.arange(600) / 20.0), 1 / 120)\n"
        "print('numba' in sys.modules, type(sk._biquad).__module__.split('.')[0])\n"
        "svc.svc_msi(np.tile([0.5, 0.0, -9.80665], (240, 1)), np.zeros((240, 3)), 1 / 120)\n"
        "print(*(type(getattr(svc, n)).__module__.split('.')[0] for n in ('_cross', '_deriv', '_run')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[:3] == ["False", "True numba", "numba numba numba"]


def test_the_compiled_function_computes_what_its_python_source_does() -> None:
    from washbench.perception import sickness

    rng = np.random.default_rng(5)
    x = rng.normal(size=500)
    args = (0.2, 0.4, 0.2, -0.5, 0.25, x)
    compiled = sickness._biquad  # the dispatcher once any lazy function of the module has been called
    fn = getattr(compiled, "py_func", compiled)
    np.testing.assert_allclose(np.asarray(compiled(*args)), fn(*args), rtol=0, atol=1e-12)
    # a direct-form II transposed biquad from rest, by its difference equation written out here
    y = np.zeros_like(x)
    for n in range(len(x)):
        y[n] = 0.2 * x[n] + (0.4 * x[n - 1] if n >= 1 else 0.0) + (0.2 * x[n - 2] if n >= 2 else 0.0)
        y[n] -= (-0.5 * y[n - 1] if n >= 1 else 0.0) + (0.25 * y[n - 2] if n >= 2 else 0.0)
    np.testing.assert_allclose(fn(*args), y, rtol=0, atol=1e-12)
