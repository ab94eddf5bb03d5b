"""Where washbench finds its bundled files: package data, found through importlib.resources.

The authored aircraft, the bundled manoeuvres, the pilot profiles and the parameter files live under
``washbench/data/`` in the source tree and in the wheel alike, so an editable checkout and an installed wheel
find them the same way.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

#: ``washbench/data``: parameter sets, platform limits, pilot profiles, aircraft, manoeuvres.
DATA_DIR = Path(str(files("washbench") / "data"))
#: Bundled aircraft models (``<name>/<name>.xml``), searched before JSBSim's own.
AIRCRAFT_DIR = DATA_DIR / "aircraft"
#: Bundled manoeuvres (``<aircraft>/<name>.yaml``): what ``washbench suite`` runs by default.
MANOEUVRES_DIR = DATA_DIR / "manoeuvres"
