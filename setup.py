"""Ships the repository's top-level ``aircraft/``, ``manoeuvres/`` and ``tasks/`` inside the wheel, and compiles the
numba kernels into it.

- The data folders live beside ``washbench/`` in the source tree (where a user looks for them) and are copied into
  ``washbench/data/`` of the built package, so an installed washbench finds them from any folder
  (``washbench.io.paths``).
- The kernels: :mod:`washbench.numerics.precompile` runs on the built package (the wheel's files; an editable
  install's source tree), so numba's cache ships in the wheel and the first command after an install loads machine
  code instead of compiling it (about 47 s of CPU, measured). It needs the kernels' imports in the build environment
  (``[build-system] requires``). Skipped with ``WASHBENCH_NO_PRECOMPILE=1`` (a wheel built for other machines:
  numba keys the cache on the CPU, so it would not be used there); a failure is one warning line, never a failed
  build: the kernels then compile at their first use, as they would without this.
- The core-metadata ``License`` field (``pyproject.toml`` says why it is not a PEP 639 expression there).

Everything else is in ``pyproject.toml``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

#: Top-level folders shipped as ``washbench/data/<name>`` (keep in step with ``washbench.io.paths.BUNDLED_FOLDERS``).
BUNDLED_FOLDERS = ("aircraft", "manoeuvres", "tasks")


def precompile(package_root: Path) -> None:
    """Fill numba's cache of the washbench package under ``package_root`` (the folder holding ``washbench/``)."""
    if os.environ.get("WASHBENCH_NO_PRECOMPILE"):
        return
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}  # the cache beside the built sources
    env["PYTHONDONTWRITEBYTECODE"] = "1"  # no .pyc files into the wheel
    print("washbench: compiling the numerical kernels into the package (about 47 s of CPU in two processes: half a "
          "minute on two idle cores, minutes on a busy machine)", file=sys.stderr, flush=True)  # fmt: skip
    try:
        # the working folder first on sys.path: the built package is the one imported and compiled
        done = subprocess.run([sys.executable, "-m", "washbench.numerics.precompile"], cwd=package_root, env=env,
                              capture_output=True, text=True, timeout=1800)  # fmt: skip
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        failed = done.returncode != 0 and last
    except (OSError, subprocess.SubprocessError) as exc:
        failed = last = str(exc)
    if failed:
        print(f"washbench: warning: kernels not precompiled ({failed}); they compile at first use", file=sys.stderr)
    else:
        print(last, file=sys.stderr, flush=True)  # "... N compiled functions ... in S s": how long it took here


class BuildPyWithData(build_py):
    """``build_py`` that also copies the top-level data folders into the built package and compiles its kernels."""

    def run(self) -> None:
        super().run()
        root = Path(__file__).resolve().parent
        if getattr(self, "editable_mode", False):
            # an editable install reads the data folders in place (washbench.io.paths looks beside the package)
            precompile(root)
            return
        for name in BUNDLED_FOLDERS:
            src = root / name
            dest = Path(self.build_lib) / "washbench" / "data" / name
            if dest.exists():
                shutil.rmtree(dest)
            shutil.copytree(src, dest, ignore=shutil.ignore_patterns("__pycache__", "*.py[cod]"))
        precompile(Path(self.build_lib))


#: The licence, an SPDX identifier, as the core-metadata ``License`` field that ``pip show`` prints from pip 23 on.
LICENSE = "Apache-2.0"

setup(cmdclass={"build_py": BuildPyWithData}, license=LICENSE)
