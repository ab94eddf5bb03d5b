"""``washbench examples DIR``: copy the bundled manoeuvres, pilot profiles, washout parameter file and platform
files into a folder the user can edit.

The copy is laid out as a washbench project: ``DIR/manoeuvres/<aircraft>/<name>.yaml``,
``DIR/aircraft/<aircraft>/pilot.yaml`` and ``DIR/params/cw1.yaml`` (for ``--params``) with every bundled platform
file, ``DIR/params/atlas.yaml``, ``hexapod.yaml``, ``rig2dof.yaml`` (for ``--platform``). A manoeuvre in
``DIR/manoeuvres/`` finds ``DIR/aircraft/`` by the "``aircraft/`` next to the manoeuvre or in a parent" rule, so an
edited profile there is the one flown (the aircraft models themselves are still found bundled or in JSBSim; copy a
model folder into ``DIR/aircraft/`` to change it too).
"""

from __future__ import annotations

import sys
from pathlib import Path

from washbench.errors import WashbenchError, located
from washbench.io.atomic import write_text_atomic
from washbench.io.lock import output_lock
from washbench.io.outfolder import recover, staged
from washbench.io.paths import AIRCRAFT_DIR, BUNDLED_PARAMS, BUNDLED_PLATFORMS, DATA_DIR, MANOEUVRES_DIR, PROFILE_NAME

PARAM_FILES = tuple(f"{name}.yaml" for name in (*BUNDLED_PARAMS, *BUNDLED_PLATFORMS))
"""The bundled washout parameter set and platform files, copied into ``DIR/params/``."""
TOPS = ("manoeuvres", "aircraft", "params")
"""The folders ``washbench examples`` creates in ``DIR`` (it refuses when one exists)."""


def example_files(dest: Path) -> list[tuple[Path, Path]]:
    """(bundled source, destination) pairs for every file ``washbench examples`` copies."""
    pairs = [
        (src, dest / "manoeuvres" / src.relative_to(MANOEUVRES_DIR)) for src in sorted(MANOEUVRES_DIR.rglob("*.yaml"))
    ]
    pairs += [
        (src, dest / "aircraft" / src.parent.name / PROFILE_NAME)
        for src in sorted(AIRCRAFT_DIR.glob(f"*/{PROFILE_NAME}"))
    ]
    pairs += [(DATA_DIR / name, dest / "params" / name) for name in PARAM_FILES]
    return pairs


def copy_examples(dest: Path) -> int:
    """Copy the examples into ``dest`` (created), all or nothing; refuse before writing anything if
    ``dest/manoeuvres``, ``dest/aircraft`` or ``dest/params`` exists (a link there is never followed).

    Built in a hidden stage folder inside ``dest`` and published whole (:mod:`washbench.io.outfolder`), under
    ``dest``'s lock: a full disk or a signal leaves nothing half-copied, so a rerun works.
    """

    if dest.exists() and not dest.is_dir():
        raise WashbenchError(located(dest, "exists and is not a folder"))
    with output_lock(dest):
        recover(dest, only_washbench=True)  # the user's folder: only washbench's own leftovers
        for top in TOPS:
            if (dest / top).exists() or (dest / top).is_symlink():
                raise WashbenchError(located(dest / top, "already exists; nothing copied (examples never overwrite)"))
        with staged(dest, []) as stage:
            try:
                for src, dst in example_files(stage):
                    dst.parent.mkdir(parents=True, exist_ok=True)
                    write_text_atomic(dst, src.read_text())
            except OSError as exc:
                raise WashbenchError(located(dest, f"cannot write ({exc.strerror or exc})")) from None
    pairs = example_files(dest)
    n_m = sum(1 for _, d in pairs if d.suffix == ".yaml" and "manoeuvres" in d.parts)
    n_p = len(pairs) - n_m - len(PARAM_FILES)
    n_platforms = len(BUNDLED_PLATFORMS)
    print(f"{n_m} manoeuvres, {n_p} pilot profiles, a washout parameter file and {n_platforms} platform files "
          f"({', '.join(BUNDLED_PLATFORMS)}) copied to {dest}")  # fmt: skip
    print(f"  run one:   washbench run {dest / 'manoeuvres' / 'c172' / 'coordinated_turn.yaml'} --out my-runs")
    print(f"  run all:   washbench suite {dest / 'manoeuvres'} --out my-suite")
    print(f"  profiles:  {dest / 'aircraft'}/<aircraft>/pilot.yaml are used by the manoeuvres under {dest}")
    print(f"  params:    --params {dest / 'params' / 'cw1.yaml'} --platform {dest / 'params' / 'hexapod.yaml'} (a "
          "parameter file may hold only the sections it changes)")  # fmt: skip
    sys.stdout.flush()
    return 0
