"""The recording's 3D scene: the aircraft and each washout's platform cockpit side by side (rows of at most
:data:`MAX_PER_ROW`), in one NED frame.

Every object is the same line shape (fuselage with a nose chevron, wings, tailplane, fin) over a translucent floor
plate, so roll, pitch and yaw read at a glance and the aircraft and the cockpits point the same way when their
attitudes agree. The aircraft is shown relative to its initial heading (the cockpits start at yaw 0). Each Atlas
cockpit sits in its sphere (``envelope.sphere_diameter_m``) and is translated by the stage position inside the stage's
range box (a hexapod drawn with its legs, a rig or a plugin's platform as a base and the cockpit at its pose). One
label per object. Poses are sent at most at :data:`SCENE_RATE_HZ`: the 3D view shows one instant, and
scrubbing or playing needs no more; of those, only the ones that differ from the last one sent by more than
:data:`POSE_ANGLE_TOLERANCE_DEG` or :data:`POSE_TRANSLATION_TOLERANCE_M` (the view holds the latest pose), and one at
least every :data:`POSE_MAX_GAP_S`.
"""

from __future__ import annotations

import math

import numpy as np
import rerun as rr

from washbench.review.blueprint import AIRCRAFT_COLOR, LIMIT_COLOR, series_color
from washbench.review.thinning import keep_changes

__all__ = [
    "POSE_ANGLE_TOLERANCE_DEG",
    "POSE_MAX_GAP_S",
    "POSE_TRANSLATION_TOLERANCE_M",
    "SCENE_RATE_HZ",
    "camera",
    "grid_shape",
    "label_points",
    "object_offsets",
    "pose_samples",
    "relative_to_initial_heading",
    "scene_extent",
    "scene_stride",
    "send_scene",
]

SCENE_RATE_HZ = 30.0
"""Highest rate of the 3D poses, Hz."""

POSE_ANGLE_TOLERANCE_DEG = 0.1
"""A held pose is at most this far (rotation angle) from the pose at any step it stands for, deg."""

POSE_TRANSLATION_TOLERANCE_M = 0.001
"""A held stage position is within this of the position at any step it stands for, per axis, m."""

POSE_MAX_GAP_S = 1.0
"""At least one pose every this many seconds, s."""


def quat_wxyz_to_xyzw(q_wxyz: np.ndarray) -> np.ndarray:
    """Convert scalar-first quaternions (..., 4) [w, x, y, z] to rerun's scalar-last [x, y, z, w].

    The only place in washbench where quaternion order changes.
    """
    q_wxyz = np.asarray(q_wxyz, dtype=np.float64)
    return np.concatenate([q_wxyz[..., 1:4], q_wxyz[..., 0:1]], axis=-1)


def relative_to_initial_heading(q_wxyz: np.ndarray) -> np.ndarray:
    """Body->NED quaternions (N, 4), scalar first, turned about NED z so that the first sample's heading is 0.

    ``q_rel = q_z(-psi_0) q``, with psi_0 the ZYX yaw of ``q[0]``; roll and pitch are unchanged.
    """
    q = np.asarray(q_wxyz, dtype=np.float64)
    w, x, y, z = q[0]
    psi0 = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    c, s = math.cos(-psi0 / 2.0), math.sin(-psi0 / 2.0)  # r = [c, 0, 0, s]; r * q (Hamilton)
    return np.column_stack(
        [
            c * q[:, 0] - s * q[:, 3],
            c * q[:, 1] - s * q[:, 2],
            c * q[:, 2] + s * q[:, 1],
            c * q[:, 3] + s * q[:, 0],
        ]
    )


def scene_stride(dt_s: float) -> int:
    """Send every k-th pose so that the 3D rate is at most SCENE_RATE_HZ."""
    return max(1, math.floor(1.0 / (dt_s * SCENE_RATE_HZ) + 1e-9))


def pose_samples(t_s: np.ndarray, q_wxyz: np.ndarray, pos_m: np.ndarray | None = None) -> np.ndarray:
    """Indices of the poses to send: every :func:`scene_stride`-th step, of those the ones that move by more than the
    pose tolerances from the last one kept (quaternion components within sin(angle / 4) of each other bound the
    rotation between them by the angle), one at least every :data:`POSE_MAX_GAP_S`, and the last step."""
    stride = scene_stride(float(t_s[1] - t_s[0])) if t_s.size > 1 else 1
    idx = np.unique(np.append(np.arange(0, t_s.size, stride), t_s.size - 1))
    columns = [np.asarray(q_wxyz, dtype=np.float64)[idx]]
    tol = [np.full(4, math.sin(math.radians(POSE_ANGLE_TOLERANCE_DEG) / 4.0))]
    if pos_m is not None:
        columns.append(np.asarray(pos_m, dtype=np.float64)[idx])
        tol.append(np.full(3, POSE_TRANSLATION_TOLERANCE_M))
    dt_rows = float(t_s[idx[1]] - t_s[idx[0]]) if idx.size > 1 else 1.0
    gap = max(1, math.floor(POSE_MAX_GAP_S / dt_rows + 1e-9))
    return idx[keep_changes(np.column_stack(columns), np.concatenate(tol), gap)]


MAX_PER_ROW = 4
"""Objects side by side in one row of the 3D view; more go into rows behind (north of) it. In the 3D tab of a
1280x720 window four objects a row leave each label about 210 px, more than ``adaptive-large-angle`` needs; eight in
one row ran their labels into one another."""


def grid_shape(n_objects: int) -> tuple[int, int]:
    """(rows, objects a row): one row up to :data:`MAX_PER_ROW` objects, else as few rows as hold them, filled
    evenly (eight objects: two rows of four)."""
    rows = max(1, math.ceil(n_objects / MAX_PER_ROW))
    return rows, math.ceil(n_objects / rows)


def object_offsets(n_washouts: int, travel_m: np.ndarray, diameter_m: float) -> np.ndarray:
    """Centre of each object (aircraft first, then the washouts) (1 + n_washouts, 3), NED, metres: in rows along y
    (east), at most :data:`MAX_PER_ROW` a row, further rows behind the first (north, away from the camera)."""
    spacing = 2.0 * float(travel_m[1]) + diameter_m + 1.0
    n = 1 + n_washouts
    _, per_row = grid_shape(n)
    i = np.arange(n)
    offsets = np.zeros((n, 3))
    offsets[:, 0] = (i // per_row) * 2.0 * spacing
    offsets[:, 1] = (i % per_row) * spacing
    return offsets


FOV_Y_DEG = 55.0
"""The vertical field of view of rerun's 3-D eye (``Eye::DEFAULT_FOV_Y`` in re_view_spatial), deg."""

VIEW_ASPECT = 1.4
"""Width / height of the 3-D tab's view, the narrower of 1920x1080 (about 1340 x 950 px) and 1280x720 (890 x 630):
the camera frames the scene for it (a wider view shows more room at the sides)."""

ELEVATION_DEG = 45.0
"""The camera looks north and down by this angle: the rows behind one another stand apart, each row's labels fall
between it and the row in front (screenshots at 1920x1080 and 1280x720)."""

FILL = 0.92
"""The scene's extremes reach this share of the view's half-angles (tangents): room for the labels' text, which
the viewer draws in pixels around their points."""

LABEL_GAP_M = 0.4
"""A label's point lies this far in front of (south of) its object's front lower edge, m."""


def _boxes(offsets: np.ndarray, travel_m: np.ndarray, diameter_m: float) -> np.ndarray:
    """Half-sizes (n, 3) of each object's box, m: the aircraft's shape (half the sphere's diameter), a cockpit's
    sphere or its stage's range box, whichever is larger on each axis."""
    half = diameter_m / 2.0
    boxes = np.tile(np.maximum(half, np.asarray(travel_m, dtype=np.float64)), (len(offsets), 1))
    boxes[0] = half
    return boxes


def label_points(offsets: np.ndarray, travel_m: np.ndarray, diameter_m: float) -> np.ndarray:
    """Where each object's label is drawn (n, 3), NED, m: in front of the middle of its box's front lower edge, the
    lowest point of the object on the screen of a camera looking north and down (a label under the object, seen from
    above, lay over its own box)."""
    boxes = _boxes(offsets, travel_m, diameter_m)
    return np.asarray(offsets, dtype=np.float64) + np.column_stack(
        [-boxes[:, 0] - LABEL_GAP_M, np.zeros(len(boxes)), boxes[:, 2]]
    )


def scene_extent(offsets: np.ndarray, travel_m: np.ndarray, diameter_m: float) -> np.ndarray:
    """Points that bound what the 3-D view shows (NED, m): the corners of each object's box (:func:`_boxes`) and each
    label's point (:func:`label_points`)."""
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)
    boxes = _boxes(offsets, travel_m, diameter_m)
    points = [np.asarray(offsets, dtype=np.float64)[i] + corners * boxes[i] for i in range(len(boxes))]
    return np.vstack([*points, label_points(offsets, travel_m, diameter_m)])


def camera(offsets: np.ndarray, travel_m: np.ndarray, diameter_m: float
           ) -> tuple[tuple[float, float, float], tuple[float, float, float]]:  # fmt: skip
    """Eye and target (NED, m): looking north and down (:data:`ELEVATION_DEG`), as close as the view (rerun's
    :data:`FOV_Y_DEG` field of view, :data:`VIEW_ASPECT`) holds every point of :func:`scene_extent` within
    :data:`FILL` of its half-angles, centred (the camera set by hand cut the front row off under the view's edge
    and left its top third empty).

    With the view's axes r (right, east), u (up) and f (forward) and the eye E = e_r r + e_u u + e_f f, a point p is
    inside when |p.r - e_r| <= k_r (p.f - e_f) and |p.u - e_u| <= k_u (p.f - e_f), k the half-angles' tangents times
    FILL: e_f <= min_p (p.f - p.r / k_r) + e_r / k_r and e_f <= min_p (p.f + p.r / k_r) - e_r / k_r. The nearest eye
    sideways is where both bounds meet, e_r = k_r (B - A) / 2, e_f = (A + B) / 2 (A, B the two minima); the same
    upward; e_f the smaller of the two (the other direction then centred between its bounds). The target: the point
    of the line of sight nearest the scene's centre."""
    e = math.radians(ELEVATION_DEG)
    fwd = np.array([math.cos(e), 0.0, math.sin(e)])  # north and down (NED: down is +z)
    right = np.array([0.0, 1.0, 0.0])  # east
    up = np.array([math.sin(e), 0.0, -math.cos(e)])  # perpendicular to both, pointing up
    tan_half = math.tan(math.radians(FOV_Y_DEG) / 2.0) * FILL
    points = scene_extent(offsets, travel_m, diameter_m)
    pf = points @ fwd
    eye_f, sideways = [], []
    for axis, k in ((right, tan_half * VIEW_ASPECT), (up, tan_half)):
        pa = points @ axis
        a, b = float(np.min(pf - pa / k)), float(np.min(pf + pa / k))
        eye_f.append(0.5 * (a + b))
        sideways.append(0.5 * k * (b - a))
    eye = sideways[0] * right + sideways[1] * up + min(eye_f) * fwd
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    target = eye + fwd * float((centre - eye) @ fwd)
    return (float(eye[0]), float(eye[1]), float(eye[2])), (float(target[0]), float(target[1]), float(target[2]))


def _shape(size: float) -> list[list[list[float]]]:
    """Line strips of the attitude shape in body axes (x forward, y right, z down), ``size`` = half length, m."""
    s = size
    return [
        [[-s, 0, 0], [s, 0, 0]],  # fuselage
        [[0.72 * s, -0.18 * s, 0], [s, 0, 0], [0.72 * s, 0.18 * s, 0]],  # nose chevron
        [[0.1 * s, -s, 0], [0.1 * s, s, 0]],  # wings
        [[-0.9 * s, -0.38 * s, 0], [-0.9 * s, 0.38 * s, 0]],  # tailplane
        [[-0.8 * s, 0, 0], [-s, 0, -0.5 * s]],  # fin (up is -z)
    ]


def _log_object(rec: rr.RecordingStream, path: str, size: float, color: tuple[int, int, int]) -> None:
    rec.log(
        f"{path}/shape",
        rr.LineStrips3D(_shape(size), colors=[color], radii=[0.035 * size]),
        static=True,
        strict=True,
    )
    rec.log(
        f"{path}/floor",
        rr.Boxes3D(
            half_sizes=[[0.75 * size, 0.55 * size, 0.02 * size]],
            colors=[(*color, 110)],
            fill_mode="Solid",
        ),
        static=True,
        strict=True,
    )


def send_scene(
    rec: rr.RecordingStream,
    time_of: object,
    t_s: np.ndarray,
    aircraft_q: np.ndarray,
    washout_q: dict[str, np.ndarray],
    stage_pos_m: dict[str, np.ndarray],
    travel_m: np.ndarray,
    diameter_m: float,
    hexapod: object | None = None,
    platform: str = "atlas",
) -> None:
    """Log the scene; ``time_of(t_s)`` makes the time column. Quaternions scalar first, body->NED. ``hexapod``
    (:class:`washbench.review.rerun_log.HexapodDrawing`): each washout's platform is that hexapod, drawn with its
    legs (:func:`_send_hexapod`), instead of the Atlas. ``platform``: ``atlas`` (the sphere in its stage's range box),
    anything else without a hexapod drawing (a rig, a plugin's platform): a base and the cockpit at its pose
    (:func:`_send_base_and_cockpit`)."""
    washouts = list(washout_q)
    offsets = object_offsets(len(washouts), travel_m, diameter_m)
    half = diameter_m / 2.0
    rec.log("/world", rr.ViewCoordinates.FRD, static=True, strict=True)  # x north, y east, z down

    rec.log("/world/aircraft", rr.Transform3D(translation=offsets[0]), static=True, strict=True)
    q_rel = relative_to_initial_heading(aircraft_q)
    idx = pose_samples(t_s, q_rel)
    q_ac = q_rel[idx]
    rec.send_columns(
        "/world/aircraft/body",
        indexes=[time_of(t_s[idx])],
        columns=rr.Transform3D.columns(quaternion=quat_wxyz_to_xyzw(q_ac)),
        strict=True,
    )
    _log_object(rec, "/world/aircraft/body", half, AIRCRAFT_COLOR)
    # one label per object, in front of its lower edge, where it hides no shape; at most MAX_PER_ROW objects a row,
    # so neighbours' labels do not run into one another (eight in one row did)
    rec.log(
        "/world/labels",
        rr.Points3D(
            label_points(offsets, travel_m, diameter_m),
            labels=["aircraft", *washouts],
            colors=[AIRCRAFT_COLOR, *[series_color(w, washouts) for w in washouts]],
            radii=[0.05],
            show_labels=True,
        ),
        static=True,
        strict=True,
    )
    if hexapod is not None:
        for i, w in enumerate(washouts):
            _send_hexapod(rec, time_of, t_s, w, series_color(w, washouts), offsets[i + 1], washout_q[w], stage_pos_m[w],
                          hexapod, half)  # fmt: skip
        return
    if platform != "atlas":
        for i, w in enumerate(washouts):
            _send_base_and_cockpit(rec, time_of, t_s, w, series_color(w, washouts), offsets[i + 1], washout_q[w],
                                   stage_pos_m[w], travel_m, half)  # fmt: skip
        return
    for i, w in enumerate(washouts):
        color = series_color(w, washouts)
        base = f"/world/atlas/{w}"
        rec.log(base, rr.Transform3D(translation=offsets[i + 1]), static=True, strict=True)
        rec.log(
            f"{base}/stage_range",
            rr.Boxes3D(half_sizes=[travel_m], colors=[(*LIMIT_COLOR, 160)], fill_mode="MajorWireframe"),
            static=True,
            strict=True,
        )
        idx = pose_samples(t_s, washout_q[w], stage_pos_m[w])
        pos = np.asarray(stage_pos_m[w], dtype=np.float64)[idx]
        rec.send_columns(
            f"{base}/cockpit",
            indexes=[time_of(t_s[idx])],
            columns=rr.Transform3D.columns(translation=pos, quaternion=quat_wxyz_to_xyzw(washout_q[w][idx])),
            strict=True,
        )
        rec.log(
            f"{base}/cockpit/sphere",
            rr.Ellipsoids3D(half_sizes=[[half, half, half]], colors=[(*color, 70)], fill_mode="MajorWireframe"),
            static=True,
            strict=True,
        )
        _log_object(rec, f"{base}/cockpit", 0.8 * half, color)


def _send_hexapod(
    rec: rr.RecordingStream,
    time_of: object,
    t_s: np.ndarray,
    washout: str,
    color: tuple[int, int, int],
    offset: np.ndarray,
    q_wxyz: np.ndarray,
    pos_m: np.ndarray,
    hexapod: object,
    half: float,
) -> None:
    """One washout's hexapod: the base joints (static, a hexagon on the floor), the cockpit (its platform joints'
    hexagon and the attitude shape) at the motion reference point n + p with attitude q, and the six legs from each
    base joint b_i to its platform joint n + p + R(q) a_i, at the poses sent (:func:`pose_samples`). The base frame's
    origin sits at ``offset`` less the neutral point, so the cockpit at neutral is at ``offset``."""
    b = np.asarray(hexapod.base_joints_m, dtype=np.float64)  # type: ignore[attr-defined]
    a = np.asarray(hexapod.platform_joints_m, dtype=np.float64)  # type: ignore[attr-defined]
    n = np.asarray(hexapod.neutral_m, dtype=np.float64)  # type: ignore[attr-defined]
    root = f"/world/hexapod/{washout}"
    rec.log(root, rr.Transform3D(translation=np.asarray(offset) - n), static=True, strict=True)
    rec.log(f"{root}/base", rr.LineStrips3D([np.vstack([b, b[:1]])], colors=[LIMIT_COLOR], radii=[0.03]), static=True,
            strict=True)  # fmt: skip
    idx = pose_samples(t_s, q_wxyz, pos_m)
    q = np.asarray(q_wxyz, dtype=np.float64)[idx]
    p = np.asarray(pos_m, dtype=np.float64)[idx] + n
    rec.send_columns(
        f"{root}/cockpit",
        indexes=[time_of(t_s[idx])],
        columns=rr.Transform3D.columns(translation=p, quaternion=quat_wxyz_to_xyzw(q)),
        strict=True,
    )
    rec.log(f"{root}/cockpit/joints", rr.LineStrips3D([np.vstack([a, a[:1]])], colors=[color], radii=[0.03]),
            static=True, strict=True)  # fmt: skip
    _log_object(rec, f"{root}/cockpit", 0.8 * half, color)
    # legs: platform joints in the base frame, v + 2 w (u x v) + 2 u x (u x v) for each pose and joint
    w, u = q[:, None, :1], np.broadcast_to(q[:, None, 1:], (len(q), 6, 3))
    av = np.broadcast_to(a, (len(q), 6, 3))
    t = 2.0 * np.cross(u, av)
    top = p[:, None, :] + av + w * t + np.cross(u, t)
    strips = np.stack([np.broadcast_to(b, top.shape), top], axis=2).reshape(-1, 2, 3)  # (poses * 6, 2, 3)
    rec.send_columns(
        f"{root}/legs",
        indexes=[time_of(t_s[idx])],
        columns=rr.LineStrips3D.columns(strips=list(strips)).partition([6] * len(idx)),
        strict=True,
    )
    rec.log(f"{root}/legs", rr.LineStrips3D.from_fields(colors=[(200, 200, 200)], radii=[0.04]), static=True,
            strict=True)  # fmt: skip


def _send_base_and_cockpit(
    rec: rr.RecordingStream,
    time_of: object,
    t_s: np.ndarray,
    washout: str,
    color: tuple[int, int, int],
    offset: np.ndarray,
    q_wxyz: np.ndarray,
    pos_m: np.ndarray,
    travel_m: np.ndarray,
    half: float,
) -> None:
    """A platform drawn simply (a rig, a plugin's platform): a grey base plate under the motion reference point
    (static), a post from it to the cockpit, the travel box when the platform has one, and the cockpit (attitude
    shape and floor plate) at the pose reached: translated by ``pos_m`` (NED, from neutral) and turned by ``q``."""
    root = f"/world/platform/{washout}"
    rec.log(root, rr.Transform3D(translation=offset), static=True, strict=True)
    below = 0.9 * half  # the base's depth under the motion reference point, m (down is +z)
    plate = rr.Boxes3D(centers=[[0.0, 0.0, below]], half_sizes=[[0.7 * half, 0.7 * half, 0.04 * half]],
                       colors=[(*LIMIT_COLOR, 200)], fill_mode="Solid")  # fmt: skip
    rec.log(f"{root}/base", plate, static=True, strict=True)
    rec.log(f"{root}/post", rr.LineStrips3D([[[0.0, 0.0, below], [0.0, 0.0, 0.0]]], colors=[LIMIT_COLOR],
                                            radii=[0.03]), static=True, strict=True)  # fmt: skip
    if np.any(np.asarray(travel_m) > 1e-2):  # a travel box worth drawing (a rig's heave, a plugin's envelope)
        rec.log(f"{root}/range", rr.Boxes3D(half_sizes=[np.maximum(travel_m, 1e-2)], colors=[(*LIMIT_COLOR, 160)],
                                            fill_mode="MajorWireframe"), static=True, strict=True)  # fmt: skip
    idx = pose_samples(t_s, q_wxyz, pos_m)
    rec.send_columns(
        f"{root}/cockpit",
        indexes=[time_of(t_s[idx])],
        columns=rr.Transform3D.columns(translation=np.asarray(pos_m, dtype=np.float64)[idx],
                                       quaternion=quat_wxyz_to_xyzw(np.asarray(q_wxyz, dtype=np.float64)[idx])),
        strict=True,
    )  # fmt: skip
    _log_object(rec, f"{root}/cockpit", 0.8 * half, color)
