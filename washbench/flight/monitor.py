"""Crash and divergence monitor: JSBSim does not detect crashes, so the testbed does.

Each check returns ``None`` when all is well, else a short cause. The fly loop stops the
run at the first cause, keeps what was recorded and marks the flight failed.
"""

from __future__ import annotations

from washbench.flight.profile import PilotProfile

ALPHA_MAX_RAD = 0.6  # ~34 deg: beyond any wing's usable range; the aircraft has departed
BIG = 1.0e7


SCRIPT_NZ_LIMITS = (-10.0, 15.0)
"""Load factors [g] no aircraft flies outside: beyond them a JSBSim script (with no pilot profile) has crashed."""


class Monitor:
    """Limits of one aircraft; cheap per-step checks in plain floats.

    ``vne_kts`` [kt], load factors [g], ``sink_max_fps`` [ft/s], ``h_collapsed_ft``: a centre of gravity
    this low above the ground means the gear has gone [ft]; ``alpha_max_rad``: out of the envelope in flight.
    """

    def __init__(
        self,
        vne_kts: float,
        nz_max: float,
        nz_min: float,
        sink_max_fps: float,
        h_collapsed_ft: float,
        alpha_max_rad: float = ALPHA_MAX_RAD,
    ) -> None:
        self.vne = vne_kts
        self.nz_max = nz_max
        self.nz_min = nz_min
        self.sink_max = sink_max_fps
        self.h_collapsed = h_collapsed_ft
        self.alpha_max = alpha_max_rad

    @classmethod
    def for_profile(cls, profile: PilotProfile) -> Monitor:
        """The limits of a pilot profile (the scripted pilot's aircraft)."""
        return cls(
            vne_kts=profile.speeds.vne_kts,
            nz_max=profile.limits.nz_max,
            nz_min=profile.limits.nz_min,
            sink_max_fps=profile.limits.touchdown_sink_max_fps,
            h_collapsed_ft=0.5 * profile.geometry.cg_height_on_ground_ft,
        )

    @classmethod
    def for_script(cls) -> Monitor:
        """Crash limits for any aircraft JSBSim flies from its own script (no profile): non-finite state, an
        airframe contact point on the ground, the centre of gravity below the ground, load factors beyond
        :data:`SCRIPT_NZ_LIMITS`. No airspeed, angle-of-attack (helicopters hover at any) or sink limits."""
        inf = float("inf")
        return cls(inf, SCRIPT_NZ_LIMITS[1], SCRIPT_NZ_LIMITS[0], inf, 0.0, inf)

    def state(self, total: float, vc: float, alpha: float, h_agl: float, wow: bool, structure_wow: float) -> str | None:
        """Checks on the current state. ``total`` is a sum of state values (NaN/inf propagate into it)."""
        if not -BIG < total < BIG:
            return "the flight model diverged (non-finite state)"
        if structure_wow > 0.0:
            return "the airframe touched the ground (a structural contact point)"
        if vc > self.vne:
            return f"airspeed {vc:.1f} kt beyond VNE {self.vne:g} kt"
        if not wow and (alpha > self.alpha_max or alpha < -self.alpha_max):
            return f"angle of attack {alpha * 57.29578:.1f} deg: out of the flight envelope"
        if h_agl < self.h_collapsed:
            if self.h_collapsed <= 0.0:
                return f"the centre of gravity is {-h_agl:.1f} ft below the ground"
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
