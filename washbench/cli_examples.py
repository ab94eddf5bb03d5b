"""The examples that end each command's ``--help``, and the pointer to the documentation in the top-level help.

Kept apart from ``cli.py`` (which holds the parser) so the examples read as a list; ``tests/test_cli_help.py``
parses every example with the real parser, so an example cannot name an option that does not exist.
A new command needs two or three examples here.
"""

from __future__ import annotations

import argparse

#: Where the documentation is (the top-level help names it).
DOCS = (
    "documentation: each command's --help (its options, then examples) and, for the Python API, "
    "python -m pydoc washbench (both ship with the package). The guides and reference are the docs/ folder of the "
    "washbench source (a checkout, or the source distribution washbench-VERSION.tar.gz; the wheel holds no docs/): "
    "start with docs/tutorial/getting-started.md; every command and option: docs/reference/commands.md; build it "
    "as a site with pip install 'washbench[docs]' && python -m sphinx -b html docs docs/_build/html"
)

#: Command name -> example command lines (each one starts with ``washbench``).
EXAMPLES: dict[str, tuple[str, ...]] = {
    "cue": (
        "washbench cue flight.csv --out cued",
        "washbench cue Data.txt --out cued-xplane --resample 120",
        "washbench cue imu.csv.gz --out cued-imu --columns t=Time:ms,f_x=ax:g,omega_x=p:radps --axes flu",
    ),
    "fly": (
        "washbench fly c172/coordinated_turn --out out/turn",
        "washbench fly manoeuvres/my_turn.yaml --out out/try --aircraft-dir ~/aircraft",
    ),
    "validate": (
        "washbench validate c172 columbia400/takeoff",
        "washbench validate my_turn.yaml --aircraft-dir ~/aircraft",
    ),
    "schema": (
        "washbench schema --out manoeuvre.schema.json",
        "washbench schema | python -m json.tool",
    ),
    "live": (
        "washbench live --listen 127.0.0.1:49005 --format xplane --out live",
        "washbench live --listen 0.0.0.0:5500 --format flightgear --out live-fg --sink udp://192.0.2.10:6000",
        "washbench live --print-flightgear-protocol",
    ),
    "send": (
        "washbench send flight.csv --to 127.0.0.1:49005 --format xplane --speed 10",
        "washbench send --fly c172/takeoff --to 127.0.0.1:49005 --format washbench",
    ),
    "run": (
        "washbench run c172/takeoff --out runs --washout large-angle --washout adaptive-large-angle",
        "washbench run my_turn.yaml --out runs --washout-plugin my_washout.py:MyWashout --washout my-washout",
        "washbench run c172_cruise_8K.xml --out runs --max-time-s 60 --no-recording",
    ),
    "suite": (
        "washbench suite --out results",
        "washbench suite --out results-all --washout all",
        "washbench suite --jsbsim-scripts c1723 c172_cross_wind --out jsbsim-suite",
    ),
    "omct": (
        "washbench omct --out omct",
        "washbench omct --out omct --washout large-angle --boundaries boundaries.yaml --rate-hz 1000",
    ),
    "signal": (
        "washbench signal step --axis f_x --amplitude 2 --out surge_step.csv",
        "washbench signal sine --axis roll --amplitude 10 --frequency-hz 0.2 --duration-s 60 --out roll.parquet",
    ),
    "sweep": (
        "washbench sweep manoeuvres --set tilt.gain_per_s=0.4,1,2,5 --out study",
        "washbench sweep c172 --set tilt.gain_per_s=1,2 --washout large-angle --from results --out study",
        "washbench sweep c172/aileron_3211 --set rotational.highpass_wn_radps.roll=0.2,0.5,1 --pilot c172/roll --out s",
    ),
    "tune": (
        "washbench tune c172/takeoff c172/stall_recovery --washout large-angle --tune tilt.gain_per_s=0.2:5 --out t",
        "washbench tune c172 --washout unrestricted --tune tilt.gain_per_s=0.2:5 --budget 50 --out tuned",
        "washbench tune c172/steep_turn --washout large-angle --tune scale.angular_velocity=0.3:1 --pilot c172/roll "
        "--budget 30 --out t",
    ),
    "track": (
        "washbench track c172/roll --out track-roll",
        "washbench track c172/pitch --out track-pitch --washout large-angle --washout unrestricted --runs 3",
        "washbench track my_task.yaml --out t --variant half=small-angle,scale.angular_velocity=0.5",
    ),
    "examples": (
        "washbench examples my-study",
        "washbench examples . && washbench validate manoeuvres/c172/*.yaml",
    ),
    "report": (
        "washbench report results",
        "washbench report results/c172p/takeoff",
    ),
    "replay": (
        "washbench replay results/c172p/takeoff/recording.rrd",
        "washbench replay --web A/recording.rrd B/recording.rrd",
    ),
}


def subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """The sub-command parsers of ``parser`` by name (empty when it has none)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def add_examples(parser: argparse.ArgumentParser) -> None:
    """Name the docs at the top level; give each command its one-line help as description and its examples."""
    parser.epilog = DOCS
    for action in parser._actions:
        if not isinstance(action, argparse._SubParsersAction):
            continue
        helps = {choice.dest: choice.help for choice in action._choices_actions}
        for name, sub in action.choices.items():
            sub.formatter_class = argparse.RawDescriptionHelpFormatter
            if sub.description is None and helps.get(name):
                sub.description = helps[name]
            lines = EXAMPLES.get(name, ())
            if lines:
                sub.epilog = "examples:\n" + "\n".join(f"  {line}" for line in lines)
