"""Ships the repository's top-level ``aircraft/`` and ``manoeuvres/`` inside the wheel.

They live beside ``washbench/`` in the source tree (where a user looks for them) and are copied into
``washbench/data/`` of the built package, so an installed washbench finds them from any folder
(``washbench.io.paths``). Also the core-metadata ``License`` field (``pyproject.toml`` says why it is not a PEP 639
expression there). Everything else is in ``pyproject.toml``.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

#: Top-level folders shipped as ``washbench/data/<name>`` (keep in step with ``washbench.io.paths.BUNDLED_FOLDERS``).
BUNDLED_FOLDERS = ("aircraft", "manoeuvres")


class BuildPyWithData(build_py):
    """``build_py`` that also copies the top-level data folders into the built package."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return  # an editable install reads them in place (washbench.io.paths looks beside the package)
        root = Path(__file__).resolve().parent
        for name in BUNDLED_FOLDERS:
            src = root / name
            dest = Path(self.build_lib) / "washbench" / "data" / name
            if dest.exists():
                shutil.rmtree(dest)
            shutil.copytree(src, dest, ignore=shutil.ignore_patterns("__pycache__", "*.py[cod]"))


#: The licence, an SPDX identifier, as the core-metadata ``License`` field that ``pip show`` prints from pip 23 on.
LICENSE = "Apache-2.0"

setup(cmdclass={"build_py": BuildPyWithData}, license=LICENSE)
