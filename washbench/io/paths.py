"""Where washbench finds its bundled files (the package is installed editable from the repo)."""

from __future__ import annotations

from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent.parent
DATA_DIR = PACKAGE_DIR / "data"
PROJECT_ROOT = PACKAGE_DIR.parent
AIRCRAFT_DIR = PROJECT_ROOT / "aircraft"
MANOEUVRES_DIR = PROJECT_ROOT / "manoeuvres"
