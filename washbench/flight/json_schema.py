"""``washbench schema``: the JSON Schema of manoeuvre files, for editors (completion and checking)."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from washbench.flight.manoeuvre import Manoeuvre
from washbench.io.atomic import write_text_atomic
from washbench.io.publish import prepare_output_file


def manoeuvre_json_schema() -> dict[str, Any]:
    """The JSON Schema of manoeuvre files (for editors: completion and checking)."""
    schema = _plain_descriptions(Manoeuvre.model_json_schema())
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "washbench manoeuvre"
    return schema


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
