"""Column names: washbench's input motion and the traces table (``traces.parquet``), the one place that spells them.

Input motion (``washbench cue INPUT``) in washbench's own columns, one row per sample, body axes
(x forward, y right, z down), time uniform and increasing (other layouts: :mod:`washbench.io.readers`)::

    t_s, f_x_mps2, f_y_mps2, f_z_mps2, omega_x_degps, omega_y_degps, omega_z_degps

Other columns are ignored by the cueing but kept in :attr:`washbench.io.motion.Motion.extra` and written back
unchanged to ``traces.parquet`` (e.g. the flight pipeline's state columns).

``DIR/traces.parquet`` (see :func:`motion_columns` and :func:`washout_columns`; written and read by
:mod:`washbench.io.parquet_files`)::

    t_s
    S.f_{x,y,z}_mps2, S.omega_{x,y,z}_degps                  head motion of pilot S
    S.perceived_f_{x,y,z}_mps2, S.perceived_omega_{x,y,z}_degps   vestibular model output
        for S = "aircraft" and for each washout W (its simulator pilot)
    W.pos_{x,y,z}_m, W.vel_{x,y,z}_mps, W.acc_{x,y,z}_mps2   platform centre, NED inertial
    W.q_{w,x,y,z}                                            platform attitude, body -> inertial
    W.omega_platform_{x,y,z}_degps                           platform angular velocity, body axes
    W.wheel_{1,2,3}_radps                                    Atlas omni-wheel speeds (the Atlas only)
    W.leg_{1..6}_m                                           hexapod leg lengths, joint to joint (a hexapod only)
    W.sp_pos_{x,y,z}_m, W.sp_q_{w,x,y,z}                     the washout's set points for the platform
    W.tilt_rate_degps                                        tilt-coordination rate commanded (empty: none known)
    W.sat_<kind>                                             saturation flags, 0/1 (int8)
    <extra input columns, unchanged>

The columns of ``metrics.csv`` are in :mod:`washbench.io.metrics_csv`.
"""

from __future__ import annotations

from collections.abc import Iterable

AXES = ("x", "y", "z")
TIME_COLUMN = "t_s"
F_COLUMNS = tuple(f"f_{a}_mps2" for a in AXES)
OMEGA_COLUMNS = tuple(f"omega_{a}_degps" for a in AXES)
INPUT_COLUMNS = (TIME_COLUMN, *F_COLUMNS, *OMEGA_COLUMNS)
"""The required input columns, in order."""

AIRCRAFT = "aircraft"
"""Source name of the aircraft pilot in traces.parquet."""


def f_columns(source: str) -> tuple[str, str, str]:
    """Head specific force of pilot ``source`` [m/s^2], body x, y, z."""
    return tuple(f"{source}.f_{a}_mps2" for a in AXES)  # type: ignore[return-value]


def omega_columns(source: str) -> tuple[str, str, str]:
    """Head angular velocity of pilot ``source`` [deg/s], body x, y, z."""
    return tuple(f"{source}.omega_{a}_degps" for a in AXES)  # type: ignore[return-value]


def perceived_f_columns(source: str) -> tuple[str, str, str]:
    """Perceived specific force (otolith model output) of pilot ``source`` [m/s^2]."""
    return tuple(f"{source}.perceived_f_{a}_mps2" for a in AXES)  # type: ignore[return-value]


def perceived_omega_columns(source: str) -> tuple[str, str, str]:
    """Perceived angular velocity (canal model output) of pilot ``source`` [deg/s]."""
    return tuple(f"{source}.perceived_omega_{a}_degps" for a in AXES)  # type: ignore[return-value]


def motion_columns(source: str) -> tuple[str, ...]:
    """All 12 head-motion and perception columns of one pilot, in table order."""
    return (
        *f_columns(source),
        *omega_columns(source),
        *perceived_f_columns(source),
        *perceived_omega_columns(source),
    )


def pos_columns(washout: str) -> tuple[str, str, str]:
    """Platform position, NED inertial [m]."""
    return tuple(f"{washout}.pos_{a}_m" for a in AXES)  # type: ignore[return-value]


def vel_columns(washout: str) -> tuple[str, str, str]:
    """Platform velocity, NED inertial [m/s]."""
    return tuple(f"{washout}.vel_{a}_mps" for a in AXES)  # type: ignore[return-value]


def acc_columns(washout: str) -> tuple[str, str, str]:
    """Platform acceleration, NED inertial [m/s^2]."""
    return tuple(f"{washout}.acc_{a}_mps2" for a in AXES)  # type: ignore[return-value]


def q_columns(washout: str) -> tuple[str, str, str, str]:
    """Platform attitude quaternion, scalar first, body -> inertial."""
    return tuple(f"{washout}.q_{c}" for c in ("w", "x", "y", "z"))  # type: ignore[return-value]


def omega_platform_columns(washout: str) -> tuple[str, str, str]:
    """Platform angular velocity, body axes [deg/s]."""
    return tuple(f"{washout}.omega_platform_{a}_degps" for a in AXES)  # type: ignore[return-value]


def wheel_columns(washout: str) -> tuple[str, str, str]:
    """Atlas omni-wheel speeds [rad/s]."""
    return tuple(f"{washout}.wheel_{i}_radps" for i in (1, 2, 3))  # type: ignore[return-value]


def leg_columns(washout: str) -> tuple[str, ...]:
    """Hexapod leg lengths, joint to joint [m], in the order of the platform file's joints."""
    return tuple(f"{washout}.leg_{i}_m" for i in range(1, 7))


def sp_pos_columns(washout: str) -> tuple[str, str, str]:
    """The washout's position set point for the platform, NED inertial [m]."""
    return tuple(f"{washout}.sp_pos_{a}_m" for a in AXES)  # type: ignore[return-value]


def sp_q_columns(washout: str) -> tuple[str, str, str, str]:
    """The washout's attitude set point for the platform, scalar first, body -> inertial."""
    return tuple(f"{washout}.sp_q_{c}" for c in ("w", "x", "y", "z"))  # type: ignore[return-value]


def tilt_rate_column(washout: str) -> str:
    """The tilt-coordination rate the washout commanded [deg/s], after its tilt-rate limit and measured as that limit
    measures it (``WashoutTrace.tilt_rate_radps``); empty (null, NaN when read by numpy) for a washout that reports
    none."""
    return f"{washout}.tilt_rate_degps"


def sat_column(washout: str, kind: str) -> str:
    """Saturation flag column (0/1) of one limit ``kind``."""
    return f"{washout}.sat_{kind}"


def washout_columns(washout: str, sat_kinds: Iterable[str]) -> tuple[str, ...]:
    """All columns of one washout in table order (its pilot's motion, then the platform)."""
    return (
        *motion_columns(washout),
        *pos_columns(washout),
        *vel_columns(washout),
        *acc_columns(washout),
        *q_columns(washout),
        *omega_platform_columns(washout),
        *wheel_columns(washout),
        *sp_pos_columns(washout),
        *sp_q_columns(washout),
        tilt_rate_column(washout),
        *(sat_column(washout, k) for k in sat_kinds),
    )
