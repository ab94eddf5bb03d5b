"""washbench.numerics.statespace.tf2ss against scipy.signal.tf2ss: the same matrices, bit for bit."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from washbench.numerics.statespace import tf2ss
from washbench.perception.vestibular import CanalParams, OtolithParams, canal_tf, otolith_tf

COEF = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


def same_bits(ours: tuple[np.ndarray, ...], theirs: tuple[np.ndarray, ...]) -> None:
    for a, b in zip(ours, theirs, strict=True):
        assert a.shape == b.shape and a.dtype == b.dtype
        assert a.tobytes() == b.tobytes()


@pytest.mark.parametrize("tf", [otolith_tf(OtolithParams()), canal_tf(CanalParams())], ids=["otolith", "canal"])
def test_the_vestibular_models_are_scipys(tf):
    same_bits(tf2ss(*tf), signal.tf2ss(*tf))


@pytest.mark.filterwarnings("ignore::scipy.signal.BadCoefficients")
@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    den=st.lists(COEF, min_size=2, max_size=5).filter(lambda d: abs(d[0]) > 1e-3),
    num=st.lists(COEF, min_size=1, max_size=5),
)
def test_any_proper_function_is_scipys(den, num):
    num = num[: len(den)]  # proper
    same_bits(tf2ss(num, den), signal.tf2ss(num, den))


@pytest.mark.filterwarnings("ignore::scipy.signal.BadCoefficients")
@pytest.mark.parametrize("num", [[0.0, 0.0, 2.0, 1.0], [1e-15, 2.0, 1.0], [0.0], [0.0, 0.0]])
def test_leading_zeros_are_dropped_as_scipy_drops_them(num):
    den = [0.0, 1.0, 3.0, 2.0]
    same_bits(tf2ss(num, den), signal.tf2ss(num, den))


@pytest.mark.parametrize(("num", "den"), [([1.0, 2.0, 3.0], [1.0, 2.0]), ([1.0], [0.0, 0.0]), ([1.0], [2.0])])
def test_improper_zero_or_static_is_a_value_error(num, den):
    with pytest.raises(ValueError, match="tf2ss"):
        tf2ss(num, den)


def test_the_model_washouts_and_the_bound_do_not_import_scipy_signal():
    """Importing scipy.signal took 1.3 s of every process with an optimal or MPC washout or the bound."""
    code = (
        "import sys; import washbench.cueing.mpc, washbench.cueing.mpc_unrestricted, washbench.cueing.optimal, "
        "washbench.analysis.bound, washbench.analysis.bound_replay, washbench.analysis.ceiling; "
        "print('scipy.signal' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
