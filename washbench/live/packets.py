"""What each simulator sends over UDP, decoded into washbench units and axes (and encoded again, for
``washbench send``). The set-up on each simulator's side is in docs/live.md.

Every decoder turns one datagram into one sample ``(t_s, f_x, f_y, f_z, omega_x, omega_y, omega_z)``: time [s],
the pilot's specific force [m/s^2] and body angular velocity [deg/s], body axes x forward, y right, z down (the
units of washbench's own input files, so the received samples are saved as a ``washbench cue`` input as they are),
or ``None`` for a datagram that carries no sample (JSBSim's ``<LABELS>`` header, a partial RREF set). A datagram
that is not one is :class:`PacketError` (``foreign``: another program's packet; ``malformed``: truncated, wrong
length, non-finite or absurd values).

Formats (:data:`FORMATS`):

- ``washbench``: washbench's own packet, little-endian, 68 bytes: ``b"WBMO"``, version u8 (1), 3 pad bytes,
  sequence number u32, t_s f64, f_{x,y,z}_mps2 3 x f64, omega_{x,y,z}_degps 3 x f64 (exactly a row of a
  washbench input file).
- ``xplane``: X-Plane's Data Output "network via UDP" datagram: ``b"DATA"``, one byte, then rows of
  (int32 index, 8 x float32), little-endian. Rows 1 (Times: real time s), 4 (Mach, VVI, g-load: normal, axial,
  side load factors) and 16 (Angular velocities: Q, P, R in rad/s) are read, as :mod:`washbench.io.xplane` reads
  them from Data.txt: f_x = +axial g, f_y = +side g, f_z = -normal g (x 9.80665 m/s^2).
- ``xplane-rref``: replies to washbench's RREF subscription: ``b"RREF,"`` then (int32 id, float32 value)
  pairs. Datarefs :data:`RREF_DATAREFS`; the subscription packet is ``b"RREF\\0"``, int32 frequency [Hz],
  int32 id, the dataref path in 400 bytes (frequency 0 cancels it).
- ``flightgear``: the generic protocol of :data:`FLIGHTGEAR_PROTOCOL` (binary, network byte order): 7 doubles,
  /sim/time/elapsed-sec, /fdm/jsbsim/accelerations/a-pilot-{x,y,z}-ft_sec2 and /fdm/jsbsim/velocities/
  {p,q,r}-rad_sec (JSBSim-model aircraft).
- ``jsbsim``: JSBSim's ``<output type="SOCKET" protocol="UDP">``: a first datagram ``<LABELS>,Time,...`` naming
  the columns, then one line of comma-separated numbers per output step. The columns are found as in JSBSim's
  CSV output (:mod:`washbench.io.jsbsim_csv`): ``accelerations/a-pilot-{x,y,z}-ft_sec2`` and the body rates
  (``<rates>`` gives ``P``, ``Q``, ``R`` in deg/s; or ``velocities/{p,q,r}-rad_sec``). JSBSim's pilot
  accelerations lag one frame (:func:`washbench.io.readers.shift_jsbsim_lag`): :attr:`Decoder.lag_shift`.
"""

from __future__ import annotations

import math
import struct
from importlib import resources

from washbench.io.jsbsim_csv import JSBSIM_F
from washbench.io.motion import F_MAX_MPS2, OMEGA_MAX_DEGPS
from washbench.io.units import FT_M, G0_MPS2
from washbench.live import FORMATS  # noqa: F401 (re-exported: the codecs' formats)

Sample = tuple[float, float, float, float, float, float, float]
"""(t_s, f_x_mps2, f_y_mps2, f_z_mps2, omega_x_degps, omega_y_degps, omega_z_degps), body axes frd."""

_R2D = 180.0 / math.pi
_D2R = math.pi / 180.0
_FT = FT_M


class PacketError(Exception):
    """A datagram that is not a sample: ``kind`` is ``foreign`` (not this format) or ``malformed``."""

    def __init__(self, kind: str, text: str) -> None:
        super().__init__(text)
        self.kind = kind


def check_sample(s: Sample) -> Sample:
    """``s`` if every value is finite and within the accepted magnitudes (a ``washbench cue`` input), else
    PacketError ``malformed`` (a corrupt packet must not stop the session, nor the result at its end)."""
    t, fx, fy, fz, wx, wy, wz = s
    if not math.isfinite(t + fx + fy + fz + wx + wy + wz):  # no finite sum overflows: the values are checked below
        raise PacketError("malformed", "non-finite value")
    if max(abs(fx), abs(fy), abs(fz)) > F_MAX_MPS2 or max(abs(wx), abs(wy), abs(wz)) > OMEGA_MAX_DEGPS:
        raise PacketError("malformed", "value beyond the accepted range")
    if abs(t) > 1e9:
        raise PacketError("malformed", "time beyond 1e9 s")
    return s


class Decoder:
    """One source format: :meth:`decode` a datagram; :attr:`notes` what the conversion does (printed at start)."""

    name = ""
    lag_shift = False
    notes: tuple[str, ...] = ()

    def decode(self, data: bytes) -> Sample | None:
        raise NotImplementedError


# --------------------------------------------------------------------------- washbench's own packet

WB_MAGIC = b"WBMO"
WB_VERSION = 1
_WB = struct.Struct("<4sB3xId6d")


def encode_washbench(seq: int, s: Sample) -> bytes:
    """washbench's motion packet of sample ``s`` (sequence number ``seq``, wrapped to 32 bits)."""
    return _WB.pack(WB_MAGIC, WB_VERSION, seq & 0xFFFFFFFF, *s)


class WashbenchDecoder(Decoder):
    name = "washbench"
    notes = ("washbench packets: t_s, f_{x,y,z}_mps2 and omega_{x,y,z}_degps as sent (float64, body axes frd)",)

    def decode(self, data: bytes) -> Sample | None:
        if data[:4] != WB_MAGIC:
            raise PacketError("foreign", "not a washbench packet")
        if len(data) != _WB.size:
            raise PacketError("malformed", f"{len(data)} bytes, expected {_WB.size}")
        _, version, _seq, *values = _WB.unpack(data)
        if version != WB_VERSION:
            raise PacketError("malformed", f"packet version {version}, expected {WB_VERSION}")
        return check_sample(tuple(values))  # type: ignore[arg-type]


# --------------------------------------------------------------------------- X-Plane DATA

_XP_ROW = struct.Struct("<i8f")
XP_TIMES, XP_GLOAD, XP_RATES = 1, 4, 16
_NONE = -999.0


def encode_xplane(seq: int, s: Sample) -> bytes:
    """An X-Plane Data Output datagram with rows 1, 4 and 16 (float32, as X-Plane sends them)."""
    t, fx, fy, fz, wx, wy, wz = s
    rows = (
        (XP_TIMES, (t, t, t, t, _NONE, 0.0, 0.0, t)),
        (XP_GLOAD, (0.0, _NONE, 0.0, _NONE, -fz / G0_MPS2, fx / G0_MPS2, fy / G0_MPS2, _NONE)),
        (XP_RATES, (wy * _D2R, wx * _D2R, wz * _D2R, _NONE, _NONE, _NONE, _NONE, _NONE)),
    )
    return b"DATA*" + b"".join(_XP_ROW.pack(i, *v) for i, v in rows)


class XPlaneDecoder(Decoder):
    name = "xplane"
    notes = (
        "X-Plane DATA rows 1, 4, 16 (float32): t = real time [s]; f_x = +axial, f_y = +side, f_z = -normal "
        "load factor x 9.80665 m/s^2; omega = P, Q, R rad/s -> deg/s (body axes frd)",
    )

    def decode(self, data: bytes) -> Sample | None:
        if data[:4] != b"DATA":
            raise PacketError("foreign", "not an X-Plane DATA packet")
        body = memoryview(data)[5:]
        if len(data) < 5 or len(body) % _XP_ROW.size:
            raise PacketError("malformed", f"{len(data)} bytes: not 5 + 36 n")
        rows = {}
        for off in range(0, len(body), _XP_ROW.size):
            index, *v = _XP_ROW.unpack_from(body, off)
            rows[index] = v
        missing = [i for i in (XP_TIMES, XP_GLOAD, XP_RATES) if i not in rows]
        if missing:
            raise PacketError("malformed", f"rows {missing} not in the packet (tick them in Data Output)")
        times, g, rates = rows[XP_TIMES], rows[XP_GLOAD], rows[XP_RATES]
        s = (
            times[0],
            g[5] * G0_MPS2,
            g[6] * G0_MPS2,
            -g[4] * G0_MPS2,
            rates[1] * _R2D,
            rates[0] * _R2D,
            rates[2] * _R2D,
        )
        return check_sample(s)


# --------------------------------------------------------------------------- X-Plane RREF

RREF_DATAREFS = (
    ("sim/time/total_running_time_sec", "s"),
    ("sim/flightmodel/forces/g_axil", "g"),
    ("sim/flightmodel/forces/g_side", "g"),
    ("sim/flightmodel/forces/g_nrml", "g"),
    ("sim/flightmodel/position/P", "deg/s"),
    ("sim/flightmodel/position/Q", "deg/s"),
    ("sim/flightmodel/position/R", "deg/s"),
)
"""The datarefs washbench subscribes to, in sample order, with their units; their RREF ids are
:data:`RREF_ID0` + position."""
RREF_ID0 = 4700
_RREF_REQ = struct.Struct("<5sii400s")
_RREF_PAIR = struct.Struct("<if")


def rref_request(freq_hz: int, rref_id: int, dataref: str) -> bytes:
    """An RREF subscription (``freq_hz`` > 0) or its cancellation (0) for ``dataref`` under id ``rref_id``."""
    return _RREF_REQ.pack(b"RREF\0", freq_hz, rref_id, dataref.encode("ascii"))


def parse_rref_request(data: bytes) -> tuple[int, int, str] | None:
    """(frequency, id, dataref) of a subscription packet, or None if ``data`` is not one."""
    if len(data) != _RREF_REQ.size or data[:5] != b"RREF\0":
        return None
    _, freq, rid, path = _RREF_REQ.unpack(data)
    return freq, rid, path.split(b"\0", 1)[0].decode("ascii", "replace")


def rref_values(s: Sample) -> tuple[float, ...]:
    """The dataref values X-Plane would send for sample ``s`` (in :data:`RREF_DATAREFS` order and units)."""
    t, fx, fy, fz, wx, wy, wz = s
    return (t, fx / G0_MPS2, fy / G0_MPS2, -fz / G0_MPS2, wx, wy, wz)


def encode_rref(pairs: list[tuple[int, float]]) -> bytes:
    """An RREF reply: ``b"RREF,"`` and (id, float32 value) pairs."""
    return b"RREF," + b"".join(_RREF_PAIR.pack(i, v) for i, v in pairs)


class RrefDecoder(Decoder):
    name = "xplane-rref"
    notes = (
        "X-Plane RREF (float32): t = sim/time/total_running_time_sec; f_x = +g_axil, f_y = +g_side, "
        "f_z = -g_nrml x 9.80665 m/s^2; omega = P, Q, R deg/s (body axes frd)",
    )

    def __init__(self) -> None:
        self.values: list[float | None] = [None] * len(RREF_DATAREFS)

    def decode(self, data: bytes) -> Sample | None:
        if data[:5] != b"RREF,":
            raise PacketError("foreign", "not an X-Plane RREF reply")
        body = memoryview(data)[5:]
        if len(body) % _RREF_PAIR.size or not len(body):
            raise PacketError("malformed", f"{len(data)} bytes: not 5 + 8 n")
        has_time = False
        for off in range(0, len(body), _RREF_PAIR.size):
            rid, v = _RREF_PAIR.unpack_from(body, off)
            j = rid - RREF_ID0
            if 0 <= j < len(self.values):
                self.values[j] = v
                has_time |= j == 0
        vals = self.values
        if not has_time or any(v is None for v in vals):
            return None
        t, ax, side, nrml, p, q, r = vals  # type: ignore[misc]
        return check_sample((t, ax * G0_MPS2, side * G0_MPS2, -nrml * G0_MPS2, p, q, r))  # type: ignore[operator]


# --------------------------------------------------------------------------- FlightGear generic protocol

FLIGHTGEAR_PROTOCOL = "washbench.xml"
"""The generic-protocol file shipped in the package (``washbench live --print-flightgear-protocol``)."""
_FG = struct.Struct(">7d")


def flightgear_protocol() -> str:
    """The text of the FlightGear generic-protocol file."""
    return resources.files("washbench").joinpath("data", FLIGHTGEAR_PROTOCOL).read_text(encoding="utf-8")


def encode_flightgear(seq: int, s: Sample) -> bytes:
    """The datagram FlightGear sends with :data:`FLIGHTGEAR_PROTOCOL` (ft/s^2 and rad/s, big-endian doubles)."""
    t, fx, fy, fz, wx, wy, wz = s
    return _FG.pack(t, fx / _FT, fy / _FT, fz / _FT, wx * _D2R, wy * _D2R, wz * _D2R)


class FlightGearDecoder(Decoder):
    name = "flightgear"
    notes = (
        "FlightGear generic protocol 'washbench' (7 big-endian doubles): t = /sim/time/elapsed-sec; f = "
        "a-pilot ft/s^2 -> m/s^2; omega = p, q, r rad/s -> deg/s (body axes frd)",
    )

    def decode(self, data: bytes) -> Sample | None:
        if len(data) != _FG.size:
            raise PacketError("foreign" if len(data) < 8 or len(data) > 4 * _FG.size else "malformed",
                              f"{len(data)} bytes, expected {_FG.size}")  # fmt: skip
        t, ax, ay, az, p, q, r = _FG.unpack(data)
        return check_sample((t, ax * _FT, ay * _FT, az * _FT, p * _R2D, q * _R2D, r * _R2D))


# --------------------------------------------------------------------------- JSBSim socket output

JSBSIM_LABELS = ("Time", *JSBSIM_F, "P", "Q", "R")
"""The columns ``washbench send --format jsbsim`` sends (JSBSim's with ``<rates>`` and the three properties)."""
_RATES = (
    (("P", "Q", "R"), 1.0),
    (("P (deg/s)", "Q (deg/s)", "R (deg/s)"), 1.0),
    (tuple(f"velocities/{r}-rad_sec" for r in "pqr"), _R2D),
)


def encode_jsbsim_labels() -> bytes:
    return ("<LABELS>," + ",".join(JSBSIM_LABELS) + "\n").encode("ascii")


def encode_jsbsim(seq: int, s: Sample) -> bytes:
    """One line of JSBSim's socket output for ``s`` (Time, a-pilot ft/s^2, P Q R deg/s), exact decimals."""
    t, fx, fy, fz, wx, wy, wz = s
    return (",".join(repr(float(v)) for v in (t, fx / _FT, fy / _FT, fz / _FT, wx, wy, wz)) + "\n").encode("ascii")


class JsbsimDecoder(Decoder):
    name = "jsbsim"
    lag_shift = True
    notes = (
        "JSBSim socket output: t = Time; f = accelerations/a-pilot-{x,y,z}-ft_sec2 -> m/s^2; omega = P, Q, R "
        "deg/s (or velocities/{p,q,r}-rad_sec); the pilot accelerations shifted back one frame (their lag)",
    )

    def __init__(self) -> None:
        self.index: tuple[int, ...] | None = None
        self.rate_factor = 1.0

    def _labels(self, text: str) -> None:
        """Find the columns in ``<LABELS> ,Time,P,Q,R,...``. JSBSim prints a property by its last name with ``_``
        as a space (``a-pilot-x-ft sec2``); full paths (``accelerations/a-pilot-x-ft_sec2``) are accepted too."""
        raw = [n.strip() for n in text.split(",")[1:]]
        short = [n.replace(" ", "_").rsplit("/", 1)[-1] for n in raw]

        def find(name: str) -> int | None:
            if name in raw:
                return raw.index(name)
            base = name.rsplit("/", 1)[-1]
            return short.index(base) if "/" in name and base in short else None

        cols = [find("Time"), *(find(p) for p in JSBSIM_F)]
        for rates, factor in _RATES:
            found = [find(r) for r in rates]
            if all(i is not None for i in found):
                cols += found
                self.rate_factor = factor
                break
        if any(i is None for i in cols) or len(cols) != 7:
            raise PacketError("malformed", "the <LABELS> lack Time, a-pilot accelerations or body rates")
        self.index = tuple(int(i) for i in cols)  # type: ignore[arg-type]

    def decode(self, data: bytes) -> Sample | None:
        try:
            text = data.decode("ascii")
        except UnicodeDecodeError:
            raise PacketError("foreign", "not JSBSim text output") from None
        if text.startswith("<LABELS>"):
            self._labels(text)
            return None
        if text.startswith("<STATUS>"):
            return None
        try:
            values = [float(v) for v in text.split(",")]
        except ValueError:
            raise PacketError("foreign", "not a line of numbers") from None
        if self.index is None:
            raise PacketError("malformed", "data before the <LABELS> datagram (start washbench live first)")
        if len(values) <= max(self.index):
            raise PacketError("malformed", f"{len(values)} values, the labels name more")
        t, ax, ay, az, p, q, r = (values[i] for i in self.index)
        k = self.rate_factor
        return check_sample((t, ax * _FT, ay * _FT, az * _FT, p * k, q * k, r * k))


DECODERS: dict[str, type[Decoder]] = {
    "washbench": WashbenchDecoder,
    "xplane": XPlaneDecoder,
    "xplane-rref": RrefDecoder,
    "flightgear": FlightGearDecoder,
    "jsbsim": JsbsimDecoder,
}

ENCODERS = {
    "washbench": encode_washbench,
    "xplane": encode_xplane,
    "flightgear": encode_flightgear,
    "jsbsim": encode_jsbsim,
}
"""Sample encoders of ``washbench send`` (``xplane-rref`` answers subscriptions: :mod:`washbench.runs.send`)."""


def decoder(fmt: str) -> Decoder:
    """A fresh decoder of format ``fmt`` (one of :data:`FORMATS`)."""
    return DECODERS[fmt]()
