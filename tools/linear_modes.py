"""Print the linearised modes of an aircraft at a manoeuvre's start: JSBSim's FGLinearization.

    .venv/bin/python tools/linear_modes.py manoeuvres/c172/rudder_doublet.yaml

The start state is the one ``washbench fly`` begins from (trimmed, or the flying start); the
lateral-directional block (beta, phi, p, r) and the longitudinal one (Vt, alpha, theta, q) of the
system matrix give the Dutch roll, roll and spiral modes, and the short period and phugoid. The
bundled rudder doublets' checks bracket the Dutch roll printed here (c172p: 2.74 s, 0.187;
columbia400: 2.57 s, 0.121). On the Columbia model the linearisation takes minutes of CPU, so the
tests compare the c172p only.
"""

from __future__ import annotations

import math
import sys

import jsbsim
import numpy as np

from washbench.flight.fdm import make_fdm
from washbench.flight.manoeuvre import load_manoeuvre, pilot_profile_path
from washbench.flight.profile import load_profile

BLOCKS = {"lateral": ("Beta", "Phi", "P", "R"), "longitudinal": ("Vt", "Alpha", "Theta", "Q")}


def main(path: str) -> None:
    m = load_manoeuvre(path)
    fdm, _ = make_fdm(m, load_profile(pilot_profile_path(m.aircraft)))
    lin = jsbsim.FGLinearization(fdm)
    names = list(lin.x_names)
    a = np.array(lin.system_matrix)
    for block, states in BLOCKS.items():
        idx = [names.index(n) for n in states]
        for e in sorted(np.linalg.eigvals(a[np.ix_(idx, idx)]), key=lambda z: -abs(z)):
            if e.imag > 0:
                print(
                    f"{block}: oscillatory, period {2 * math.pi / e.imag:.3f} s, damping ratio {-e.real / abs(e):.3f}"
                )
            elif e.imag == 0:
                print(f"{block}: real, time constant {-1 / e.real:.2f} s" if e.real else f"{block}: zero")


if __name__ == "__main__":
    main(sys.argv[1])
