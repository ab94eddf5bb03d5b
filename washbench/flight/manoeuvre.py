"""A manoeuvre as washbench flies it: the file's fields (:mod:`washbench.flight.manoeuvre_schema`) checked in full
(:mod:`washbench.flight.manoeuvre_checks`), read from a file with one-line errors; where its aircraft is found.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from pydantic import PrivateAttr, ValidationInfo, model_validator

from washbench.errors import WashbenchError, located
from washbench.flight.manoeuvre_checks import Where, check_semantics
from washbench.flight.manoeuvre_schema import ManoeuvreFields
from washbench.io.paths import AircraftFiles, find_aircraft, find_aircraft_files, find_profile
from washbench.io.yamlio import Loc, format_field_path, line_of, read_yaml, validate_data


class Manoeuvre(ManoeuvreFields):
    """One manoeuvre file, checked in full however it is built.

    The name and the aircraft become result folders (OUT/aircraft/name/), so both are plain identifiers:
    letters, digits, '_' and '-'. After the schema the semantic checks run (a known aircraft with a pilot
    profile, one start, phases that can end, at most an hour of flight): from Python a ValidationError lists
    every problem, from a file every problem is one line naming the file, the line and the field.
    """

    _files: AircraftFiles | None = PrivateAttr(default=None)
    _source: Path | None = PrivateAttr(default=None)
    _lines: dict[Loc, int] = PrivateAttr(default_factory=dict)

    @property
    def dt_s(self) -> float:
        """The flight dynamics time step, s."""
        return 1.0 / self.rate_hz

    @property
    def source(self) -> Path | None:
        """The file this manoeuvre was loaded from (None when built in Python)."""
        return self._source

    def located(self, loc: Loc, problem: str) -> str:
        """``FILE:LINE: FIELD: PROBLEM`` for a problem found later (e.g. in flight) with a field of this manoeuvre."""
        field = format_field_path(loc)
        if self._source is None:
            return f"manoeuvre '{self.name}': {field}: {problem}"
        return located(self._source, problem, line=line_of(self._lines, loc), field=field)

    @model_validator(mode="after")
    def _semantic_checks(self, info: ValidationInfo) -> Manoeuvre:
        context = info.context if isinstance(info.context, dict) else {}
        source = context.get("source")
        where = Where(Path(source) if source is not None else None, context.get("lines", {}))
        files = check_semantics(self, where, context.get("aircraft_dirs", ()))
        if where.problems:
            if source is not None:  # from a file: one located line per problem (WashbenchError passes through)
                raise WashbenchError(where.problems[0], where.problems[1:])
            raise ValueError("; ".join(where.problems))
        self._files = files
        if source is not None:
            self._source = Path(source)
            self._lines = context.get("lines", {})
        return self

    @property
    def aircraft_files(self) -> AircraftFiles:
        """Where the aircraft model and the pilot profile are (found when the file was loaded).

        For a manoeuvre built in Python, searched now without a manoeuvre file or ``--aircraft-dir``.
        """
        if self._files is None:
            self._files = find_aircraft_files(self.aircraft, self._source, (), self.pilot_profile)
        return self._files


def load_manoeuvre(path: str | Path, aircraft_dirs: Sequence[Path] = ()) -> Manoeuvre:
    """Read, validate and semantically check a manoeuvre file.

    The aircraft and its pilot profile are found along the search path of :mod:`washbench.io.paths`
    (``aircraft_dirs`` are the ``--aircraft-dir`` folders) and kept in :attr:`Manoeuvre.aircraft_files`.
    Raises WashbenchError holding every problem of the file (``problems``: one located line each).
    """
    path = Path(path)
    data, lines = read_yaml(path)
    context = {"source": path, "lines": lines, "aircraft_dirs": tuple(aircraft_dirs)}
    return validate_data(path, data, lines, Manoeuvre, context=context)


def aircraft_path(name: str, manoeuvre_file: Path | None = None, aircraft_dirs: Sequence[Path] = ()) -> Path | None:
    """The folder holding ``<name>/<name>.xml`` along the search path (washbench.io.paths), or None."""
    try:
        return find_aircraft(name, manoeuvre_file, aircraft_dirs)
    except WashbenchError:
        return None


def pilot_profile_path(aircraft: str, manoeuvre_file: Path | None = None, aircraft_dirs: Sequence[Path] = ()) -> Path:
    """The scripted pilot's profile for ``aircraft`` along the search path (WashbenchError if there is none)."""
    return find_profile(aircraft, manoeuvre_file, aircraft_dirs)
