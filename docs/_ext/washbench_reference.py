"""Reference sections generated from the code at build time (so the pages cannot drift from it).

Directives, usable in any MyST page as ```{washbench-commands}``` etc.:

- ``washbench-commands``: every command and option of ``washbench.cli.build_parser()`` (help, usage, each
  argument with its default, and the examples of each command's epilog).
- ``washbench-schema``: the manoeuvre file's JSON Schema (``washbench schema``), one table per object.
- ``washbench-model DOTTED.PATH``: a pydantic model's JSON Schema in the same tables (parameter, platform files).
- ``washbench-columns``: the columns of ``flight.parquet`` (``washbench.flight.columns.FLIGHT_COLUMNS``).

Each builds reStructuredText and parses it in place, so headings, tables and literal blocks are Sphinx's own.
"""

from __future__ import annotations

import argparse
import importlib
import json
from typing import Any

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles


def _lit(text: object) -> str:
    """An inline literal that survives any content (backquotes escaped by splitting)."""
    s = str(text).replace("`", "'")
    return f"``{s}``" if s else ""


def _cell(text: object) -> str:
    """One grid-table-free cell: a list-table item on one line."""
    return " ".join(str(text).split())


def _list_table(header: list[str], rows: list[list[str]], widths: list[int] | None = None) -> list[str]:
    out = [".. list-table::", "   :header-rows: 1"]
    if widths:
        out.append(f"   :widths: {' '.join(str(w) for w in widths)}")
    out.append("")
    for row in [header, *rows]:
        first = True
        for cell in row:
            out.append(f"   {'* -' if first else '  -'} {_cell(cell) or ' '}")
            first = False
    out.append("")
    return out


class _RstDirective(SphinxDirective):
    """A directive that renders generated reStructuredText."""

    def rst_lines(self) -> list[str]:  # pragma: no cover - overridden
        raise NotImplementedError

    def run(self) -> list[nodes.Node]:
        node = nodes.section()
        node.document = self.state.document
        content = StringList(self.rst_lines(), source=f"<{self.name}>")
        nested_parse_with_titles(self.state, content, node)
        return node.children


# ---- commands -------------------------------------------------------------------------------------------------


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _argument_rows(parser: argparse.ArgumentParser) -> list[list[str]]:
    rows = []
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction | argparse._SubParsersAction):
            continue
        if action.option_strings:
            metavar = action.metavar or (action.dest.upper() if action.nargs != 0 else "")
            if isinstance(metavar, tuple):
                metavar = " ".join(metavar)
            if action.choices and not action.metavar:
                metavar = "{" + ",".join(map(str, action.choices)) + "}"
            name = ", ".join(action.option_strings) + (f" {metavar}" if metavar else "")
        else:
            name = action.metavar or action.dest
            if action.nargs in ("+", "*"):
                name += " ..."
        notes = []
        if getattr(action, "required", False) and action.option_strings:
            notes.append("required")
        if isinstance(action, argparse._AppendAction):
            notes.append("repeatable")
        default = action.default
        if default not in (None, False, [], argparse.SUPPRESS) and not isinstance(action, argparse._VersionAction):
            notes.append(f"default {_lit(default)}")
        help_text = (action.help or "").replace("%(default)s", str(default)).replace("%%", "%")
        if isinstance(action, argparse._VersionAction):
            help_text = "print the versions of washbench, JSBSim, rerun-sdk, numpy and Python, then exit"
        rows.append([_lit(name), _escape(help_text), "; ".join(notes)])
    return rows


def _escape(text: str) -> str:
    """Plain help text as reStructuredText: inline markup characters kept literal."""
    out = text.replace("\\", "\\\\")
    for ch in ("*", "`", "|", "_"):
        out = out.replace(ch, "\\" + ch)
    return out


class CommandsDirective(_RstDirective):
    """Every command and option of the ``washbench`` parser."""

    has_content = False

    def rst_lines(self) -> list[str]:
        from washbench.cli import build_parser

        parser = build_parser()
        lines = ["Top level", "---------", "", "::", ""]
        lines += ["   " + ln for ln in parser.format_usage().strip().splitlines()]
        lines += [""]
        lines += _list_table(["option", "what it does", "notes"], _argument_rows(parser), [30, 55, 15])
        for name, sub in _subparsers(parser).items():
            lines += [f"washbench {name}", "-" * (len(name) + 10), ""]
            if sub.description:
                lines += [_escape(sub.description), ""]
            lines += ["::", ""]
            usage = sub.format_usage().strip().removeprefix("usage: ")
            lines += ["   " + ln for ln in usage.splitlines()]
            lines += [""]
            lines += _list_table(["argument", "what it does", "notes"], _argument_rows(sub), [30, 55, 15])
            if sub.epilog:
                lines += ["Examples::", ""]
                examples = [ln.strip() for ln in sub.epilog.splitlines()]
                lines += ["   " + ln for ln in examples if ln and ln != "examples:"]
                lines += [""]
        return lines


# ---- JSON Schema ------------------------------------------------------------------------------------------------


def _type_of(prop: dict[str, Any]) -> str:
    if "$ref" in prop:
        name = prop["$ref"].rsplit("/", 1)[-1]
        return f":ref:`{name} <schema-{_anchor(name)}>`"
    if "anyOf" in prop:
        parts = [_type_of(p) for p in prop["anyOf"] if p.get("type") != "null"]
        return " or ".join(parts) + (" or null" if any(p.get("type") == "null" for p in prop["anyOf"]) else "")
    if "enum" in prop:
        return "one of " + ", ".join(_lit(v) for v in prop["enum"])
    if "const" in prop:
        return _lit(prop["const"])
    t = prop.get("type", "any")
    if t == "array":
        if "prefixItems" in prop:
            return "[" + ", ".join(_type_of(p) for p in prop["prefixItems"]) + "]"
        return "list of " + _type_of(prop.get("items", {}))
    if t == "object" and "additionalProperties" in prop and isinstance(prop["additionalProperties"], dict):
        return "mapping to " + _type_of(prop["additionalProperties"])
    return str(t)


def _limits(prop: dict[str, Any]) -> str:
    bits = []
    for key, sym in (("minimum", ">="), ("exclusiveMinimum", ">"), ("maximum", "<="), ("exclusiveMaximum", "<")):
        if key in prop:
            bits.append(f"{sym} {prop[key]:g}" if isinstance(prop[key], float) else f"{sym} {prop[key]}")
    for key, what in (("minLength", "length >="), ("maxLength", "length <="), ("minItems", "items >="),
                      ("maxItems", "items <=")):
        if key in prop:
            bits.append(f"{what} {prop[key]}")
    if "pattern" in prop:
        bits.append("pattern " + _lit(prop["pattern"]))
    for sub in prop.get("anyOf", []):
        inner = _limits(sub)
        if inner:
            bits.append(inner)
    return ", ".join(bits)


def _anchor(name: str) -> str:
    return name.lower().replace("_", "-")


def _object_table(schema: dict[str, Any]) -> list[str]:
    required = set(schema.get("required", []))
    rows = []
    for key, prop in schema.get("properties", {}).items():
        default = ""
        if key in required:
            default = "required"
        elif "default" in prop:
            default = _lit(json.dumps(prop["default"]))
        rows.append([_lit(key), _type_of(prop), _limits(prop), default, _escape(prop.get("description", ""))])
    if not rows:
        return ["(no keys)", ""]
    return _list_table(["key", "type", "allowed", "default", "meaning"], rows, [18, 18, 16, 12, 36])


def schema_lines(schema: dict[str, Any], title: str) -> list[str]:
    """Tables for a JSON Schema: the top object, then each definition (linked from the type column)."""
    lines = [f".. _schema-{_anchor(title)}:", "", title, "-" * len(title), ""]
    if schema.get("description"):
        lines += [_escape(schema["description"]), ""]
    lines += _object_table(schema)
    for name, sub in sorted(schema.get("$defs", {}).items()):
        lines += [f".. _schema-{_anchor(name)}:", "", name, "~" * len(name), ""]
        if sub.get("description"):
            lines += [_escape(ln) for ln in sub["description"].splitlines()] + [""]
        if "properties" in sub:
            lines += _object_table(sub)
        else:
            lines += [f"Type: {_type_of(sub)}", ""]
    return lines


class SchemaDirective(_RstDirective):
    """The manoeuvre file format (``washbench schema``)."""

    has_content = False

    def rst_lines(self) -> list[str]:
        from washbench.flight.json_schema import manoeuvre_json_schema

        return schema_lines(manoeuvre_json_schema(), "Manoeuvre")


class ModelDirective(_RstDirective):
    """A pydantic model's keys (``washbench-model washbench.cueing.params.WashoutParams``)."""

    required_arguments = 1
    has_content = False

    def rst_lines(self) -> list[str]:
        module, _, name = self.arguments[0].rpartition(".")
        model = getattr(importlib.import_module(module), name)
        return schema_lines(model.model_json_schema(), name)


class ColumnsDirective(_RstDirective):
    """The columns of ``flight.parquet``."""

    has_content = False

    def rst_lines(self) -> list[str]:
        from washbench.flight.columns import FLIGHT_COLUMNS

        return _list_table(["column", "meaning"], [[_lit(n), _escape(d)] for n, d in FLIGHT_COLUMNS], [25, 75])


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("washbench-commands", CommandsDirective)
    app.add_directive("washbench-schema", SchemaDirective)
    app.add_directive("washbench-model", ModelDirective)
    app.add_directive("washbench-columns", ColumnsDirective)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
