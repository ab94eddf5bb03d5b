"""``washbench schema``: the JSON Schema of manoeuvre files, for editors (completion and checking).

A field's description is the docstring written under it in its model (``name: type`` then a string literal), read
from the source here, when the schema is made: pydantic's ``use_attribute_docstrings`` would read it for every
model class each time washbench is imported (about 0.05 s of every command's start), for this command alone.
"""

from __future__ import annotations

import ast
import inspect
import json
import sys
import textwrap
from pathlib import Path
from typing import Any

from pydantic import BaseModel
from pydantic.json_schema import GenerateJsonSchema, JsonSchemaValue
from pydantic_core import core_schema

from washbench.flight.manoeuvre import Manoeuvre
from washbench.io.atomic import write_text_atomic
from washbench.io.publish import prepare_output_file


def manoeuvre_json_schema() -> dict[str, Any]:
    """The JSON Schema of manoeuvre files (for editors: completion and checking)."""
    schema = _plain_descriptions(Manoeuvre.model_json_schema(schema_generator=_WithAttributeDocstrings))
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "washbench manoeuvre"
    return schema


class _WithAttributeDocstrings(GenerateJsonSchema):
    """Pydantic's JSON Schema, each model's properties described by their attribute docstrings (an explicit
    ``Field(description=...)`` wins)."""

    def model_schema(self, schema: core_schema.ModelSchema) -> JsonSchemaValue:
        json_schema = super().model_schema(schema)
        docs = attribute_docstrings(schema["cls"])
        for name, prop in json_schema.get("properties", {}).items():
            if name in docs and "description" not in prop:
                prop["description"] = docs[name]
        return json_schema


def attribute_docstrings(cls: type) -> dict[str, str]:
    """The docstrings written under a model's annotated attributes, by attribute name (its bases' first, as
    pydantic's ``use_attribute_docstrings`` gives them: cleaned with :func:`inspect.cleandoc`)."""
    docs: dict[str, str] = {}
    for base in reversed(cls.__mro__):
        if issubclass(base, BaseModel) and base is not BaseModel:
            docs.update(_own_attribute_docstrings(base))
    return docs


def _own_attribute_docstrings(cls: type) -> dict[str, str]:
    try:
        source = textwrap.dedent(inspect.getsource(cls))
    except (OSError, TypeError):  # no source (an interactive session)
        return {}
    body = ast.parse(source).body[0]
    if not isinstance(body, ast.ClassDef):
        return {}
    docs: dict[str, str] = {}
    for stmt, after in zip(body.body, body.body[1:], strict=False):
        if (
            isinstance(stmt, ast.AnnAssign)
            and isinstance(stmt.target, ast.Name)
            and isinstance(after, ast.Expr)
            and isinstance(after.value, ast.Constant)
            and isinstance(after.value.value, str)
        ):
            docs[stmt.target.id] = inspect.cleandoc(after.value.value)
    return docs


def _plain_descriptions(node: Any) -> Any:
    """Docstrings as editor hover text: ``code`` as Markdown `code`, lines joined within a paragraph."""
    if isinstance(node, dict):
        out = {k: _plain_descriptions(v) for k, v in node.items()}
        text = node.get("description")
        if isinstance(text, str):
            paragraphs = [" ".join(p.split()) for p in text.replace("``", "`").split("\n\n")]
            out["description"] = "\n\n".join(p for p in paragraphs if p)
        return out
    if isinstance(node, list):
        return [_plain_descriptions(v) for v in node]
    return node


def schema_command(out: Path | None) -> int:
    """``washbench schema [--out FILE]``: print or write the JSON Schema."""
    text = json.dumps(manoeuvre_json_schema(), indent=2, sort_keys=True) + "\n"
    if out is None:
        sys.stdout.write(text)
    else:
        write_text_atomic(prepare_output_file(out), text)
    return 0
