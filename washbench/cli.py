"""The ``washbench`` command. Argument parsing lives here and nowhere else.

Each sub-command hands plain values to a function in the module that owns the work;
those functions raise :class:`washbench.errors.WashbenchError` for bad input, which is
printed here as one line (no traceback) with exit status 2.
"""

from __future__ import annotations

import argparse
import difflib
import errno
import os
import signal
import sys
from pathlib import Path
from typing import Any

from washbench import __version__
from washbench.cli_examples import add_examples, subcommands
from washbench.cueing import registry
from washbench.cueing.params import WASHOUT_KINDS
from washbench.errors import Terminated, WashbenchError, printable
from washbench.io import config as project_config
from washbench.io import interrupts
from washbench.io.examples import copy_examples
from washbench.io.paths import resolve_data_file, resolve_manoeuvre, resolve_task, unknown_manoeuvre
from washbench.live import FORMATS
from washbench.review.replay import replay_command
from washbench.runs.outputs import Outputs

_VARIANT_HELP = "add a washout NAME of KIND with dotted-key overrides of the parameter file, repeatable"


def _plugin_option(p: argparse.ArgumentParser) -> None:
    """--washout-plugin FILE.py:NAME, shared by every command that runs washouts."""
    p.add_argument(
        "--washout-plugin",
        action="append",
        default=[],
        metavar="FILE.py:NAME",
        help="load a washout algorithm from a Python file (docs/washouts.md); its name is then a washout, repeatable",
    )


def _washout_options(p: argparse.ArgumentParser, variants: bool = True) -> None:
    """--washout (built-in washouts) and --variant (named variants), shared by cue, run, suite (and omct)."""
    p.add_argument(
        "--washout",
        action="append",
        metavar="NAME",
        help=f"washout to run, repeatable: {', '.join(WASHOUT_KINDS)}, optimal, mpc, mpc-unrestricted, the naive "
        "references replay, replay-rotation, still, bound (whole recordings), a plugin's name, or all (every "
        "built-in, the references and the bound) (default: small-angle, large-angle, unrestricted and the three "
        "references, or none with a variant)",
    )
    if variants:
        p.add_argument("--variant", action="append", default=[], metavar="NAME=KIND[,KEY=VALUE...]", help=_VARIANT_HELP)
    _plugin_option(p)


def _rank_option(p: argparse.ArgumentParser) -> None:
    """--rank-by, --thresholds and --vestibular (cue, live, run, suite), recorded in the provenance
    (docs/metrics.md)."""
    p.add_argument("--rank-by", choices=("felt", "score", "false-cue", "weighted"),
                   help="ranking rule (default: the parameter file's ranking: section, else felt: the felt error); "
                   "score is the rule before it; weighted uses the section's ranking.dof_weights")  # fmt: skip
    p.add_argument("--thresholds", choices=("zacharias", "none"),
                   help="perception thresholds of the felt error (default: the parameter file's ranking: section, "
                   "else zacharias: Zacharias 1978); none: no dead band")  # fmt: skip
    p.add_argument("--vestibular", choices=("young-meiry", "telban-cardullo"),
                   help="vestibular models (default young-meiry: Meiry-Young otolith, Young-Oman canals)")


def _platform_options(p: argparse.ArgumentParser) -> None:
    """--platform and --platform-plugin (docs/platforms.md)."""
    p.add_argument("--platform", type=Path, metavar="FILE|NAME",
                   help="platform file, its kind: key picks the model: atlas, hexapod, rig or a plugin's; or a bundled "
                   "one by name from any folder: atlas, hexapod, rig2dof (default: atlas)")  # fmt: skip
    p.add_argument("--platform-plugin", metavar="FILE.py:NAME",
                   help="load a platform from a Python file (docs/platforms.md); without --platform it is the platform")


def _study_options(p: argparse.ArgumentParser) -> None:
    """What sweep and tune share."""
    _plugin_option(p)
    p.add_argument("--params", type=Path, help="base washout parameter YAML (default: the bundled cw1)")
    _platform_options(p)
    p.add_argument(
        "--from",
        dest="from_dir",
        type=Path,
        metavar="RESULTS_DIR",
        help="read RESULTS_DIR/<aircraft>/<manoeuvre>/flight.parquet instead of flying",
    )
    p.add_argument("--jobs", type=_jobs, help="processes for the flights (default: the CPUs this process may use)")
    p.add_argument("--dask", metavar="ADDRESS", help="send the work to this Dask scheduler (washbench[cluster])")
    p.add_argument("--quiet", action="store_true", help="no progress display")
    _aircraft_dir_option(p)
    p.add_argument("--pilot", type=Path, metavar="TASK",
                   help="the pilot model's measures on this tracking task too (docs/pilot-model.md)")  # fmt: skip


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors are one line and exit 2 (as argparse does), naming the option meant for
    one it does not know (``--output``: did you mean ``--out``?)."""

    def parse_known_args(self, args: Any = None, namespace: Any = None) -> Any:  # type: ignore[override]
        self._given = list(sys.argv[1:] if args is None else args)
        return super().parse_known_args(args, namespace)

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message}{self._meant()}\n")

    def _meant(self) -> str:
        """`` (--output: did you mean --out?)`` for each option given that this command does not know."""
        given = getattr(self, "_given", [])
        command = subcommands(self).get(next((w for w in given if not w.startswith("-")), ""), self)
        known = [s for a in command._actions for s in a.option_strings]
        meant = []
        for word in dict.fromkeys(w.partition("=")[0] for w in given if w.startswith("--")):
            close = difflib.get_close_matches(word, known, n=1, cutoff=0.6) if word not in known else []
            meant += [f"{word}: did you mean {close[0]}?"] if close else []
        return f" ({'; '.join(meant)})" if meant else ""


def _out_path(text: str) -> Path:
    """``--out``: not empty (an empty string would silently mean the current folder)."""
    if not text:
        raise argparse.ArgumentTypeError("an empty path; name a folder (. for the current one)")
    return Path(text)


def _check_paths(args: argparse.Namespace) -> None:
    """Every path argument must be valid UTF-8 (results and messages name it): one line otherwise."""
    for key, value in vars(args).items():
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, Path):
                try:
                    str(item).encode("utf-8")
                except UnicodeEncodeError:
                    shown = str(item).encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
                    raise WashbenchError(f"{shown}: the path is not valid UTF-8 ({key}); rename it") from None


def _jobs(text: str) -> int:
    """``--jobs``: a whole number of at least 1 (argparse reports anything else as a usage error)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid int value: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected at least 1 process, got {value}")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The full command-line interface."""
    parser = _Parser(
        prog="washbench",
        description="A testbed for flight-simulator motion cueing: JSBSim manoeuvres, recorded logs or a simulator's "
        "live output through washouts (classical small-angle, large-angle and unrestricted, their adaptive forms, "
        "optimal, model-predictive, the oracle bound, naive references, your own plugins: `washbench run --help` "
        "lists them) on a "
        "kinematic platform (the Atlas, a hexapod, a rig or your own), vestibular models, metrics and a ranking.",
    )
    parser.add_argument("--version", action="version", version=_version_line())
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    p = sub.add_parser("cue", help="run washouts, platform model, vestibular models and metrics on a recorded trace")
    p.add_argument(
        "input",
        type=Path,
        help="CSV/TSV/TXT (.gz too), Parquet, X-Plane Data.txt or JSBSim CSV output; washbench's own columns "
        "t_s, f_{x,y,z}_mps2, omega_{x,y,z}_degps unless mapped",
    )
    p.add_argument("--out", type=_out_path, required=True, help="output folder (a run result folder's files)")
    _cue_input_options(p)
    _washout_options(p)
    _rank_option(p)
    p.add_argument("--params", type=Path, help="washout parameter YAML (default: the bundled cw1)")
    _platform_options(p)

    p = sub.add_parser("fly", help="fly a manoeuvre file with JSBSim and the scripted pilot")
    p.add_argument("manoeuvre", type=Path, help="manoeuvre YAML file, or a bundled one by name (c172/takeoff)")
    p.add_argument("--out", type=_out_path, required=True, help="output folder (flight.parquet, flight.json)")
    _aircraft_dir_option(p)
    p.add_argument("--quiet", action="store_true", help="no progress display")

    p = sub.add_parser("validate", help="check manoeuvre files and JSBSim scripts without flying them")
    p.add_argument("manoeuvres", type=Path, nargs="+", help="manoeuvre files, JSBSim scripts, folders or bundled names")
    _aircraft_dir_option(p)

    p = sub.add_parser("schema", help="print the manoeuvre file JSON Schema")
    p.add_argument("--out", type=Path, help="write to this file instead of standard output")

    p = sub.add_parser("run", help="fly a manoeuvre with the washouts in lockstep; write traces, metrics, recording")
    p.add_argument(
        "manoeuvre", type=Path,
        help="manoeuvre YAML file, a bundled one by name (c172/takeoff), or a JSBSim script (a file, or one shipped "
        "with JSBSim by name: c1723)",
    )
    p.add_argument("--out", type=_out_path, required=True, help="results folder; writes OUT/<aircraft>/<manoeuvre>/")
    _washout_options(p)
    _rank_option(p)
    _aircraft_dir_option(p)
    p.add_argument("--max-time-s", type=float, metavar="S", help="JSBSim script: stop after S s (default 1200)")
    p.add_argument("--filter-start", choices=("steady", "rest"), default="steady", help="filters' start state")
    p.add_argument("--params", type=Path, help="washout parameter YAML (default: the bundled cw1)")
    _platform_options(p)
    p.add_argument("--quiet", action="store_true", help="no progress display")
    _output_options(p)

    p = sub.add_parser("suite", help="run many manoeuvres in parallel and compare the washouts")
    p.add_argument(
        "inputs",
        type=Path,
        nargs="*",
        help="manoeuvre files, JSBSim scripts or folders, or bundled manoeuvres by name (c172, columbia400/takeoff); "
        "default: all bundled",
    )
    p.add_argument("--jsbsim-scripts", nargs="+", default=[], metavar="NAME", help="scripts shipped with JSBSim")
    p.add_argument("--max-time-s", type=float, metavar="S", help="JSBSim scripts: stop each after S s (default 1200)")
    p.add_argument("--out", type=_out_path, required=True, help="results folder")
    _aircraft_dir_option(p)
    p.add_argument("--jobs", type=_jobs, help="parallel processes (default: the CPUs this process may use)")
    _washout_options(p)
    _rank_option(p)
    p.add_argument("--params", type=Path, help="washout parameter YAML (default: the bundled cw1)")
    _platform_options(p)
    p.add_argument("--dask", metavar="ADDRESS", help="run on this Dask scheduler instead of local processes")
    p.add_argument("--quiet", action="store_true", help="no progress display")
    _output_options(p)

    p = sub.add_parser("omct", help="Objective Motion Cueing Test: gain and phase of each washout, Bode plots")
    p.add_argument("--out", type=_out_path, required=True, help="output folder (omct.csv, bode_<test>.png, report.md)")
    _washout_options(p)
    p.add_argument("--params", type=Path, help="washout parameter YAML (default: the bundled cw1)")
    _platform_options(p)
    p.add_argument("--boundaries", type=Path, help="gain/phase boundaries YAML, drawn and checked (docs: OMCT)")
    p.add_argument("--rate-hz", type=float, default=120.0, help="washout sample rate (default 120)")
    p.add_argument("--amplitude-scale", type=float, default=1.0, help="multiply every input amplitude (default 1)")
    p.add_argument("--quiet", action="store_true", help="no progress display")

    p = sub.add_parser("signal", help="write a test signal on one axis as a washbench cue input")
    p.add_argument("kind", help="signal shape: sine, step, pulse, doublet, chirp, multisine")
    p.add_argument(
        "--axis", required=True, help="f_x, f_y, f_z (specific force, or surge, sway, heave), roll, pitch, yaw"
    )
    p.add_argument("--amplitude", type=float, required=True, help="m/s^2 (f_x, f_y, f_z) or deg/s (rotations)")
    p.add_argument("--frequency-hz", type=float, help="frequency (every kind but step; see docs/how-to/omct.md)")
    p.add_argument("--duration-s", type=float, default=20.0, help="length (default 20 s)")
    p.add_argument("--rate-hz", type=float, default=120.0, help="sample rate (default 120 Hz)")
    p.add_argument("--start-s", type=float, default=1.0, help="onset of step, pulse, doublet, chirp (default 1 s)")
    p.add_argument("--out", type=_out_path, required=True, help="output file, .csv or .parquet")

    p = sub.add_parser("sweep", help="a grid of washout parameters on recorded flights: scores and metrics per point")
    p.add_argument("manoeuvres", type=Path, nargs="+", help="manoeuvre files or folders")
    p.add_argument("--washout", action="append", metavar="KIND", help="washout kind, repeatable (default: all three)")
    p.add_argument(
        "--set",
        dest="sets",
        action="append",
        default=[],
        metavar="KEY=V1,V2,...",
        help="a parameter-file key and its values, repeatable (the grid is every combination)",
    )
    p.add_argument(
        "--out", type=_out_path, required=True, help="output folder (sweep.csv, sweep_metrics.csv, sweep.png)"
    )
    p.add_argument("--force", action="store_true", help="run a grid of more than 2000 points")
    _study_options(p)

    p = sub.add_parser("tune", help="tune washout parameters on training manoeuvres (differential evolution)")
    p.add_argument("manoeuvres", type=Path, nargs="+", help="training manoeuvre files or folders")
    p.add_argument(
        "--washout", required=True, metavar="KIND",
        help=f"washout kind: {', '.join(WASHOUT_KINDS)}, optimal, mpc, mpc-unrestricted or a plugin's name",
    )  # fmt: skip
    p.add_argument(
        "--tune",
        dest="tunes",
        action="append",
        default=[],
        metavar="KEY=LOW:HIGH",
        help="a parameter-file key and its search interval, repeatable",
    )
    p.add_argument("--test", type=Path, nargs="+", default=[], metavar="MANOEUVRE", help="test manoeuvres")
    p.add_argument("--budget", type=int, default=200, help="evaluations at most (default 200)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0): same seed, same result")
    p.add_argument(
        "--saturation-weight",
        type=float,
        default=1.0,
        help="penalty per unit fraction of time at a platform limit (default 1)",
    )
    p.add_argument("--out", type=_out_path, required=True, help="output folder (tuned.yaml, tune.csv, report.md)")
    p.add_argument("--pilot-weight", type=float, default=1.0,
                   help="with --pilot: weight of the pilot's distance from flight (%%/100) (default 1)")  # fmt: skip
    _study_options(p)
    _track_parser(sub)
    p = sub.add_parser("examples", help="copy the bundled manoeuvres, pilot profiles, parameter and platform files "
                       "into a folder to edit")
    p.add_argument("folder", type=Path, help="destination (created; existing files are never overwritten)")

    p = sub.add_parser("report", help="write report.md and its figures (PNG and PDF) again from existing results")
    p.add_argument("results", type=Path, help="a result folder (washbench run / cue) or a suite folder")
    p.add_argument("--palette", choices=("default", "colorblind"), default=None,
                   help="figure colours: default, or colorblind (Okabe-Ito); also $WASHBENCH_PALETTE")  # fmt: skip

    p = sub.add_parser("replay", help="open a recording (or compare two) in the rerun viewer")
    p.add_argument(
        "recording", type=Path, nargs="+", help=".rrd file(s) from washbench run or suite: one, or two to compare"
    )
    p.add_argument("--web", action="store_true", help="always use the web viewer")
    _live_parsers(sub)
    add_examples(parser)  # the docs named at the top level, examples at the end of each command's help
    return parser


def _track_parser(sub: Any) -> None:
    """``washbench track`` (docs/pilot-model.md)."""
    p = sub.add_parser("track", help="a pilot model flies a tracking task in JSBSim through each washout: how its "
                       "control changes from flight")  # fmt: skip
    p.add_argument("task", type=Path, help="task YAML file, or a bundled one by name (c172/roll, columbia400/pitch)")
    p.add_argument("--out", type=_out_path, required=True,
                   help="output folder (report.md, track.json, measures.csv, frf.csv, signals.parquet)")  # fmt: skip
    _washout_options(p)
    p.add_argument("--vestibular", choices=("young-meiry", "telban-cardullo"),
                   help="vestibular models of the pilot (default telban-cardullo: canals with a lead)")  # fmt: skip
    p.add_argument("--params", type=Path, help="washout parameter YAML (default: bundled CW1)")
    _platform_options(p)
    p.add_argument("--runs", type=int, metavar="N", help="runs per condition (default: the task's)")
    p.add_argument("--pilot-plugin", metavar="FILE.py:NAME",
                   help="fly your own pilot model from a Python file (docs/pilot-model.md)")  # fmt: skip
    _aircraft_dir_option(p)
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    _output_options(p)
    p.set_defaults(rank_by=None, thresholds=None)  # the run options track does not take (the ranking's)


def _track(args: argparse.Namespace) -> int:
    from washbench.runs.track import TrackOptions, track_command  # deferred: numba

    opts = TrackOptions(runs=args.runs, outputs=_outputs(args), progress=not args.quiet, pilot_plugin=args.pilot_plugin)
    return track_command(resolve_task(args.task), args.out, _run_options(args), opts)


def _live_parsers(sub: Any) -> None:
    """``washbench live`` and ``washbench send`` (docs/live.md)."""

    p = sub.add_parser("live", help="run the washouts live on a flight simulator's UDP output; drive a platform")
    p.add_argument("--listen", metavar="HOST:PORT", help="where to receive the simulator's datagrams")
    p.add_argument("--format", choices=FORMATS, help="what the simulator sends (docs/live.md)")
    p.add_argument("--out", type=Path, help="output folder: the result folder of washbench cue on the saved input")
    p.add_argument("--sink", metavar="udp://HOST:PORT", help="send the platform commands there (default: nowhere)")
    p.add_argument("--sink-format", choices=("binary", "json"), default="binary", help="command packets (docs/live.md)")
    p.add_argument("--duration", type=float, metavar="S", help="stop after S seconds")
    p.add_argument("--idle-timeout", type=float, metavar="S", help="stop when the source is quiet for S seconds")
    p.add_argument("--rate-hz", type=float, metavar="HZ", help="the source's rate (default: measured)")
    p.add_argument("--resample", type=float, metavar="HZ", help="cue the saved input at HZ (default: only if needed)")
    p.add_argument("--xplane", metavar="HOST:PORT", default="127.0.0.1:49000", help="X-Plane's address for RREF")
    p.add_argument("--rref-hz", type=int, default=60, metavar="HZ", help="RREF subscription rate (default 60)")
    p.add_argument("--no-viewer", action="store_true", help="no live rerun viewer")
    p.add_argument("--realtime", action="store_true", help="SCHED_FIFO priority while receiving (root/CAP_SYS_NICE)")
    p.add_argument("--filter-start", choices=("steady", "rest"), default="steady", help="filters' start state")
    p.add_argument("--print-flightgear-protocol", action="store_true", help="print FlightGear's protocol file, exit")
    _washout_options(p)
    p.add_argument("--params", type=Path, help="washout parameter YAML (default: the bundled cw1)")
    _platform_options(p)
    _rank_option(p)
    _output_options(p)

    p = sub.add_parser("send", help="send a recorded file or a JSBSim flight over UDP as a flight simulator would")
    p.add_argument("file", type=Path, nargs="?", help="any washbench cue input")
    p.add_argument("--fly", type=Path, metavar="MANOEUVRE", help="fly this manoeuvre with JSBSim and send it")
    p.add_argument("--to", metavar="HOST:PORT", help="where washbench live listens")
    p.add_argument("--format", choices=FORMATS, default="washbench", help="what to send as (default washbench)")
    p.add_argument("--speed", type=float, default=1.0, help="times real time (default 1)")
    p.add_argument("--listen", metavar="HOST:PORT", help="xplane-rref: where to take subscriptions (X-Plane's 49000)")
    _aircraft_dir_option(p)


def _live(args: argparse.Namespace) -> int:
    from washbench.live.endpoints import parse_address  # deferred: numba
    from washbench.runs.live import LiveOptions, run_live  # deferred: numba

    if args.print_flightgear_protocol:
        from washbench.live.packets import flightgear_protocol  # deferred: numpy

        print(flightgear_protocol(), end="")
        return 0
    for flag, value in (("--listen", args.listen), ("--format", args.format), ("--out", args.out)):
        if value is None:
            raise WashbenchError(f"{flag} is required")
    opts = LiveOptions(
        listen=parse_address(args.listen, "--listen"), fmt=args.format, out=args.out,
        sink=parse_address(args.sink, "--sink") if args.sink else None, sink_format=args.sink_format,
        duration_s=args.duration, idle_timeout_s=args.idle_timeout, rate_hz=args.rate_hz, resample_hz=args.resample,
        xplane=parse_address(args.xplane, "--xplane"), rref_hz=args.rref_hz, viewer=not args.no_viewer,
        realtime=args.realtime,
    )  # fmt: skip
    return run_live(opts, _run_options(args))


def _send(args: argparse.Namespace) -> int:
    from washbench.live.endpoints import parse_address  # deferred: numba
    from washbench.runs.send import run_send  # deferred: pyarrow

    to = parse_address(args.to, "--to") if args.to else None
    listen = parse_address(args.listen, "--listen") if args.listen else None
    return run_send(args.format, to, args.file, args.fly, args.speed, listen, tuple(args.aircraft_dir))


def _cue_input_options(p: argparse.ArgumentParser) -> None:
    """``washbench cue``'s options for reading, converting, cutting and checking a recording."""
    g = p.add_argument_group("reading and converting the input")
    g.add_argument(
        "--columns", metavar="MAP", help="field=[-]COLUMN[:UNIT],... e.g. t=Time:ms,f_x=ax:g,omega_x=p:radps"
    )
    g.add_argument("--input-format", type=Path, metavar="FILE", help="YAML: format, delimiter, axes, columns")
    g.add_argument("--axes", metavar="XYZ", help="sensor axes as body directions, e.g. flu (z up, y left); default frd")
    g.add_argument("--delimiter", metavar="D", help="CSV delimiter (default: detected): , ; tab | or a character")
    g.add_argument("--decimal", choices=(".", ","), help="decimal mark of the numbers (default .)")
    g.add_argument("--jsbsim-dt", type=float, metavar="S", help="JSBSim CSV: the simulation frame time (script dt)")
    g = p.add_argument_group("time")
    g.add_argument("--resample", type=float, metavar="HZ", help="interpolate onto a uniform grid at HZ (anti-alias)")
    g.add_argument("--force", action="store_true", help="resample even to more than 100 times the rows read")
    g.add_argument("--max-gap-s", type=float, metavar="S", help="largest allowed time step (default: 5 median steps)")
    g.add_argument("--no-split", action="store_true", help="refuse a time reset instead of cueing each part")
    g.add_argument("--start-s", type=float, metavar="S", help="cue from this time on (input time, s)")
    g.add_argument("--end-s", type=float, metavar="S", help="cue up to this time (input time, s)")
    g.add_argument("--filter-start", choices=("steady", "rest"), default="steady",
                   help="filters start in the first sample's steady state (default) or at rest")  # fmt: skip
    g = p.add_argument_group("checks and outputs")
    g.add_argument("--strict", action="store_true", help="plausibility warnings are errors")
    g.add_argument("--quiet", action="store_true", help="no progress display")
    _output_options(g)


def _output_options(p: Any) -> None:
    """--no-recording and --no-figures (run, suite, cue): the optional parts of a result folder."""
    p.add_argument("--no-recording", action="store_true", help="do not write recording.rrd (smaller, faster)")
    p.add_argument("--no-figures", action="store_true",
                   help="report.md without figures (faster; `washbench report DIR` draws them later)")  # fmt: skip


def _outputs(args: argparse.Namespace) -> Any:
    return Outputs(recording=not args.no_recording, figures=not args.no_figures)


def _run_options(args: argparse.Namespace) -> Any:
    """The options of ``run``, ``suite``, ``cue`` and ``live`` (:func:`washbench.runs.options.load_options`: each
    file read once); what a command has no flag for is the default."""
    from washbench.runs.options import load_options  # deferred: numpy

    return load_options(params_path=args.params, platform_path=args.platform, washouts=args.washout,
                        variants=args.variant, aircraft_dirs=getattr(args, "aircraft_dir", ()), outputs=_outputs(args),
                        filter_start=getattr(args, "filter_start", "steady"),
                        max_time_s=getattr(args, "max_time_s", None), rank_by=args.rank_by,
                        vestibular=args.vestibular, thresholds=args.thresholds)  # fmt: skip


def _cue(args: argparse.Namespace) -> int:
    from washbench.io.input_format import input_format  # deferred: numpy
    from washbench.runs.cue import CueOptions, run_cue  # deferred: pyarrow

    opts = CueOptions(
        fmt=input_format(args.columns, args.input_format, args.axes, args.delimiter, args.decimal, args.jsbsim_dt),
        resample_hz=args.resample,
        max_gap_s=args.max_gap_s,
        split=not args.no_split,
        start_s=args.start_s,
        end_s=args.end_s,
        strict=args.strict,
        progress=not args.quiet,
        force=args.force,
    )
    return run_cue(args.input, args.out, opts, _run_options(args))


def _aircraft_dir_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--aircraft-dir",
        type=Path,
        action="append",
        default=[],
        metavar="DIR",
        help="folder of aircraft (<DIR>/<name>/<name>.xml, <DIR>/<name>/pilot.yaml), searched first; repeatable",
    )


def _version_line() -> str:
    """``washbench X (JSBSim Y, rerun-sdk Z, Python W)`` from the installed distributions (no heavy imports)."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    def dist(name: str) -> str:
        try:
            return version(name)
        except PackageNotFoundError:
            return "not installed"

    return (
        f"washbench {__version__} (JSBSim {dist('jsbsim')}, rerun-sdk {dist('rerun-sdk')}, "
        f"numpy {dist('numpy')}, Python {platform.python_version()})"
    )


def _dispatch(args: argparse.Namespace) -> int:
    if hasattr(args, "manoeuvre") or hasattr(args, "manoeuvres"):
        if hasattr(args, "manoeuvre"):
            args.manoeuvre = resolve_manoeuvre(args.manoeuvre)
            if not args.manoeuvre.exists():
                raise unknown_manoeuvre(args.manoeuvre)
        else:
            args.manoeuvres = [resolve_manoeuvre(m) for m in args.manoeuvres]
    washouts = getattr(args, "washout", None)
    for name in [washouts] if isinstance(washouts, str) else washouts or []:
        if "," in name:  # --washout a,b: one name per --washout
            parts = [f"--washout {n.strip()}" for n in name.split(",") if n.strip()]
            how = f"one at a time ({parts[0]})" if isinstance(washouts, str) else f"repeat it: {' '.join(parts)}"
            raise WashbenchError(f"--washout {name}: one washout per --washout; {how}")
    for option in ("platform", "params"):  # a bundled file by name from any folder (hexapod, washbench:data/...)
        if getattr(args, option, None) is not None:
            setattr(args, option, resolve_data_file(getattr(args, option), f"--{option}"))
    if args.command == "cue":
        return _cue(args)
    if args.command == "fly":
        from washbench.flight.fly import fly_command  # deferred: numpy

        return fly_command(args.manoeuvre, args.out, progress=not args.quiet, aircraft_dirs=args.aircraft_dir)
    if args.command == "validate":
        from washbench.flight.validate import validate_command  # deferred: numpy

        return validate_command(args.manoeuvres, aircraft_dirs=args.aircraft_dir)
    if args.command == "schema":
        from washbench.flight.json_schema import schema_command  # deferred: pydantic

        return schema_command(args.out)
    if args.command == "run":
        from washbench.runs.pipeline import run_command  # deferred: pyarrow

        return run_command(args.manoeuvre, args.out, _run_options(args), progress=not args.quiet)
    if args.command == "suite":
        from washbench.runs.suite import suite_command  # deferred: pyarrow

        return suite_command(
            args.inputs,
            args.out,
            _run_options(args),
            jobs=args.jobs,
            progress=not args.quiet,
            jsbsim_scripts=args.jsbsim_scripts,
            dask=args.dask,
        )
    if args.command == "omct":
        from washbench.runs.omct import run_omct  # deferred: pyarrow

        run_omct(
            args.out,
            args.washout,
            args.params,
            args.platform,
            args.boundaries,
            rate_hz=args.rate_hz,
            amplitude_scale=args.amplitude_scale,
            variants=args.variant,
            progress=not args.quiet,
        )
        return 0
    if args.command == "signal":
        from washbench.runs.omct import signal_command  # deferred: pyarrow

        return signal_command(
            args.kind,
            args.axis,
            args.amplitude,
            args.frequency_hz,
            args.duration_s,
            args.rate_hz,
            args.start_s,
            args.out,
        )
    if args.command in ("sweep", "tune"):
        return _study(args)
    if args.command == "examples":
        return copy_examples(args.folder)
    if args.command == "report":
        from washbench.review.report_command import report_command  # deferred: numpy

        return report_command(args.results, args.palette)
    if args.command == "track":
        return _track(args)
    if args.command in ("live", "send"):
        return _live(args) if args.command == "live" else _send(args)
    if args.command == "replay":
        return replay_command(args.recording, web=args.web)
    raise AssertionError(f"unhandled command {args.command}")  # unreachable: argparse restricts choices


def _study(args: argparse.Namespace) -> int:
    common = dict(
        params_path=args.params,
        platform_path=args.platform,
        from_dir=args.from_dir,
        jobs=args.jobs,
        dask=args.dask,
        progress=not args.quiet,
        aircraft_dirs=args.aircraft_dir,
        pilot=resolve_task(args.pilot) if args.pilot is not None else None,
    )
    if args.command == "sweep":
        from washbench.runs.sweep import sweep_command  # deferred: numba

        return sweep_command(
            args.manoeuvres, args.out, washouts=args.washout, sets=args.sets, force=args.force, **common
        )
    from washbench.runs.tune import tune_command  # deferred: numba

    return tune_command(
        args.manoeuvres,
        args.out,
        washout=args.washout,
        tunes=args.tunes,
        test=args.test,
        budget=args.budget,
        seed=args.seed,
        saturation_weight=args.saturation_weight,
        pilot_weight=args.pilot_weight,
        **common,
    )


def _quiet_broken_pipe() -> int:
    """Standard output was closed early (``washbench validate ... | head -1``): exit quietly, like a Unix tool."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # the interpreter's last flush must not fail again
    except (OSError, ValueError):
        pass
    return 141  # 128 + SIGPIPE, what a shell reports for a tool stopped by a closed pipe


def _load_plugins(args: argparse.Namespace) -> None:
    """Load every ``--washout-plugin`` before anything reads a parameter file or a washout name."""
    specs = getattr(args, "washout_plugin", None) or []
    if specs:
        for spec in specs:
            registry.load_plugin(spec)
    platform_spec = getattr(args, "platform_plugin", None)
    if platform_spec:
        from washbench.platform import model, plugins  # deferred: numpy

        kind = plugins.load_plugin(platform_spec)
        model.set_default_plugin(kind if getattr(args, "platform", None) is None else None)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``washbench`` console script; returns the exit status.

    SIGINT and SIGTERM stop the command at once: cleanup code runs (half-built results are removed, worker
    processes and viewers stopped), one line is printed and the status is 130 or 143.
    """
    notes: list[str] = []
    try:  # the project configuration file (washbench.toml or [tool.washbench]) gives defaults; a flag wins
        config = project_config.discover(notes=notes)
    except (WashbenchError, MemoryError) as exc:
        if not {"-h", "--help", "--version"} & set(sys.argv[1:] if argv is None else argv):
            text = str(exc) if isinstance(exc, WashbenchError) else "out of memory reading the configuration file"
            print(f"washbench: error: {printable(text)}", file=sys.stderr)
            return 2
        config = None
    parser = build_parser()
    if config is not None:
        _config_defaults(parser, config)
    args = parser.parse_args(argv)
    for note in notes:
        print(f"washbench: warning: {note}", file=sys.stderr)
    if config is not None:  # which defaults apply is never silent
        print(f"washbench: note: configuration from {printable(str(config.path))}", file=sys.stderr)
    if config is not None and getattr(args, "aircraft_dir", None) == []:
        args.aircraft_dir = list(config.aircraft_dirs)  # a --aircraft-dir given at all replaces the file's list
    env_before = os.environ.pop(project_config.CONFIG_USED_ENV, None)
    if config is not None:  # recorded in the provenance, also by worker processes
        os.environ[project_config.CONFIG_USED_ENV] = str(config.path)
    signal.signal(signal.SIGTERM, interrupts.terminate)
    sigint_before = signal.signal(signal.SIGINT, interrupts.interrupt)  # counted (a plugin's KeyboardInterrupt is not)
    signals_before = interrupts.received()
    hook, sys.unraisablehook = sys.unraisablehook, interrupts.signal_in_finalizer
    try:
        try:
            _check_paths(args)
            _load_plugins(args)
            status = _dispatch(args)
            sys.stdout.flush()
            interrupts.raise_pending()  # signalled at the very end (swallowed in a finalizer): done, say so anyway
            return status
        except WashbenchError as exc:
            print(f"washbench: error: {printable(str(exc))}", file=sys.stderr)
            return 2
        except BrokenPipeError:
            return _quiet_broken_pipe()
        except OSError as exc:  # the environment (disk full, permissions) where no file-specific message was made
            full = exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS)
            named = exc.filename or (getattr(args, "out", None) if full else None)  # a full disk: name --out
            where = f"{named}: " if named else ""
            print(f"washbench: error: {printable(where + str(exc.strerror or exc))}", file=sys.stderr)
            return 2
        except MemoryError:
            print("washbench: error: out of memory (an input or option asks for more than this machine has)",
                  file=sys.stderr)  # fmt: skip
            return 2
        except Exception as exc:  # a signal's exception wrapped by Python (a class made mid-import): the signal
            signalled = interrupts.signal_beneath(exc, signals_before)
            if signalled is None:
                raise
            raise signalled from None
    except KeyboardInterrupt as exc:
        print(printable(f"washbench: interrupted{_what_it_cost(exc)}"), file=sys.stderr)
        return 130
    except Terminated as exc:
        print(printable(f"washbench: terminated{_what_it_cost(exc)}"), file=sys.stderr)
        return 143
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.signal(signal.SIGINT, sigint_before)
        sys.unraisablehook = hook
        os.environ.pop(project_config.CONFIG_USED_ENV, None)
        if env_before is not None:
            os.environ[project_config.CONFIG_USED_ENV] = env_before


def _what_it_cost(exc: BaseException) -> str:
    """``: TEXT`` when the interrupted command said what the interruption cost (:func:`interrupts.explain`)."""
    text = interrupts.explanation(exc)
    return f": {text}" if text else ""


def _config_defaults(parser: argparse.ArgumentParser, config: project_config.ProjectConfig) -> None:
    """The configuration file's values as each command's defaults (a required --out is then optional)."""
    for name, sub in subcommands(parser).items():
        defaults = project_config.defaults_for(config, name, [a.dest for a in sub._actions])
        defaults.pop("aircraft_dir", None)  # appended to by --aircraft-dir, so applied after parsing instead
        for action in sub._actions:
            if action.dest in defaults:
                action.default = defaults[action.dest]
                action.required = False


if __name__ == "__main__":
    raise SystemExit(main())
