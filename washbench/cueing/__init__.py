"""Motion cueing: the washout stage, from the aircraft's pilot-head motion to the platform's set points.

The washouts, each a kind in :mod:`washbench.cueing.registry` (``washbench run --help`` lists their names): the
classical washouts of Micomonaco et al. (``small-angle``, Reid and Nahon's; its ``large-angle`` quaternion extension;
the ``unrestricted`` angular washout) and the coordinated adaptive washout in the same three forms, compiled
(``kernel``, ``bank``); the optimal (LQ) washout (``optimal``); the model-predictive ones (``mpc``,
``mpc-unrestricted``); the oracle bound (``bound``, computed over a whole recording: :mod:`washbench.analysis.bound`);
the naive references (``replay``, ``replay-rotation``, ``still``: :mod:`washbench.cueing.references`); and any
plugin (``--washout-plugin FILE.py:NAME`` or the ``washbench.washouts`` entry points). Each drives any platform
(:mod:`washbench.platform`) that it can, through the same interface (``algorithm``).

Public API::

    from washbench.cueing import (WASHOUT_NAMES, check_washouts, WashoutParams, load_washout_params,
                                  CueingBank, WashoutTrace, cue_trace)
    from washbench.cueing.variants import Washout, parse_variant, select_washouts   # named variants

See ``docs/cueing.md`` for the block diagrams as implemented and every interpretation of the paper.
Frames and units: aircraft and simulator body axes x forward, y right, z down; inertial NED with
g_I = [0, 0, +g]; specific force f = a - g (m/s^2, [0, 0, -g] at rest); body angular velocity rad/s;
quaternions scalar first, body->inertial; break frequencies rad/s.

Modules: ``params`` (cw1.yaml model), ``variants`` (named washouts with their own parameters), ``filters``
(transfer functions, discretisation), ``kernel`` (the compiled step), ``bank`` (CueingBank, cue_trace).
Quaternion and Euler kinematics and numba's cache are one floor down, in :mod:`washbench.numerics`
(:mod:`washbench.numerics.rotations`, :mod:`washbench.numerics.jitcache`).
The bank names are loaded lazily, so importing the package for its parameters stays light.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from washbench.cueing.params import WASHOUT_KINDS, WASHOUT_NAMES, WashoutParams
from washbench.cueing.registry import check_washouts
from washbench.cueing.variants import load_washout_params
from washbench.io.outfolder import signals_held
from washbench.numerics.jitcache import configure_cache

configure_cache()  # before any jitted module is imported (numba reads its cache folder at decoration)

if TYPE_CHECKING:
    from washbench.cueing.bank import CueingBank, WashoutTrace, cue_trace

__all__ = [
    "WASHOUT_KINDS",
    "WASHOUT_NAMES",
    "CueingBank",
    "WashoutParams",
    "WashoutTrace",
    "check_washouts",
    "cue_trace",
    "load_washout_params",
]

_LAZY = {"CueingBank", "WashoutTrace", "cue_trace"}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        with signals_held():  # a SIGINT/SIGTERM in the middle of this import was lost (acts once it is done)
            from washbench.cueing import bank  # deferred: numba

        return getattr(bank, name)
    raise AttributeError(f"module 'washbench.cueing' has no attribute {name!r}")
