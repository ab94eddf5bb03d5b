"""Where aircraft, pilot profiles and bundled manoeuvres are found (washbench.io.paths), rule by rule.

Each test builds a small project in a temporary folder with real copies of the bundled Columbia 400 model
(renamed, so only the copy can match) and checks which folder the search picks, against the order written in
docs/how-to/own-aircraft.md: --aircraft-dir, WASHBENCH_AIRCRAFT_PATH, aircraft/ next to the manoeuvre (up to the project
root), bundled, JSBSim.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import inprocess
import pytest

from washbench.errors import WashbenchError
from washbench.flight.manoeuvre import load_manoeuvre
from washbench.io.paths import (
    AIRCRAFT_DIR,
    AIRCRAFT_PATH_ENV,
    BUNDLED_PARAMS,
    BUNDLED_PLATFORMS,
    DATA_DIR,
    MANOEUVRES_DIR,
    bundled_file,
    find_aircraft,
    find_profile,
    jsbsim_root,
    resolve_data_file,
    resolve_manoeuvre,
    search_places,
    unknown_manoeuvre,
)
from washbench.io.provenance import bundled_name

BUNDLED_C400 = AIRCRAFT_DIR / "columbia400"


def copy_aircraft(dest_root: Path, name: str, with_profile: bool = True) -> Path:
    """A renamed copy of the bundled Columbia 400 model as ``dest_root/name/name.xml``; returns its folder."""
    folder = dest_root / name
    shutil.copytree(BUNDLED_C400, folder)
    (folder / "columbia400.xml").rename(folder / f"{name}.xml")
    if not with_profile:
        (folder / "pilot.yaml").unlink()
    return folder


def write_manoeuvre(path: Path, aircraft: str, extra: str = "") -> Path:
    text = (MANOEUVRES_DIR / "columbia400" / "stall_recovery.yaml").read_text()
    text = text.replace("aircraft: columbia400", f"aircraft: {aircraft}").replace(
        "name: stall_recovery", "name: my_stall"
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text + extra)
    return path


@pytest.fixture
def no_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(AIRCRAFT_PATH_ENV, raising=False)


def test_bundled_aircraft_then_jsbsims_own(no_env: None) -> None:
    assert find_aircraft("columbia400") == AIRCRAFT_DIR
    # the bundled c172p folder holds only a pilot profile: the model is JSBSim's
    assert find_aircraft("c172p") == jsbsim_root() / "aircraft"
    assert find_profile("c172p") == AIRCRAFT_DIR / "c172p" / "pilot.yaml"


def test_order_aircraft_dir_then_env_then_next_to_manoeuvre(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    proj = tmp_path / "proj"
    (proj / ".git").mkdir(parents=True)
    m = write_manoeuvre(proj / "manoeuvres" / "m.yaml", "myplane")
    for where in ("cli", "env", "proj/aircraft"):
        copy_aircraft(tmp_path / where if where != "proj/aircraft" else proj / "aircraft", "myplane")
    monkeypatch.setenv(AIRCRAFT_PATH_ENV, os.pathsep.join([str(tmp_path / "nowhere"), str(tmp_path / "env")]))
    assert find_aircraft("myplane", m, [tmp_path / "cli"]) == tmp_path / "cli"
    assert find_aircraft("myplane", m) == tmp_path / "env"
    monkeypatch.delenv(AIRCRAFT_PATH_ENV)
    assert find_aircraft("myplane", m) == proj / "aircraft"
    # the profile follows the same order
    assert find_profile("myplane", m, [tmp_path / "cli"]) == tmp_path / "cli" / "myplane" / "pilot.yaml"
    assert find_profile("myplane", m) == proj / "aircraft" / "myplane" / "pilot.yaml"


def test_user_copy_under_the_bundled_name_wins_over_the_bundled_model(tmp_path: Path, no_env: None) -> None:
    m = write_manoeuvre(tmp_path / "p" / "m.yaml", "columbia400")
    copy_aircraft(tmp_path / "p" / "aircraft", "columbia400")
    assert find_aircraft("columbia400", m) == tmp_path / "p" / "aircraft"
    assert find_aircraft("columbia400") == AIRCRAFT_DIR


def test_parents_are_searched_up_to_the_project_root_only(tmp_path: Path, no_env: None) -> None:
    outside = tmp_path / "outside"
    copy_aircraft(outside / "aircraft", "myplane")
    proj = outside / "proj"
    (proj / "pyproject.toml").parent.mkdir(parents=True)
    (proj / "pyproject.toml").write_text("")
    m = write_manoeuvre(proj / "a" / "b" / "m.yaml", "myplane")
    with pytest.raises(WashbenchError) as info:
        find_aircraft("myplane", m)
    assert str(outside / "aircraft") not in str(info.value)  # beyond the project root: not searched
    for folder in (proj / "a" / "b", proj / "a", proj):
        assert str(folder / "aircraft") in str(info.value)
    copy_aircraft(proj / "a" / "aircraft", "myplane")
    assert find_aircraft("myplane", m) == proj / "a" / "aircraft"


def test_pilot_profile_key_is_relative_to_the_manoeuvre_and_comes_first(tmp_path: Path, no_env: None) -> None:
    copy_aircraft(tmp_path / "aircraft", "myplane")
    (tmp_path / "profiles").mkdir()
    shutil.copy(BUNDLED_C400 / "pilot.yaml", tmp_path / "profiles" / "mine.yaml")
    m_path = write_manoeuvre(tmp_path / "m" / "m.yaml", "myplane", "pilot_profile: ../profiles/mine.yaml\n")
    m = load_manoeuvre(m_path)
    assert m.aircraft_files.root == tmp_path / "aircraft"
    assert m.aircraft_files.profile.resolve() == (tmp_path / "profiles" / "mine.yaml").resolve()


def test_missing_profile_and_unknown_aircraft_list_every_searched_place(tmp_path: Path, no_env: None) -> None:
    copy_aircraft(tmp_path / "aircraft", "myplane", with_profile=False)
    m_path = write_manoeuvre(tmp_path / "m.yaml", "myplane")
    with pytest.raises(WashbenchError) as info:
        load_manoeuvre(m_path, [tmp_path / "extra"])
    msg = str(info.value)
    assert re.match(rf"{re.escape(str(m_path))}:\d+: aircraft: no scripted-pilot profile for .myplane.", msg)
    for place in search_places(m_path, [tmp_path / "extra"]):
        assert str(place.folder) in msg
    assert "--aircraft-dir" in msg and "bundled" in msg and "JSBSim" in msg and "\n" not in msg
    bad = write_manoeuvre(tmp_path / "b.yaml", "myplane", "pilot_profile: nope.yaml\n")
    with pytest.raises(WashbenchError, match=r"b\.yaml:\d+: pilot_profile: no such file .*nope\.yaml"):
        load_manoeuvre(bad)
    unknown = write_manoeuvre(tmp_path / "u.yaml", "nosuchplane")
    with pytest.raises(WashbenchError) as info:
        load_manoeuvre(unknown)
    assert "unknown aircraft 'nosuchplane': no nosuchplane/nosuchplane.xml" in str(info.value)
    assert str(jsbsim_root() / "aircraft") in str(info.value) and str(AIRCRAFT_DIR) in str(info.value)


def test_bundled_manoeuvres_by_name(tmp_path: Path) -> None:
    assert resolve_manoeuvre(Path("c172/takeoff")) == MANOEUVRES_DIR / "c172" / "takeoff.yaml"
    assert resolve_manoeuvre(Path("columbia400")) == MANOEUVRES_DIR / "columbia400"
    mine = tmp_path / "c172" / "takeoff.yaml"  # an existing path always wins, relative ones too
    assert resolve_manoeuvre(mine) == mine
    assert resolve_manoeuvre(Path("no/such")) == Path("no/such")


def test_jsbsim_scripts_and_provenance_names_name_manoeuvres(tmp_path: Path) -> None:
    """Issue 52, items 5 and 9: ``run c172_cruise_8K.xml`` (its ``--help`` example), ``c1723`` and the provenance's
    spellings name the same files from any folder; a misspelt name gets the closest ones."""
    script = jsbsim_root() / "scripts" / "c1723.xml"
    for name in ("c1723", "c1723.xml", "jsbsim:scripts/c1723.xml"):
        assert resolve_manoeuvre(Path(name)) == script
    assert resolve_manoeuvre(Path("washbench:manoeuvres/c172/takeoff.yaml")) == MANOEUVRES_DIR / "c172" / "takeoff.yaml"
    assert "did you mean c172/steep_turn?" in str(unknown_manoeuvre(Path("c172/steep_trun")))
    assert "did you mean c172_cruise_8K?" in str(unknown_manoeuvre(Path("c172_cruise_8k.xml")))


def test_bundled_data_files_by_name(tmp_path: Path) -> None:
    """Issue 52, item 5: ``--platform hexapod``, ``hexapod.yaml`` or the provenance's ``washbench:data/hexapod.yaml``
    name the bundled file from any folder (an existing file of the user's wins); every bundled YAML file has a name,
    and every file the provenance names as bundled resolves back to itself."""
    assert sorted(p.stem for p in DATA_DIR.glob("*.yaml")) == sorted((*BUNDLED_PLATFORMS, *BUNDLED_PARAMS))
    for name in BUNDLED_PLATFORMS:
        for spelt in (name, f"{name}.yaml", f"washbench:data/{name}.yaml"):
            assert resolve_data_file(Path(spelt), "--platform") == DATA_DIR / f"{name}.yaml"
    assert resolve_data_file(Path("cw1"), "--params") == DATA_DIR / "cw1.yaml"
    mine = tmp_path / "hexapod.yaml"
    mine.write_text("kind: hexapod\n")
    assert resolve_data_file(mine, "--platform") == mine
    bundled = [*DATA_DIR.glob("*.yaml"), *MANOEUVRES_DIR.glob("*/*.yaml"), *AIRCRAFT_DIR.glob("*/pilot.yaml"),
               jsbsim_root() / "scripts" / "c1723.xml"]  # fmt: skip
    for path in bundled:
        named = bundled_name(path)
        assert named is not None and bundled_file(named[1]) == path, path
    with pytest.raises(WashbenchError, match=r"washbench/data/hexapod\.yaml: no such file.*did you mean --platform "
                       r"hexapod\?"):  # fmt: skip
        resolve_data_file(tmp_path / "washbench/data/hexapod.yaml", "--platform")  # (the checkout's: elsewhere)
    with pytest.raises(WashbenchError, match=r"load a plugin with --platform-plugin mywork/box\.py:CLASS"):
        resolve_data_file(Path("mywork/box.py"), "--platform")
    with pytest.raises(WashbenchError, match=r"--params cw2: no such file, nor a bundled name \(cw1"):
        resolve_data_file(Path("cw2"), "--params")


def test_bundled_platforms_by_name_from_an_empty_folder(tmp_path: Path) -> None:
    """Issue 52, item 5: the bundled hexapod and rig named from a folder that is not a checkout, recorded by the same
    name (``washbench:data/...``) in the provenance; ``washbench examples`` copies every platform file."""
    out = _cli("run", "c172/elevator_doublet", "--out", "r", "--platform", "hexapod", "--no-recording",
               "--no-figures", "--quiet", cwd=tmp_path)  # fmt: skip
    assert out.returncode == 0, out.stderr
    run = json.loads((tmp_path / "r" / "c172p" / "elevator_doublet" / "run.json").read_text())
    assert run["provenance"]["platform"]["path"] == "washbench:data/hexapod.yaml"
    rows = ["t_s,f_x_mps2,f_y_mps2,f_z_mps2,omega_x_degps,omega_y_degps,omega_z_degps"]
    rows += [f"{k / 100},{0.5 * (k > 50)},0,-9.80665,{2.0 * (k > 100)},0,0" for k in range(300)]
    (tmp_path / "step.csv").write_text("\n".join(rows) + "\n")
    out = _cli("cue", "step.csv", "--out", "c", "--platform", "washbench:data/rig2dof.yaml", "--params", "cw1",
               "--no-recording", "--no-figures", "--quiet", cwd=tmp_path)  # fmt: skip
    assert out.returncode == 0, out.stderr
    provenance = json.loads((tmp_path / "c" / "run.json").read_text())["provenance"]
    assert provenance["platform"]["path"] == "washbench:data/rig2dof.yaml"
    assert provenance["params"]["path"] == "washbench:data/cw1.yaml"
    out = _cli("run", "c172/elevator_doublet", "--out", "r", "--platform", "washbench/data/hexapod.yaml", cwd=tmp_path)
    assert out.returncode == 2 and "did you mean --platform hexapod?" in out.stderr


def _cli(*args: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return inprocess.washbench(*args, cwd=cwd, timeout=300, env={**os.environ, **(env or {})})


def test_a_renamed_copy_in_the_users_folder_flies_from_the_cli(tmp_path: Path, no_env: None) -> None:
    """``washbench fly --aircraft-dir`` on a user's copy of the Columbia under another name: a real flight."""
    copy_aircraft(tmp_path / "my_models", "mycolumbia")
    m = write_manoeuvre(tmp_path / "work" / "m.yaml", "mycolumbia")
    out = _cli("validate", str(m), cwd=tmp_path)
    assert out.returncode == 2 and "unknown aircraft 'mycolumbia'" in out.stderr
    out = _cli("fly", str(m), "--out", "out", "--aircraft-dir", str(tmp_path / "my_models"), "--quiet", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    flight = json.loads((tmp_path / "out" / "flight.json").read_text())
    assert flight["aircraft"] == "mycolumbia" and flight["status"] == "ok"
    out = _cli("validate", str(m), cwd=tmp_path, env={AIRCRAFT_PATH_ENV: str(tmp_path / "my_models")})
    assert out.returncode == 0, out.stderr


def test_examples_copies_a_runnable_project_and_never_overwrites(tmp_path: Path, no_env: None) -> None:
    out = _cli("examples", "ex", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    copied = sorted(
        p.relative_to(tmp_path / "ex" / "manoeuvres") for p in (tmp_path / "ex").rglob("manoeuvres/*/*.yaml")
    )
    assert copied == sorted(p.relative_to(MANOEUVRES_DIR) for p in MANOEUVRES_DIR.glob("*/*.yaml"))
    profile = tmp_path / "ex" / "aircraft" / "c172p" / "pilot.yaml"
    assert profile.read_text() == (AIRCRAFT_DIR / "c172p" / "pilot.yaml").read_text()
    for name in ("cw1", *BUNDLED_PLATFORMS):  # the parameter file and every platform file (issue 52, item 5)
        assert (tmp_path / "ex" / "params" / f"{name}.yaml").read_bytes() == (DATA_DIR / f"{name}.yaml").read_bytes()
    m = load_manoeuvre(tmp_path / "ex" / "manoeuvres" / "c172" / "takeoff.yaml")
    assert m.aircraft_files.profile == profile  # the copy's own profile is the one flown
    profile.write_text("edited\n")
    again = _cli("examples", "ex", cwd=tmp_path)
    assert again.returncode == 2 and "already exists" in again.stderr and "Traceback" not in again.stderr
    assert profile.read_text() == "edited\n"


def test_version_names_washbench_jsbsim_and_rerun(tmp_path: Path) -> None:
    from importlib.metadata import version

    import washbench

    out = _cli("--version", cwd=tmp_path)
    assert out.returncode == 0
    assert out.stdout.startswith(
        f"washbench {washbench.__version__} (JSBSim {version('jsbsim')}, rerun-sdk {version('rerun-sdk')},"
    )
