"""The platform commands ``washbench live`` sends (``--sink udp://HOST:PORT``): one datagram per cued sample.

Binary (the default, ``--sink-format binary``), little-endian, version :data:`VERSION`::

    header, 24 bytes:  magic b"WBPC" | version u8 (1) | washouts n u8 | flags u16 (bit 0: the sample is held,
                       bit 1: it starts a segment) | sequence u32 (0, 1, 2, ... per command sent) |
                       reserved u32 (0) | t_s f64 (the source's time of the sample)
    then per washout (in --washout order), 112 bytes:
                       pos_{x,y,z}_m 3 f64 (platform centre, NED) | vel_{x,y,z}_mps 3 f64 |
                       q_{w,x,y,z} 4 f64 (platform attitude, body -> inertial, scalar first) |
                       omega_{x,y,z}_radps 3 f64 (platform body rates) |
                       saturated u32 (bit j set: held at limit kind j of SAT_KINDS) | reserved u32 (0)

JSON lines (``--sink-format json``, for debugging): one object per datagram, ``{"v": 1, "seq": ..., "t_s": ...,
"held": ..., "new_segment": ..., "washouts": {NAME: {"pos_m": [...], "vel_mps": [...], "q": [...],
"omega_radps": [...], "saturated": [KIND, ...]}}}``.
"""

from __future__ import annotations

import json
import struct
from collections.abc import Sequence

import numpy as np

from washbench.cueing.kernel import O_OMEGA, O_POS, O_Q, O_SAT, O_VEL, SAT_KINDS

MAGIC = b"WBPC"
VERSION = 1
HEADER = struct.Struct("<4sBBHIId")
WASHOUT = struct.Struct("<13dII")
FLAG_HELD = 1
FLAG_NEW_SEGMENT = 2
SINK_FORMATS = ("binary", "json")


_IDX = np.r_[O_POS : O_POS + 3, O_VEL : O_VEL + 3, O_Q : O_Q + 4, O_OMEGA : O_OMEGA + 3]
_BITS = 1 << np.arange(len(SAT_KINDS))


def _fields_all(rows: np.ndarray) -> tuple[list[list[float]], list[int]]:
    """Per washout: the 13 command values (pos, vel, q, omega) and the saturation bit mask."""
    bits = ((rows[:, O_SAT : O_SAT + len(SAT_KINDS)] != 0.0) @ _BITS).tolist()
    return rows[:, _IDX].tolist(), bits


def _fields(row: np.ndarray) -> tuple[list[float], int]:
    values, bits = _fields_all(row[None, :])
    return values[0], bits[0]


def encode_binary(seq: int, t_s: float, flags: int, rows: np.ndarray) -> bytes:
    """The binary command of one sample: ``rows`` (n_washouts, N_FIELDS) from :meth:`CueingBank.step`."""
    parts = [HEADER.pack(MAGIC, VERSION, rows.shape[0], flags, seq & 0xFFFFFFFF, 0, t_s)]
    values, bits = _fields_all(rows)
    for v, b in zip(values, bits, strict=True):
        parts.append(WASHOUT.pack(*v, b, 0))
    return b"".join(parts)


def encode_json(seq: int, t_s: float, flags: int, rows: np.ndarray, names: Sequence[str]) -> bytes:
    """The JSON-lines command of one sample (one line, ending in a newline)."""
    washouts = {}
    for name, row in zip(names, rows, strict=True):
        v, bits = _fields(row)
        sat = [k for j, k in enumerate(SAT_KINDS) if bits >> j & 1]
        washouts[name] = {"pos_m": v[0:3], "vel_mps": v[3:6], "q": v[6:10], "omega_radps": v[10:13], "saturated": sat}
    doc = {"v": VERSION, "seq": seq, "t_s": t_s, "held": bool(flags & FLAG_HELD),
           "new_segment": bool(flags & FLAG_NEW_SEGMENT), "washouts": washouts}  # fmt: skip
    return (json.dumps(doc) + "\n").encode("utf-8")


def decode_binary(data: bytes) -> dict[str, object]:
    """A binary command back as a dict (for tests and for a platform driver written in Python)."""
    magic, version, n, flags, seq, _, t_s = HEADER.unpack_from(data)
    if magic != MAGIC or version != VERSION or len(data) != HEADER.size + n * WASHOUT.size:
        raise ValueError("not a washbench platform command (version 1)")
    washouts = []
    for i in range(n):
        *v, bits, _ = WASHOUT.unpack_from(data, HEADER.size + i * WASHOUT.size)
        sat = [k for j, k in enumerate(SAT_KINDS) if bits >> j & 1]
        washouts.append({"pos_m": v[0:3], "vel_mps": v[3:6], "q": v[6:10], "omega_radps": v[10:13], "saturated": sat})
    return {"seq": seq, "t_s": t_s, "flags": flags, "washouts": washouts}
