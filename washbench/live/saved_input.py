"""The received samples saved as they come: ``OUT/live_input.csv``, a ``washbench cue`` input."""

from __future__ import annotations

import os
import time
from pathlib import Path

INPUT_FILE = "live_input.csv"
INPUT_COLUMNS = ("t_s", "f_x_mps2", "f_y_mps2", "f_z_mps2", "omega_x_degps", "omega_y_degps", "omega_z_degps")
HELD_COLUMN = "live_held"
PART_SUFFIX = ".part"
"""The saved input's name while the session runs (``live_input.csv.part``)."""
FLUSH_S = 0.25
"""The saved input is flushed to the operating system at least this often (a killed session loses no more)."""


class InputWriter:
    """``live_input.csv`` written as the samples come (a ``.part`` name until the session ends), one row per cued
    sample with exact decimals (``repr``: read back to the same bits). A segment left with a single sample
    (``washbench cue`` needs two) is cut off the file again."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.part = path.with_name(path.name + PART_SUFFIX)
        self._f = open(self.part, "wb")  # noqa: SIM115 (closed by close())
        self._f.write(header())
        self.rows = 0
        self.segments = 0
        self.short_segments = 0
        self._seg_start = self._f.tell()
        self._seg_rows = 0
        self._flushed = time.monotonic()

    def row(self, s: tuple[float, ...], held: bool, new_segment: bool) -> None:
        if new_segment:
            self._end_segment()
            self._seg_start = self._f.tell()
        t, fx, fy, fz, wx, wy, wz = s
        self._f.write(f"{t!r},{fx!r},{fy!r},{fz!r},{wx!r},{wy!r},{wz!r},{int(held)}\n".encode("ascii"))
        self.rows += 1
        self._seg_rows += 1

    def tick(self) -> None:
        """Flush to the operating system if :data:`FLUSH_S` has passed."""
        now = time.monotonic()
        if now - self._flushed > FLUSH_S:
            self._f.flush()
            self._flushed = now

    def _end_segment(self) -> None:
        if self._seg_rows == 1:
            self._f.flush()
            self._f.seek(self._seg_start)
            self._f.truncate()
            self.rows -= 1
            self.short_segments += 1
        elif self._seg_rows > 1:
            self.segments += 1
        self._seg_rows = 0

    def close(self) -> Path | None:
        """End the last segment, close and rename into place; return the final path. With fewer than 2 rows
        (nothing ``washbench cue`` could read) the ``.part`` file is removed and an earlier session's file left as
        it was: None."""
        self._end_segment()
        self._f.close()
        if self.rows < 2:
            self.part.unlink(missing_ok=True)
            return None
        os.replace(self.part, self.path)
        return self.path


def header() -> bytes:
    """The saved input's first line."""
    return (",".join((*INPUT_COLUMNS, HELD_COLUMN)) + "\n").encode("ascii")


def own_leftover(part: Path) -> Path | None:
    """``part`` if it is what a killed session left (a plain file, no link, starting with the saved input's
    header), else None (absent, or someone else's: then refused as any foreign entry)."""
    try:
        if part.is_symlink() or not part.is_file():
            return None
        with open(part, "rb") as fh:
            first = fh.read(len(header()))
    except OSError:
        return None
    return part if first == header() else None
