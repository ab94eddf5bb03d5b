"""The options of a run (washbench.runs.options): each file read once per command, the provenance the same as one
build_provenance call with everything, and the object a suite hands its workers as it is."""

from __future__ import annotations

import pickle
from collections import Counter
from pathlib import Path

import pytest
from hostile import short

import washbench.io.budget as budget
import washbench.io.provenance as provenance
from washbench.cueing.params import DEFAULT_PARAMS_PATH
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.provenance import build_provenance
from washbench.perception.vestibular import model_record
from washbench.platform.limits import DEFAULT_LIMITS_PATH, load_platform_limits
from washbench.runs.cue import CueOptions, run_cue
from washbench.runs.omct import signal_command
from washbench.runs.options import load_options
from washbench.runs.outputs import Outputs
from washbench.runs.pipeline import run_manoeuvre
from washbench.runs.rank_rule import load_rank_rule
from washbench.runs.suite import run_suite

LEAN = Outputs(recording=False, figures=False)


@pytest.fixture
def params(tmp_path: Path) -> Path:
    """The bundled parameter file with a ``variants:`` and a ``ranking:`` section (three readers of one file)."""
    path = tmp_path / "params.yaml"
    path.write_text(
        DEFAULT_PARAMS_PATH.read_text()
        + "\nvariants:\n  sa_gain2: {kind: small-angle, tilt.gain_per_s: 2}\n"
        + "ranking:\n  by: weighted\n  dof_weights: {roll: 2, pitch: 1}\n"
    )
    return path


@pytest.fixture
def reads(monkeypatch: pytest.MonkeyPatch) -> Counter[Path]:
    """How often each file is read: to parse it (every YAML file washbench reads goes through read_bounded) or to
    hash it for the provenance (sha256_file)."""
    counts: Counter[Path] = Counter()

    def counted(original):  # type: ignore[no-untyped-def]
        def counting(path, *args, **kwargs):  # type: ignore[no-untyped-def]
            counts[Path(path).resolve()] += 1
            return original(path, *args, **kwargs)

        return counting

    monkeypatch.setattr(budget, "read_bounded", counted(budget.read_bounded))
    monkeypatch.setattr(provenance, "sha256_file", counted(provenance.sha256_file))
    return counts


def test_cue_reads_the_parameter_file_once(params: Path, reads: Counter[Path], tmp_path: Path) -> None:
    signal = tmp_path / "sine.csv"
    signal_command("sine", "roll", 5.0, 0.5, 2.0, 100.0, 0.5, signal)
    reads.clear()
    run = load_options(params_path=params, washouts=["small-angle"], outputs=Outputs(recording=False, figures=False))
    assert run_cue(signal, tmp_path / "cue", CueOptions(progress=False), run) == 0
    assert reads[params.resolve()] == 1  # parsed and hashed from the same bytes
    assert reads[DEFAULT_LIMITS_PATH.resolve()] == 1
    ranking = (tmp_path / "cue" / "ranking.csv").read_text().splitlines()
    assert [r.split(",")[3] for r in ranking[1:]] != [] and all(r.endswith(",weighted") for r in ranking[1:])
    assert {r.split(",")[3] for r in ranking[1:]} == {"small-angle", "sa_gain2"}  # the file's variant ran too


def test_run_and_suite_read_the_parameter_file_once(params: Path, reads: Counter[Path], tmp_path: Path) -> None:
    a, b = short(tmp_path, name="opt_a", seconds=1), short(tmp_path, name="opt_b", seconds=1)
    opts = load_options(params_path=params, washouts=["unrestricted"], outputs=LEAN)
    assert reads[params.resolve()] == 1
    summary = run_manoeuvre(a, tmp_path / "run", opts)
    assert summary.ok and [m.washout for m in summary.metrics[::6]] == ["unrestricted", "sa_gain2"]
    outcomes = run_suite([a, b], tmp_path / "suite", opts, jobs=1, progress=False)  # in this process: countable
    assert [o.run.ok for o in outcomes] == [True, True]
    assert reads[params.resolve()] == 1 and reads[DEFAULT_LIMITS_PATH.resolve()] == 1
    assert reads[a.resolve()] >= 1  # (what is counted: the manoeuvre file is read; the options are read once)


def test_provenance_is_one_build_provenance_of_everything(params: Path, tmp_path: Path) -> None:
    """The run-wide records (built once) merged with a manoeuvre's: equal, key order included, to one call."""
    path = short(tmp_path, name="prov", seconds=1)
    m = load_manoeuvre(path)
    opts = load_options(params_path=params, vestibular="telban-cardullo")
    got = opts.provenance_for(path, m.environment.turbulence, m.aircraft_files)
    whole = build_provenance(
        manoeuvre_path=path, turbulence=m.environment.turbulence, aircraft_files=m.aircraft_files,
        params_path=params, params=opts.params, washouts=opts.washouts, platform_path=DEFAULT_LIMITS_PATH,
        platform=load_platform_limits(), ranking=load_rank_rule(params).record(),
        vestibular=model_record("telban-cardullo"),
    )  # fmt: skip
    assert whole["ranking"]["by"] == "weighted" and whole["ranking"]["dof_weights"]["roll"] == 2.0
    assert list(got) == list(whole) and got == whole
    assert opts.provenance_for() == {k: v for k, v in whole.items() if k not in ("manoeuvre", "aircraft",
                                     "pilot_profile", "turbulence")}  # fmt: skip


def test_the_options_travel_to_a_worker_as_they_are(params: Path) -> None:
    opts = load_options(params_path=params, variants=["la2=large-angle,tilt.gain_per_s=1.5"], outputs=LEAN)
    again = pickle.loads(pickle.dumps(opts))
    assert again == opts and again.washout_order == ("sa_gain2", "la2")  # a variant: no built-in unless named
    with pytest.raises(AttributeError):
        opts.filter_start = "rest"  # type: ignore[misc]  (frozen)


def test_a_default_set_cut_for_the_platform_says_so(capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 52, item 8: on a hexapod (or a rig) the default set leaves out the unrestricted washout, which cannot
    drive it; one line says which and why. Named washouts are not cut (a refused one stops the command), and the
    Atlas's default set is whole: no line."""
    from washbench.cueing.variants import DEFAULT_WASHOUTS
    from washbench.io.paths import DATA_DIR

    for name in ("hexapod", "rig2dof"):
        opts = load_options(platform_path=DATA_DIR / f"{name}.yaml")
        kind = opts.limits.kind
        assert opts.washout_order == tuple(w for w in DEFAULT_WASHOUTS if w != "unrestricted")
        assert capsys.readouterr().err == (
            f"washbench: note: the default washouts run without unrestricted on this {kind}: unrestricted cannot "
            f"drive a {kind}, whose rotation is limited: its attitude set point is never washed back to level "
            "(--washout names the washouts to run)\n")
    load_options(platform_path=DATA_DIR / "hexapod.yaml", washouts=["all"])  # --washout all: the same, said
    assert capsys.readouterr().err.startswith("washbench: note: all the washouts run without unrestricted, "
                                              "adaptive-unrestricted, mpc-unrestricted on this hexapod: ")  # fmt: skip
    load_options(platform_path=DATA_DIR / "hexapod.yaml", washouts=["small-angle"])
    load_options()
    assert capsys.readouterr().err == ""
