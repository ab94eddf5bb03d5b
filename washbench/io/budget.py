"""One bound on what a command may allocate, checked from an estimate before anything is allocated.

Every command that builds a time series (``signal``, ``omct``, ``cue``'s reader, a JSBSim script's flight)
estimates its length first and refuses, with the limit in the message, what would exceed
:data:`MAX_SAMPLES`; files washbench reads whole (YAML parameter, platform and manoeuvre files) are read
at most :data:`MAX_YAML_BYTES` (``--params /dev/zero`` is refused, not read for ever); text inputs, gzip
ones included, are streamed once and refused past :data:`MAX_TEXT_BYTES` decompressed or
:data:`MAX_SAMPLES` lines, so a small gzip file that expands to gigabytes costs seconds and no memory.
"""

from __future__ import annotations

from pathlib import Path

from washbench.errors import WashbenchError, located

#: Samples of one time series (about 46 h at 120 Hz; 20 M rows of 7 float64 columns are 1.1 GB).
MAX_SAMPLES = 20_000_000
#: Bytes of a YAML file (parameters, platform limits, manoeuvres, input formats, boundaries).
MAX_YAML_BYTES = 10 * 1024 * 1024
#: Decompressed bytes of a text input (CSV, TSV, X-Plane, JSBSim CSV).
MAX_TEXT_BYTES = 4 * 1024 * 1024 * 1024


def check_samples(n: float, what: str, where: str | Path | None = None) -> int:
    """``n`` (an estimate, possibly huge or not finite) as an int, or WashbenchError naming ``what`` and the limit."""
    if n != n or n > MAX_SAMPLES:  # NaN or too many
        shown = f"{n:.4g}" if isinstance(n, float) else str(n)
        problem = f"{what}: {shown} samples, more than washbench's limit of {MAX_SAMPLES:,} for one time series"
        raise WashbenchError(located(where, problem) if where is not None else problem)
    return int(n)


def read_bounded(path: str | Path, limit: int = MAX_YAML_BYTES) -> bytes:
    """The bytes of ``path``, at most ``limit``; WashbenchError (one line naming the file) if it is longer, missing,
    a folder, or cannot be read."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(limit + 1)
    except FileNotFoundError:
        raise WashbenchError(located(path, "no such file")) from None
    except IsADirectoryError:
        raise WashbenchError(located(path, "is a folder, not a file")) from None
    except OSError as exc:
        raise WashbenchError(located(path, f"cannot read: {exc.strerror or exc}")) from None
    if len(data) > limit:
        raise WashbenchError(located(path, f"larger than {limit // (1024 * 1024)} MB: not a washbench input file"))
    return data
