"""YAML files into typed, frozen models, with one-line errors that name file, line and field.

Every YAML file washbench reads (manoeuvres, washout parameters, platform limits) goes
through :func:`load_yaml_model`. Models derive from :class:`StrictModel`: unknown keys
are rejected, numbers must be numbers (``'thirty'`` or ``"30"`` is not a number), and the
instances are frozen. A failure raises :class:`washbench.errors.WashbenchError` with
a message such as::

    manoeuvres/c172/turn.yaml:14: phases[2].hold.bank_deg: expected a number, got 'thirty'

Validation runs in pydantic's strict JSON mode (the YAML data is passed as JSON), so a
YAML list fills a tuple field and a string fills an enum or literal field, but no string
is silently turned into a number.
"""

from __future__ import annotations

import difflib
import json
import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Self, TypeVar

import pydantic
import yaml
from pydantic import BaseModel, ConfigDict

from washbench.errors import WashbenchError, located
from washbench.io import budget
from washbench.io.interrupts import signals_held

M = TypeVar("M", bound=BaseModel)

Loc = tuple[str | int, ...]


class StrictModel(BaseModel):
    """Base for models read from YAML: unknown keys rejected, strict types, no NaN or infinity, frozen.

    No invalid instance can be built from Python either: :meth:`model_copy` with ``update`` validates
    the result like a new instance (pydantic's own skips validation).
    """

    model_config = ConfigDict(
        extra="forbid", strict=True, frozen=True, allow_inf_nan=False, defer_build=True
    )  # built at a model's first use, so a command builds only what it reads; the attribute docstrings are read by
    # ``washbench schema`` alone (washbench.flight.json_schema)

    @classmethod
    def model_rebuild(cls, *args: Any, _parent_namespace_depth: int = 2, **kwargs: Any) -> bool | None:
        """pydantic's, with SIGINT and SIGTERM held back while it builds the model's schema (at the model's first
        use, ``defer_build``; a few milliseconds) and acted on once it is built.

        pydantic-core calls back into Python while it builds a validator or serializer, and a KeyboardInterrupt
        raised in such a call came out of it as a ``SchemaError`` chain: a traceback instead of "washbench:
        interrupted" (a suite signalled as its workers start, beside two busy loops). The namespace pydantic reads
        the annotations in is its caller's, one frame further out than for pydantic's own method.
        """
        with signals_held():
            return super().model_rebuild(*args, _parent_namespace_depth=_parent_namespace_depth + 1, **kwargs)

    def model_copy(self, *, update: Mapping[str, Any] | None = None, deep: bool = False) -> Self:
        """A copy; with ``update``, a new validated instance (raises ``pydantic.ValidationError``)."""
        if not update:
            return super().model_copy(deep=deep)
        unknown = sorted(set(update) - set(type(self).model_fields))
        if unknown:
            raise ValueError(f"{type(self).__name__}.model_copy: unknown field(s) {', '.join(unknown)}")
        values = {name: getattr(self, name) for name in type(self).model_fields if name in self.model_fields_set}
        values.update(update)
        return type(self).model_validate(values)


class _UniqueKeyLoader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # type: ignore[misc]
    """Safe loader (libyaml's fast parser where available) that rejects duplicate mapping keys.

    PyYAML keeps the last of duplicate keys silently; here a duplicate is an error.
    """


class _PyUniqueKeyLoader(yaml.SafeLoader):
    """The pure-Python twin of :class:`_UniqueKeyLoader`: slower, but clearer syntax-error messages."""


MERGE_TAG = "tag:yaml.org,2002:merge"
#: Deepest nesting of mappings and lists accepted (the deepest bundled file uses 5).
MAX_DEPTH = 50
#: Most nodes a document may hold once its aliases are expanded (a "billion laughs" file is refused).
MAX_NODES = 100_000
#: Largest magnitude of an integer (beyond it, no count or seed in these files makes sense).
MAX_INT = 2**63 - 1


def _construct_mapping(loader: yaml.SafeLoader, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
    """A mapping whose own keys are plain (hashable) and unique; merge keys (``<<: *defaults``) are expanded.

    Keys brought in by a merge may be overridden by the mapping's own keys, as YAML specifies.
    """
    seen: dict[Any, int] = {}
    for key_node, _ in node.value:
        if key_node.tag == MERGE_TAG:
            continue
        key = loader.construct_object(key_node, deep=deep)
        try:
            hash(key)
        except TypeError:
            raise yaml.constructor.ConstructorError(
                None, None, "a mapping key must be plain text, not a list or a mapping", key_node.start_mark
            ) from None
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r} (first on line {seen[key] + 1})", key_node.start_mark
            )
        seen[key] = key_node.start_mark.line
    return loader.construct_mapping(node, deep=deep)


def _construct_int(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> int:
    try:
        value = yaml.constructor.SafeConstructor.construct_yaml_int(loader, node)
    except ValueError:  # more digits than Python converts (sys.get_int_max_str_digits)
        value = MAX_INT + 1
    if abs(value) > MAX_INT:
        raise yaml.constructor.ConstructorError(
            None, None, f"the integer {node.value[:20]}... is too large", node.start_mark
        )
    return value


#: Scientific notation as YAML 1.2 (and every other language) writes it: ``1e-3``, ``5E2``, ``-2.5e+4``.
#: PyYAML's YAML 1.1 resolver reads these as text (it wants a dot and a signed exponent).
_FLOAT_EXPONENT = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$")

for _loader in (_UniqueKeyLoader, _PyUniqueKeyLoader):
    _loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)
    _loader.add_constructor("tag:yaml.org,2002:int", _construct_int)
    _loader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT_EXPONENT, list("-+.0123456789"))


class _LimitError(yaml.MarkedYAMLError):
    """A document beyond MAX_DEPTH or MAX_NODES (no need to parse it again for clearer words)."""


def _check_nesting(text: str, loader_class: type) -> None:
    """Refuse nesting deeper than MAX_DEPTH before composing (composing recurses once per level)."""
    depth = 0
    for event in yaml.parse(text, Loader=loader_class):
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > MAX_DEPTH:
                raise _LimitError(
                    problem=f"nested deeper than {MAX_DEPTH} levels", problem_mark=event.start_mark
                )
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _check_expansion(root: yaml.Node) -> None:
    """Refuse a node graph whose alias expansion is recursive, too large (MAX_NODES) or too deep (MAX_DEPTH).

    Each node is visited once (sizes and depths are memoised), so a "billion laughs" document is measured
    in microseconds without being expanded.
    """
    size: dict[int, int] = {}
    depth: dict[int, int] = {}
    entered: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, leaving = stack.pop()
        key = id(node)
        if leaving:
            kids = _children(node)
            size[key] = 1 + sum(size[id(k)] for k in kids)
            depth[key] = 1 + max((depth[id(k)] for k in kids), default=0)
            if size[key] > MAX_NODES:
                raise _LimitError(
                    problem=f"its aliases expand to more than {MAX_NODES} values", problem_mark=node.start_mark
                )
            if depth[key] > MAX_DEPTH:
                raise _LimitError(
                    problem=f"its aliases nest deeper than {MAX_DEPTH} levels", problem_mark=node.start_mark
                )
            continue
        if key in size:
            continue
        if key in entered:
            raise _LimitError(problem="an alias refers to a value that contains it",
                                       problem_mark=node.start_mark)  # fmt: skip
        entered.add(key)
        stack.append((node, True))
        stack.extend((k, False) for k in _children(node) if id(k) not in size)


def _line_map(node: yaml.Node | None, loc: Loc = (), out: dict[Loc, int] | None = None) -> dict[Loc, int]:
    """Map each data path to the 1-based line where it is written (a key's line for mapping values)."""
    if out is None:
        out = {}
    if node is None:
        return out
    out.setdefault(loc, node.start_mark.line + 1)
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            key = key_node.value
            out[(*loc, key)] = key_node.start_mark.line + 1
            _line_map(value_node, (*loc, key), out)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _line_map(item, (*loc, i), out)
    return out


def line_of(lines: dict[Loc, int], loc: Loc) -> int | None:
    """The line of ``loc``, or of its nearest ancestor written in the file (a missing key's parent)."""
    while loc not in lines and loc:
        loc = loc[:-1]
    return lines.get(loc)


def format_field_path(loc: Loc) -> str:
    """``('phases', 2, 'hold', 'bank_deg')`` -> ``phases[2].hold.bank_deg``."""
    text = ""
    for part in loc:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else str(part)
    return text or "(top level)"


def _data_loc(data: Any, loc: tuple[Any, ...]) -> Loc:
    """Keep the parts of a pydantic error location that are real keys or indices in ``data``.

    Pydantic inserts union-member tags and validator names into locations; those are
    dropped. The last part is kept even if absent (a missing or unknown key).
    """
    kept: list[str | int] = []
    node = data
    for i, part in enumerate(loc):
        if isinstance(node, dict) and part in node:
            kept.append(part)
            node = node[part]
        elif isinstance(node, list) and isinstance(part, int) and 0 <= part < len(node):
            kept.append(part)
            node = node[part]
        elif i == len(loc) - 1 and isinstance(part, str | int) and isinstance(node, dict):
            kept.append(part)
    return tuple(kept)


def _describe(value: Any) -> str:
    if isinstance(value, str):
        return repr(value)
    if value is None:
        return "nothing (null)"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return repr(value)


def _problem(err: dict[str, Any], model: type[BaseModel], loc: Loc) -> str:
    """A short human sentence for one pydantic error."""
    kind = err["type"]
    value = err.get("input")
    if kind == "extra_forbidden":
        key = loc[-1] if loc else ""
        allowed = _allowed_keys(model, loc[:-1])
        hint = difflib.get_close_matches(str(key), allowed, n=1)
        text = "unknown key"
        if hint:
            text += f" (did you mean '{hint[0]}'?)"
        elif allowed:
            text += f" (allowed: {', '.join(sorted(allowed))})"
        return text
    if kind == "missing":
        return "missing required field"
    if kind in {"float_type", "float_parsing", "int_type", "int_parsing", "int_from_float", "finite_number"}:
        want = "an integer" if kind.startswith("int") else "a number"
        if kind == "finite_number":
            want = "a finite number"
        return f"expected {want}, got {_describe(value)}"
    if kind in {"bool_type", "bool_parsing"}:
        return f"expected true or false, got {_describe(value)}"
    if kind in {"string_type"}:
        number = isinstance(value, int | float) and not isinstance(value, bool)
        hint = f" (write it in quotes: '{value}')" if number else ""
        return f"expected text, got {_describe(value)}{hint}"
    if kind in {"list_type", "tuple_type"}:
        return f"expected a list, got {_describe(value)}"
    if kind in {"dict_type", "model_type", "model_attributes_type"}:
        return f"expected a mapping, got {_describe(value)}"
    if kind in {"too_short", "too_long"}:
        return err["msg"].replace("Tuple", "list").replace("List", "list")
    msg = str(err["msg"])
    for prefix in ("Value error, ", "Assertion failed, "):
        msg = msg.removeprefix(prefix)
    msg = msg.replace("Input should be", "expected")
    if value is not None and not isinstance(value, dict | list) and "got" not in msg:
        msg += f", got {_describe(value)}"
    return msg


def _allowed_keys(model: type[BaseModel], loc: Loc) -> list[str]:
    """Field names of the (sub)model at ``loc`` if it can be found without ambiguity."""
    current: Any = model
    for part in loc:
        if isinstance(part, int):
            continue
        if not (isinstance(current, type) and issubclass(current, BaseModel)):
            return []
        field = current.model_fields.get(str(part))
        if field is None:
            return []
        current = _unwrap_model(field.annotation)
        if current is None:
            return []
    if isinstance(current, type) and issubclass(current, BaseModel):
        return [f.alias or name for name, f in current.model_fields.items()]
    return []


def _unwrap_model(annotation: Any) -> type[BaseModel] | None:
    """The single BaseModel inside ``annotation`` (through Optional, list, tuple), or None."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    args = getattr(annotation, "__args__", ()) or ()
    found = [m for m in (_unwrap_model(a) for a in args) if m is not None]
    return found[0] if len(found) == 1 else None


def _parse(text: str, loader_class: type) -> tuple[yaml.Node | None, Any]:
    """Compose the node tree (for line numbers) and construct the data from it, in one pass."""
    _check_nesting(text, loader_class)
    loader = loader_class(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None, None
        _check_expansion(node)
        return node, loader.construct_document(node)
    finally:
        loader.dispose()


def read_yaml(path: Path) -> tuple[Any, dict[Loc, int]]:
    """Parse a YAML file; return its data and the line of every data path.

    Raises WashbenchError for an unreadable, empty or malformed file, or duplicate keys.
    """
    data, lines, _ = read_yaml_digest(path)
    return data, lines


def read_yaml_digest(path: Path) -> tuple[Any, dict[Loc, int], str]:
    """:func:`read_yaml` and the SHA-256 (hex) of the bytes parsed: the file read once for its data and its
    provenance record."""
    import hashlib

    raw = budget.read_bounded(path)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise WashbenchError(located(path, f"cannot read: {exc}")) from None
    try:
        try:
            node, data = _parse(text, _UniqueKeyLoader)
        except _LimitError:
            raise
        except yaml.MarkedYAMLError:
            node, data = _parse(text, _PyUniqueKeyLoader)  # same error, clearer words
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        problem = exc.problem or exc.context or "malformed YAML"
        raise WashbenchError(located(path, f"invalid YAML: {problem}", line=line)) from None
    except yaml.YAMLError as exc:
        raise WashbenchError(located(path, f"invalid YAML: {exc}")) from None
    if data is None:
        raise WashbenchError(located(path, "the file is empty"))
    return data, _line_map(node), hashlib.sha256(raw).hexdigest()


def _non_finite(data: Any, loc: Loc = ()) -> list[tuple[Loc, float]]:
    """Every NaN or infinite number in ``data`` with its path (no file may hold one: a phase must end, a limit
    must limit)."""
    found: list[tuple[Loc, float]] = []
    stack: list[tuple[Loc, Any]] = [(loc, data)]
    while stack:
        here, value = stack.pop()
        if isinstance(value, float) and not math.isfinite(value):
            found.append((here, value))
        elif isinstance(value, dict):
            stack.extend(((*here, k), v) for k, v in value.items() if isinstance(k, str | int))
        elif isinstance(value, list):
            stack.extend(((*here, i), v) for i, v in enumerate(value))
    return sorted(found, key=lambda item: format_field_path(item[0]))


def _messages(path: Path, data: Any, lines: dict[Loc, int], model: type[BaseModel],
              errors: list[dict[str, Any]]) -> list[str]:  # fmt: skip
    """One located line per pydantic error, in file order; a misspelt key gives "unknown key", not also "missing"."""
    located_errors: dict[Loc, tuple[int, dict[str, Any]]] = {}
    rank = {"extra_forbidden": 0, "missing": 2}
    for err in errors:
        loc = _data_loc(data, tuple(err["loc"]))
        r = rank.get(err["type"], 1)
        if loc not in located_errors or r < located_errors[loc][0]:
            located_errors[loc] = (r, err)
    unknown_parents = {loc[:-1] for loc, (_, e) in located_errors.items() if e["type"] == "extra_forbidden"}
    out: list[tuple[int, str, str]] = []
    for loc, (_, err) in located_errors.items():
        if err["type"] == "missing" and loc[:-1] in unknown_parents:
            continue
        line = line_of(lines, loc)
        text = located(path, _problem(err, model, loc), line=line, field=format_field_path(loc))
        out.append((line or 0, format_field_path(loc), text))
    return [text for _, _, text in sorted(out)]


def raise_problems(messages: list[str]) -> None:
    """Raise one WashbenchError holding every message (nothing if the list is empty)."""
    if messages:
        raise WashbenchError(messages[0], messages[1:])


def validate_data(path: Path, data: Any, lines: dict[Loc, int], model: type[M], context: Any = None) -> M:
    """Validate parsed YAML ``data`` against ``model``; errors name file, line and field.

    Every problem of the file is collected (:attr:`WashbenchError.problems`), in file order. NaN and
    infinite numbers are refused in every file, whatever the field. ``context`` is passed to the
    model's validators (pydantic's validation context).
    """
    if not isinstance(data, dict):
        raise WashbenchError(located(path, f"expected a mapping at the top level, got {_describe(data)}", line=1))
    bad_numbers = _non_finite(data)
    messages = [
        located(path, f"expected a finite number, got {value!r}", line=line_of(lines, loc),
                field=format_field_path(loc))
        for loc, value in bad_numbers
    ]  # fmt: skip
    try:
        payload = json.dumps(data, default=str, allow_nan=True)
        result = model.model_validate_json(payload, context=context)
    except pydantic.ValidationError as exc:
        bad = {loc for loc, _ in bad_numbers}
        errors = [e for e in exc.errors(include_url=False) if _data_loc(data, tuple(e["loc"])) not in bad]
        raise_problems(sorted(set(messages + _messages(path, data, lines, model, errors)), key=_line_key))
        raise AssertionError("unreachable") from None  # pydantic gave errors only at the non-finite numbers
    raise_problems(messages)
    return result


def _line_key(message: str) -> tuple[int, str]:
    """Sort key for located messages: the line number after the file name (0 when there is none)."""
    match = re.match(r"^.*?:(\d+): ", message)
    return (int(match.group(1)) if match else 0, message)


def load_yaml_model(path: str | Path, model: type[M]) -> M:
    """Read ``path`` and validate it into ``model``, raising a one-line WashbenchError on any problem."""
    path = Path(path)
    data, lines = read_yaml(path)
    return validate_data(path, data, lines, model)
