"""Crash and divergence monitor: JSBSim does not detect crashes, so the testbed does.

Each check returns ``None`` when all is well, else a short cause. The fly loop stops the
run at the first cause, keeps what was recorded and marks the flight failed.
"""

from __future__ import annotations

from washbench.flight.profile import PilotProfile

ALPHA_MAX_RAD = 0.6  # ~34 deg: beyond any wing's usable range; the aircraft has departed
BIG = 1.0e7


class Monitor:
    """Limits of one aircraft; cheap per-step checks in plain floats."""

    def __init__(self, profile: PilotProfile) -> None:
        self.vne = profile.speeds.vne_kts
        self.nz_max = profile.limits.nz_max
        self.nz_min = profile.limits.nz_min
        self.sink_max = profile.limits.touchdown_sink_max_fps
        self.h_collapsed = 0.5 * profile.geometry.cg_height_on_ground_ft  # centre of gravity this low: gear gone

    def state(self, total: float, vc: float, alpha: float, h_agl: float, wow: bool, structure_wow: float) -> str | None:
        """Checks on the current state. ``total`` is a sum of state values (NaN/inf propagate into it)."""
        if not -BIG < total < BIG:
            return "the flight model diverged (non-finite state)"
        if structure_wow > 0.0:
            return "the airframe touched the ground (a structural contact point)"
        if vc > self.vne:
            return f"airspeed {vc:.1f} kt beyond VNE {self.vne:g} kt"
        if not wow and (alpha > ALPHA_MAX_RAD or alpha < -ALPHA_MAX_RAD):
            return f"angle of attack {alpha * 57.29578:.1f} deg: out of the flight envelope"
        if h_agl < self.h_collapsed:
            return f"the centre of gravity is {h_agl:.1f} ft above the ground: the gear has collapsed"
        return None

    def touchdown(self, sink_fps: float) -> str | None:
        """Check at the first ground contact after flight."""
        if sink_fps > self.sink_max:
            return f"hard landing: sink rate {sink_fps:.1f} ft/s beyond {self.sink_max:g} ft/s"
        return None

    def load_factor(self, nz: float) -> str | None:
        """Check the (lag-corrected) load factor in flight."""
        if nz > self.nz_max or nz < self.nz_min:
            return f"load factor {nz:.2f} g beyond the limits {self.nz_min:g}..{self.nz_max:g} g"
        return None
