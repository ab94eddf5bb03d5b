"""The MPC washout on a hexapod plans against the legs (washbench/cueing/mpc_legs.py, docs/optimal-mpc.md).

The hexapod is test_platforms' own (never bundled). The MPC is driven into its workspace's edge by a strong
sustained input; its plan's poses are then propagated through its linear model and the legs recomputed from them
with scipy's rotations (not washbench's kinematics). The end-to-end check on a violent flight (the set points'
legs recomputed from traces.parquet) is in test_platforms.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from test_platforms import LMAX, LMIN, VMAX, hexapod_file, legs_from_pose

from washbench.cueing.algorithm import WashoutContext
from washbench.cueing.mpc import MpcWashout, stacked_inputs
from washbench.platform.model import load_platform_model, planning_limits

G = 9.80665
DT = 1.0 / 120.0


def legs_of(y: np.ndarray) -> np.ndarray:
    """Leg lengths (N, 6) of poses y (N, 6) = [p (m, NED); roll, pitch, yaw (rad, ZYX)], by scipy's rotation."""
    y = np.atleast_2d(y)
    q = Rotation.from_euler("ZYX", y[:, [5, 4, 3]]).as_quat()[:, [3, 0, 1, 2]]  # scalar first
    return legs_from_pose(y[:, :3], q)


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """The MPC after 2 s of a strong sustained surge, heave and rotation input, and its plan from there."""
    hexapod = load_platform_model(hexapod_file(tmp_path_factory.mktemp("legs") / "hexapod.yaml"))
    ctx = WashoutContext(DT, G, planning_limits(hexapod), "steady", (0.0, 0.0, 0.0), platform=hexapod)
    mpc = MpcWashout(None, ctx)
    mpc.start(np.array([0.0, 0.0, -G]), np.zeros(3))
    for k in range(240):
        f = np.array([5.0, -3.0 * np.sin(2.0 * k * DT), -G - 2.0])
        w = np.array([0.3, -0.2, 0.4])
        mpc.step(f, w)
    r = stacked_inputs(f, w, G)
    x0 = mpc.x.copy()
    ok, plan = mpc.plan(r)
    assert ok
    refs = mpc._references(r)
    xs = [x0]
    for k in range(mpc.N):  # the plan's nodes, through the MPC's own model (what the plan means)
        xs.append(mpc.phi_p @ xs[-1] + mpc.gam_p @ plan[k] + mpc.gam_rp @ refs[k])
    sm = mpc.model
    y = np.array([np.concatenate([x[sm.i_pos], x[sm.i_tilt] + np.append(x[sm.i_rot], 0.0)]) for x in xs])
    # the rows' prediction of the nodes' leg lengths: rows z + (len_lo - lo), z in the whitened variables
    rows = np.empty_like(mpc.qp.var_rows)
    lo, _ = mpc.legs.rows(y[0], np.concatenate([x0, refs.ravel()]), rows)
    n_len = 6 * mpc.N
    zy = np.linalg.solve(mpc.qp.r_inv, plan.ravel())
    pred = (rows[:n_len] @ zy + (mpc.legs.len_lo - lo[:n_len])).reshape(mpc.N, 6)
    return {"mpc": mpc, "y": y, "pred": pred, "plan": plan}


def test_the_rows_are_the_legs_linearised_about_the_current_pose(planned):
    """l(y_0) + D (y_k - y_0), D by central differences of the recomputed legs, is what the rows predict."""
    y = planned["y"]
    eps = 1e-6
    d = np.column_stack([(legs_of(y[0] + eps * e) - legs_of(y[0] - eps * e))[0] / (2 * eps) for e in np.eye(6)])
    lin = legs_of(y[0])[0] + (y[1:] - y[0]) @ d.T
    np.testing.assert_allclose(planned["pred"], lin, rtol=0, atol=1e-8)


def test_the_prediction_is_within_the_linearisation_error_and_the_plan_in_stroke(planned):
    """Each node's recomputed legs differ from the prediction by at most Taylor's remainder
    1/2 max_s |d^2 l / ds^2| along the segment from y_0 (second differences of the recomputed legs), the first
    node (0.1 s ahead) by under a millimetre; the plan's constraint acts (a leg at its margin) and every node of
    the plan has its legs inside the stroke."""
    mpc, y, pred = planned["mpc"], planned["y"], planned["pred"]
    exact = legs_of(y[1:])
    h = 1e-3
    for k in range(mpc.N):
        step = y[k + 1] - y[0]
        s = np.linspace(0.0, 1.0, 21)
        curv = [(legs_of(y[0] + (c + h) * step) - 2 * legs_of(y[0] + c * step) + legs_of(y[0] + (c - h) * step))[0]
                / h**2 for c in s]  # fmt: skip
        bound = 0.5 * np.max(np.abs(curv), axis=0)
        assert np.all(np.abs(exact[k] - pred[k]) <= 1.1 * bound + 1e-9), k
    assert np.abs(exact[0] - pred[0]).max() < 1e-3
    tol = 1e-5  # DAQP's feasibility tolerance on a row, m
    assert np.all(pred >= mpc.legs.len_lo - tol) and np.all(pred <= mpc.legs.len_hi + tol)
    assert np.isclose(pred.min(), mpc.legs.len_lo, atol=tol) or np.isclose(pred.max(), mpc.legs.len_hi, atol=tol)
    assert exact.min() > LMIN and exact.max() < LMAX


def test_the_first_moves_keep_the_legs_speed(planned):
    """The leg speeds of the first move, recomputed (central differences of the recomputed legs along the move's
    start: v and the angle rates), within the margin of the limit."""
    mpc, y, plan = planned["mpc"], planned["y"], planned["plan"]
    sm = mpc.model
    rates = plan[0][sm.j_rot] + np.append(plan[0][sm.j_tilt], 0.0)
    ydot = np.concatenate([mpc.x[sm.i_vel], rates])
    eps = 1e-5
    speed = (legs_of(y[0] + eps * ydot) - legs_of(y[0] - eps * ydot))[0] / (2 * eps)
    assert np.abs(speed).max() <= mpc.params.limit_margin * VMAX * (1 + 1e-6)
