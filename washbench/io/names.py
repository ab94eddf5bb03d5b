"""Names that become file or folder names: plain identifiers, checked where they are read.

A manoeuvre's ``name`` and ``aircraft`` (and any other name that ends up in a result path: variant or
segment names) are path components of ``OUT/<aircraft>/<name>/``. A name that is not a plain
identifier (``/etc``, ``..``, ``.``, a NUL byte, 300 characters) could escape ``--out`` or replace
other results, so such names are refused when the file is loaded.

An identifier is 1 to :data:`IDENTIFIER_MAX_LENGTH` characters: ASCII letters, digits, ``_`` and ``-``,
starting with a letter or a digit.
"""

from __future__ import annotations

import re
from typing import Annotated

from pydantic import AfterValidator, WithJsonSchema

IDENTIFIER_MAX_LENGTH = 64
IDENTIFIER_PATTERN = rf"^[A-Za-z0-9][A-Za-z0-9_-]{{0,{IDENTIFIER_MAX_LENGTH - 1}}}$"
IDENTIFIER_RULE = (
    f"a plain name: letters, digits, '_' and '-', starting with a letter or digit, "
    f"at most {IDENTIFIER_MAX_LENGTH} characters"
)
_IDENTIFIER = re.compile(IDENTIFIER_PATTERN.removesuffix("$") + r"\Z")


def identifier_problem(value: object) -> str | None:
    """Why ``value`` is not an identifier (one phrase), or None if it is one."""
    if not isinstance(value, str):
        return f"expected {IDENTIFIER_RULE}, got {value!r}"
    if _IDENTIFIER.match(value) is None:
        shown = value if len(value) <= 40 else value[:37] + "..."
        return f"expected {IDENTIFIER_RULE}, got {shown!r}"
    return None


def check_identifier(value: str, what: str = "name") -> str:
    """Return ``value`` if it is an identifier, else raise ValueError naming ``what``."""
    problem = identifier_problem(value)
    if problem is not None:
        raise ValueError(f"{what}: {problem}")
    return value


def _validate(value: str) -> str:
    problem = identifier_problem(value)
    if problem is not None:
        raise ValueError(problem)
    return value


#: A pydantic field type for identifiers (JSON Schema: the pattern; errors: one clear phrase).
Identifier = Annotated[
    str,
    AfterValidator(_validate),
    WithJsonSchema({"type": "string", "pattern": IDENTIFIER_PATTERN, "maxLength": IDENTIFIER_MAX_LENGTH}),
]
