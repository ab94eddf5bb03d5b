"""SHA-256 digests of every bundled manoeuvre's flight: the check that a faster flight loop flies the same bits.

Each manoeuvre under ``manoeuvres/`` is flown twice through :func:`washbench.flight.fly.fly`,
the loop ``washbench fly`` and ``washbench run`` use: once alone (``fly``) and once with the three washouts
in lockstep as ``washbench run`` feeds them (:func:`washbench.runs.chain.lockstep_blocks`). Printed per
manoeuvre: the digest of the recorded columns (every flight.parquet column in order, name, dtype, shape and
bytes), of the summary (status, reason, phases, checks, events, as ``repr`` of the floats: exact), and of the
washout rows of the lockstep flight. The lockstep flight must record the same columns as the plain one.
A last line digests all lines, so two runs compare at a glance.

    .venv/bin/python bench/flight_digest.py [--only NAME_PART] > digests.txt
"""

from __future__ import annotations

import argparse
import hashlib

import numpy as np

from washbench.flight.columns import COLUMN_NAMES
from washbench.flight.fly import FlightResult, fly
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.paths import MANOEUVRES_DIR
from washbench.platform import load_platform_limits


def columns_digest(result: FlightResult) -> str:
    h = hashlib.sha256()
    for name in COLUMN_NAMES:
        a = np.ascontiguousarray(result.columns[name])
        h.update(f"{name}:{a.dtype.str}:{a.shape}".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def summary_digest(result: FlightResult) -> str:
    text = repr((result.status, result.reason, result.phases, result.checks, sorted(result.events.items())))
    return hashlib.sha256(text.encode()).hexdigest()


def rows_digest(rows: list[np.ndarray]) -> str:
    """SHA-256 of the lockstep's washout rows as one (N, washouts, fields) array (sample-major, as it always was)."""
    from washbench.runs.chain import stacked_rows

    block = np.ascontiguousarray(stacked_rows(rows).transpose(1, 0, 2)) if rows else np.empty(0)
    return hashlib.sha256(f"{block.dtype.str}:{block.shape}".encode() + block.tobytes()).hexdigest()


def main() -> None:
    from washbench.cueing.variants import select_washouts
    from washbench.runs.chain import LOCKSTEP_BLOCK, lockstep_blocks

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="fly only the manoeuvres whose path contains this text")
    args = parser.parse_args()
    lines = []
    for path in sorted(MANOEUVRES_DIR.rglob("*.yaml")):
        rel = path.relative_to(MANOEUVRES_DIR).as_posix()
        if args.only not in rel:
            continue
        m = load_manoeuvre(path)
        plain = fly(m)
        rows, hook = lockstep_blocks(select_washouts(), load_platform_limits(), m.dt_s)
        stepped = fly(m, block_hook=hook, block_size=LOCKSTEP_BLOCK)
        cols = columns_digest(plain)
        if columns_digest(stepped) != cols or summary_digest(stepped) != summary_digest(plain):
            raise SystemExit(f"{rel}: the lockstep flight differs from the plain one")
        line = (f"{rel:40s} n={len(plain.t_s):6d} {plain.status:6s} columns={cols[:16]} "
                f"summary={summary_digest(plain)[:16]} washouts={rows_digest(rows)[:16]}")  # fmt: skip
        print(line, flush=True)
        lines.append(line)
    print("all", hashlib.sha256("\n".join(lines).encode()).hexdigest())


if __name__ == "__main__":
    main()
