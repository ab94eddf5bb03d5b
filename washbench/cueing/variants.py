"""Washout variants: named washouts of a kind with their own parameters (a parameter set, not code).

A run's washouts are a list of :class:`Washout` (name, kind, complete parameter set). The built-in washouts are
named after their kind and use the parameter file as it is; a variant has its own name and the parameter file
with overrides given as dotted keys of the file::

    --variant sa_gain2=small-angle,tilt.gain_per_s=2,rotational.highpass_wn_radps.yaw=0.3

or, with the same meaning, in the parameter file::

    variants:
      sa_gain2: {kind: small-angle, tilt.gain_per_s: 2}
      la_free:
        kind: large-angle
        tilt: {rate_limit_degps: off}        # nested keys work too

Selection (:func:`select_washouts`): with no variant, the washouts named by ``--washout`` (default: all three
built-in ones); with any variant (command line or file), the ``--washout`` ones followed by the variants.
A variant name is a plain identifier (letters, digits, ``_`` and ``-``): it becomes a column prefix, an entity
path and part of file names. It must not be a built-in washout's name or ``aircraft``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pydantic
from pydantic import BaseModel

from washbench.cueing import registry
from washbench.cueing.params import (
    DEFAULT_PARAMS_PATH,
    WASHOUT_KINDS,
    WASHOUT_NAMES,
    WashoutParams,
    load_base_params,
)
from washbench.errors import WashbenchError, located
from washbench.io.names import identifier_problem
from washbench.io.yamlio import Loc, _problem, line_of, read_yaml, validate_data

RESERVED_NAMES = registry.RESERVED_NAMES


@dataclass(frozen=True)
class Washout:
    """One washout to run: ``name`` (in every output), ``kind`` (one of WASHOUT_KINDS), its complete parameters."""

    name: str
    kind: str
    params: WashoutParams
    source: str | None = None
    """For a plugin loaded from a file: its ``FILE.py:NAME`` (so a worker process can load it too)."""


def tilt_rate_limit_radps(washout: Washout) -> float | None:
    """The tilt-rate limit (rad/s) of a washout whose tilt rate the bench records: a compiled washout (the classical
    and adaptive kinds, ``tilt.rate_limit_degps``) or the ``mpc`` washout (``mpc.tilt_rate_limit_degps``, per axis);
    None when it has none (``off``, ``null``) or is another kind."""
    if washout.kind == "mpc":
        algo = registry.get("mpc")
        section = algo.make_params(washout.params.sections.get("mpc"), f"washout {washout.name}")
        limit = getattr(section, "tilt_rate_limit_degps", None)
        return None if limit is None else math.radians(limit)
    if washout.kind not in WASHOUT_KINDS or washout.params.tilt.rate_limit_degps is None:
        return None
    return math.radians(washout.params.tilt.rate_limit_degps)


@dataclass(frozen=True)
class VariantText:
    """A parsed ``--variant`` (or ``variants:`` entry) before its overrides are applied: dotted key -> value."""

    name: str
    kind: str
    overrides: tuple[tuple[str, Any], ...]


def parse_value(text: str) -> Any:
    """A command-line value: a number if it reads as one, ``off``/``false`` as off, otherwise the text."""
    text = text.strip()
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        pass
    return False if text.lower() in ("off", "false") else text


def check_name(name: str, where: str = "--variant") -> str:
    """A variant name, checked: a plain identifier, not a built-in washout's name, not reserved."""
    problem = identifier_problem(name)
    if problem is not None:
        raise WashbenchError(f"{where}: variant name: {problem}")
    if name in registry.known_kinds() or name in RESERVED_NAMES:
        raise WashbenchError(f"{where}: variant name {name!r} is reserved (a built-in washout or output name)")
    return name


def check_kind(kind: str, where: str = "--variant") -> str:
    """A washout kind, checked."""
    if kind not in registry.known_kinds():
        raise WashbenchError(f"{where}: unknown washout kind {kind!r} (valid: {', '.join(registry.known_kinds())})")
    return kind


def parse_variant(text: str) -> VariantText:
    """Parse ``NAME=KIND[,KEY=VALUE...]`` (one ``--variant``); keys are checked against the parameter model.

    Raises WashbenchError (one line naming the variant and the key) for a bad name, kind or key.
    """
    head, _, rest = text.partition(",")
    name, eq, kind = head.partition("=")
    where = f"--variant {text}"
    if not eq:
        raise WashbenchError(f"{where}: expected NAME=KIND[,KEY=VALUE...]")
    name, kind = check_name(name.strip(), where), check_kind(kind.strip(), where)
    overrides: dict[str, Any] = {}
    for item in (p for p in rest.split(",") if p.strip()) if rest else ():
        key, eq, value = item.partition("=")
        key = key.strip()
        if not eq:
            raise WashbenchError(f"{where}: {key}: expected KEY=VALUE")
        check_key(key, where)
        if key in overrides:
            raise WashbenchError(f"{where}: {key}: given twice")
        overrides[key] = parse_value(value)
    return VariantText(name=name, kind=kind, overrides=tuple(overrides.items()))


def check_key(key: str, where: str, model: type[BaseModel] = WashoutParams) -> tuple[str, ...]:
    """The parts of a dotted key that names one value of the parameter model; WashbenchError otherwise."""
    import difflib

    parts = tuple(key.split("."))
    if model is WashoutParams and parts[0] in registry.python_kinds():  # a Python algorithm's own section
        sub_model = registry.get(parts[0]).params_model
        if sub_model is None:
            raise WashbenchError(f"{where}: {key}: washout {parts[0]!r} takes no parameters")
        if len(parts) == 1:
            raise WashbenchError(f"{where}: {key}: is a group; set its values one by one")
        return (parts[0], *check_key(".".join(parts[1:]), f"{where}: {parts[0]}", sub_model))
    current: type[BaseModel] = model
    for i, part in enumerate(parts):
        fields = current.model_fields
        if part not in fields:
            prefix = ".".join(parts[:i])
            options = [f"{prefix}.{f}" if prefix else f for f in fields]
            hint = difflib.get_close_matches(key, options, n=1)
            extra = f" (did you mean '{hint[0]}'?)" if hint else f" (valid here: {', '.join(options)})"
            raise WashbenchError(f"{where}: {key}: unknown parameter{extra}")
        annotation = fields[part].annotation
        sub = annotation if isinstance(annotation, type) and issubclass(annotation, BaseModel) else None
        if i == len(parts) - 1:
            if sub is not None:
                leaves = ", ".join(f"{key}.{f}" for f in sub.model_fields)
                raise WashbenchError(f"{where}: {key}: is a group; set its values one by one ({leaves})")
            return parts
        if sub is None:
            raise WashbenchError(f"{where}: {key}: {'.'.join(parts[: i + 1])} has no sub-keys")
        current = sub
    return parts


def apply_overrides(
    params: WashoutParams,
    overrides: Mapping[str, Any] | Sequence[tuple[str, Any]],
    where: str,
    lines: Mapping[str, int | None] | None = None,
    field_prefix: str = "",
) -> WashoutParams:
    """``params`` with dotted-key overrides applied and validated (same rules as the parameter file).

    ``where`` names the source in errors (a file, or ``--variant ...``); ``lines`` optionally maps a key to the
    line it was written on, and ``field_prefix`` is put before the key in errors (``variants.NAME.``). Raises
    WashbenchError: ``WHERE[:LINE]: KEY: problem``.
    """
    items = list(overrides.items()) if isinstance(overrides, Mapping) else list(overrides)
    if not items:
        return params
    data = params.model_dump(mode="json")
    for key, value in items:
        parts = check_key(key, where)
        node = data
        if parts[0] in registry.python_kinds():  # into the algorithm's section (validated when the washout is made)
            node = data["sections"].setdefault(parts[0], {})
            parts = parts[1:]
        for part in parts[:-1]:
            node = node.setdefault(part, {}) if isinstance(node, dict) else node[part]
        node[parts[-1]] = value
    try:
        return WashoutParams.model_validate_json(json.dumps(data, allow_nan=True))
    except pydantic.ValidationError as exc:
        err = exc.errors(include_url=False)[0]
        loc = tuple(str(p) for p in err["loc"] if isinstance(p, str))
        key = next((k for k, _ in items if tuple(k.split(".")) == loc[: len(k.split("."))]), ".".join(loc))
        line = (lines or {}).get(key)
        problem = _problem(err, WashoutParams, loc)
        raise WashbenchError(located(where, problem, line=line, field=field_prefix + key)) from None


def value_of(params: WashoutParams, key: str) -> Any:
    """The value of a dotted key in a parameter set (a Python algorithm's key: from its validated section)."""
    parts = key.split(".")
    node: Any = params
    if parts[0] in registry.python_kinds():
        node = registry.get(parts[0]).make_params(params.sections.get(parts[0]), "parameters")
        parts = parts[1:]
    for part in parts:
        node = node[part] if isinstance(node, dict) else getattr(node, part)
    return node


def resolve(variant: VariantText, base: WashoutParams, where: str | None = None) -> Washout:
    """The variant as a :class:`Washout`: ``base`` with its overrides applied."""
    src = where or f"--variant {variant.name}"
    params = apply_overrides(base, variant.overrides, src)
    return Washout(variant.name, variant.kind, params, registry.plugin_spec(variant.kind))


def _flatten(value: Any, prefix: str, loc: Loc, out: dict[str, tuple[Any, Loc]]) -> None:
    if isinstance(value, dict):
        for k, v in value.items():
            _flatten(v, f"{prefix}.{k}" if prefix else str(k), (*loc, k), out)
    else:
        out[prefix] = (value, loc)


def _file_variants(path: Path, data: Any, lines: dict[Loc, int], base: WashoutParams) -> tuple[Washout, ...]:
    """The ``variants:`` section of a parameter file as Washouts (errors name file, line and field)."""
    if not isinstance(data, dict):
        raise WashbenchError(
            located(
                path,
                "expected a mapping of variant name -> {kind, keys}",
                line=line_of(lines, ("variants",)),
                field="variants",
            )
        )
    out = []
    for name, body in data.items():
        loc: Loc = ("variants", name)
        field = f"variants.{name}"
        check_name(str(name), located(path, field, line=line_of(lines, loc)))
        if not isinstance(body, dict) or "kind" not in body:
            raise WashbenchError(
                located(
                    path, "expected a mapping with 'kind' and parameter keys", line=line_of(lines, loc), field=field
                )
            )
        kind = check_kind(str(body["kind"]), located(path, f"{field}.kind", line=line_of(lines, (*loc, "kind"))))
        flat: dict[str, tuple[Any, Loc]] = {}
        _flatten({k: v for k, v in body.items() if k != "kind"}, "", loc, flat)
        key_lines = {k: line_of(lines, where) for k, (_, where) in flat.items()}
        for key in flat:
            check_key(key, located(path, field, line=key_lines[key]))
        params = apply_overrides(base, {k: v for k, (v, _) in flat.items()}, str(path), key_lines, f"{field}.")
        out.append(Washout(str(name), kind, params, registry.plugin_spec(kind)))
    return tuple(out)


def load_washout_params(path: Path | None = None) -> WashoutParams:
    """Load a washout parameter YAML file (``None``: the bundled CW1 set, ``washbench/data/cw1.yaml``).

    A ``variants:`` section is checked and left out (:func:`load_param_file` reads it).
    Raises :class:`washbench.errors.WashbenchError` with ``file:line: field: problem`` on bad input.
    """
    return load_param_file(path)[0]


def load_param_file(path: Path | None = None) -> tuple[WashoutParams, tuple[Washout, ...]]:
    """A parameter file's base set and its ``variants:`` section (``None``: the bundled CW1, no variants)."""
    path = DEFAULT_PARAMS_PATH if path is None else Path(path)
    data, lines = read_yaml(path)
    return param_file_from_data(path, data, lines)


_BASE_FIELDS = tuple(k for k, f in WashoutParams.model_fields.items() if f.is_required())
"""The top-level keys a parameter set must have (``name``, ``gravity_mps2``, ``scale``, ``tilt`` ...; ``adaptive``
has its defaults in the model)."""


def defaulted_sections(path: Path, data: Any) -> tuple[str, ...]:
    """The top-level keys of a parameter set that the file ``path`` (parsed: ``data``) leaves out, which are taken
    from the bundled CW1 set (:data:`DEFAULT_PARAMS_PATH`): a file may hold only what it changes, e.g. only a
    plugin's section. ``name`` left out is the file's stem. Empty for the bundled file itself or a non-mapping."""
    if not isinstance(data, dict) or Path(path).resolve() == DEFAULT_PARAMS_PATH.resolve():
        return ()
    return tuple(k for k in _BASE_FIELDS if k not in data)


def _with_defaults(path: Path, data: dict[str, Any]) -> dict[str, Any]:
    missing = defaulted_sections(path, data)
    if not missing:
        return data
    bundled, _ = read_yaml(DEFAULT_PARAMS_PATH)
    filled = {k: (Path(path).stem if k == "name" else bundled[k]) for k in missing}
    return {**filled, **data}


def param_file_from_data(path: Path, data: Any, lines: dict[Loc, int]) -> tuple[WashoutParams, tuple[Washout, ...]]:
    """:func:`load_param_file` of a file already read (``read_yaml``: its data and line map; the top-level mapping
    is not changed). Top-level sections the file leaves out are the bundled CW1 set's (:func:`defaulted_sections`):
    a section given is taken whole, as written."""
    if isinstance(data, dict):
        data = _with_defaults(path, dict(data))
    if not isinstance(data, dict):
        return validate_data(path, data, lines, WashoutParams), ()
    variants = data.pop("variants", None)
    data.pop("ranking", None)  # the ranking rule's section (washbench.runs.rank_rule)
    kinds = registry.python_kinds()
    sections = {k: data.pop(k) for k in list(data) if k in kinds}
    for kind, section in sections.items():  # each validated now, so its errors name the file and line
        if not isinstance(section, dict):
            raise WashbenchError(located(path, "expected a mapping", line=line_of(lines, (kind,)), field=kind))
        registry.get(kind).make_params(section, str(path), lines)
    if sections:
        data = {**data, "sections": {**data.get("sections", {}), **sections}}
    base = load_base_params(path, data, lines)
    return base, (() if variants is None else _file_variants(path, variants, lines, base))


def builtin(names: Sequence[str], params: WashoutParams) -> tuple[Washout, ...]:
    """Built-in washouts and registered algorithms (named after their kind) with one parameter set."""
    return tuple(Washout(n, n, params, registry.plugin_spec(n)) for n in registry.check_washouts(names))


def as_washouts(washouts: Sequence[str | Washout], params: WashoutParams | None) -> tuple[Washout, ...]:
    """Names (built-in washouts, using ``params``) and Washouts as one checked tuple of Washouts."""
    out: list[Washout] = []
    for w in washouts:
        if isinstance(w, Washout):
            out.append(w)
        else:
            if params is None:
                raise ValueError(f"washout {w!r} given by name needs a parameter set")
            out.extend(builtin([w], params))
    if not out:
        raise WashbenchError("no washout selected")
    names = [w.name for w in out]
    if len(set(names)) != len(names):
        raise WashbenchError(f"washout listed twice: {', '.join(names)}")
    return tuple(out)


ALL_WASHOUTS = "all"
"""``--washout all``: every built-in washout, the naive references and the bound (:data:`EVERY_BUILTIN`)."""

EVERY_BUILTIN: tuple[str, ...] = (*WASHOUT_KINDS, "optimal", "mpc", "mpc-unrestricted", *registry.REFERENCE_KINDS,
                                  "bound")  # fmt: skip
"""What ``--washout all`` runs, in order (on a platform one cannot drive, it is left out and said so)."""

DEFAULT_WASHOUTS: tuple[str, ...] = (*WASHOUT_NAMES, *registry.REFERENCE_KINDS)
"""What runs without ``--washout``: the paper's three classical washouts and the naive references (cheap; every
verdict says whether the best washout beats them); the report says what was not compared and that ``--washout all``
compares everything."""


def expand_all(names: Sequence[str]) -> list[str]:
    """``names`` with ``all`` replaced by :data:`EVERY_BUILTIN`."""
    out: list[str] = []
    for n in names:
        out.extend(EVERY_BUILTIN if n == ALL_WASHOUTS else [n])
    return out


def select_washouts(
    washouts: Sequence[str] | None = None,
    variants: Sequence[str] = (),
    params_path: Path | None = None,
) -> tuple[Washout, ...]:
    """The washouts a command runs, from ``--washout`` names, ``--variant`` texts and ``--params FILE``.

    No variant anywhere: the named built-in washouts (default all three). Any variant (command line or the
    file's ``variants:`` section): the named built-in washouts (default none), then the file's variants, then
    the command line's. Raises WashbenchError (one line) for any bad name, kind, key or value.
    """
    return select_from(washouts, variants, *load_param_file(params_path))


def select_from(
    washouts: Sequence[str] | None, variants: Sequence[str], base: WashoutParams, from_file: tuple[Washout, ...]
) -> tuple[Washout, ...]:
    """:func:`select_washouts` with the parameter file already loaded (its base set and ``variants:`` section)."""
    parsed = [parse_variant(v) for v in variants]
    extra = from_file + tuple(resolve(v, base) for v in parsed)
    named = list(dict.fromkeys(expand_all(washouts))) if washouts else ([] if extra else list(DEFAULT_WASHOUTS))
    return as_washouts([*builtin(named, base), *extra] if named else list(extra), None)


def _unfit(washout: Washout, platform: Any) -> tuple[str, str] | None:
    """(why ``washout`` cannot drive ``platform``, what to use instead), or None when it can."""
    kind = getattr(platform, "kind", "atlas")
    if kind == "atlas":
        return None
    plugin = kind not in ("hexapod", "rig")
    if washout.kind in ("mpc", "mpc-unrestricted") and plugin and platform.envelope() is None:
        return (f"plans against the platform's envelope (Atlas-shaped limits), which the {kind} platform plugin does "
                "not give (its class has no envelope(params))"), ""  # fmt: skip
    unlimited = getattr(platform, "unlimited_rotation", False)
    if washout.kind in ("unrestricted", "adaptive-unrestricted", "mpc-unrestricted") and not unlimited:
        why = f"cannot drive a {kind}, whose rotation is limited: its attitude set point is never washed back to level"
        return why, "use large-angle or adaptive-large-angle"
    if washout.kind == "bound" and kind not in ("hexapod", "rig"):
        return (f"its ceiling needs the platform's workspace, which the {kind} platform plugin does not give (the "
                "Atlas, a hexapod and a rig have one)"), ""  # fmt: skip
    return None


def platform_refusal(washout: Washout, platform: Any) -> str | None:
    """Why ``washout`` cannot drive ``platform`` (one line), or None when it can: on a platform of limited rotation
    (hexapod, rig) the unrestricted family (its attitude set point is never washed back to level) cannot; on a
    plugin's platform the oracle bound cannot either (its ceiling needs the platform's workspace, which a plugin
    does not give)."""
    unfit = _unfit(washout, platform)
    if unfit is None:
        return None
    why, instead = unfit
    return f"washout {washout.name} ({washout.kind}): {why}" + (f"; {instead}" if instead else "")


def default_on(
    specs: Sequence[Washout], platform: Any, which: str = "the default"
) -> tuple[tuple[Washout, ...], str | None]:
    """The washouts of a set not named one by one (``which``: "the default", "all the") that can drive ``platform``
    (:func:`platform_refusal`), and the one line that says which were left out and why (None when none was): such
    a set is never cut silently."""
    kept = tuple(w for w in specs if _unfit(w, platform) is None)
    left = [w for w in specs if w not in kept]
    if not left:
        return kept, None
    why = {w.name: _unfit(w, platform)[0] for w in left}  # type: ignore[index]
    reasons = "; ".join(f"{', '.join(n for n in why if why[n] == r)} {r}" for r in dict.fromkeys(why.values()))
    kind = getattr(platform, "kind", "atlas")
    return kept, (f"{which} washouts run without {', '.join(why)} on this {kind}: {reasons} (--washout names "
                  "the washouts to run)")  # fmt: skip


def check_platform(specs: Sequence[Washout], platform: Any) -> None:
    """Raise a one-line WashbenchError for the first washout of ``specs`` that cannot drive ``platform``
    (:func:`platform_refusal`)."""
    for w in specs:
        why = platform_refusal(w, platform)
        if why is not None:
            raise WashbenchError(why)


__all__ = [
    "VariantText",
    "Washout",
    "apply_overrides",
    "as_washouts",
    "builtin",
    "check_key",
    "check_platform",
    "default_on",
    "defaulted_sections",
    "load_param_file",
    "param_file_from_data",
    "parse_value",
    "parse_variant",
    "platform_refusal",
    "resolve",
    "select_from",
    "select_washouts",
    "value_of",
]
