"""Sphinx configuration of the washbench documentation (Sphinx + MyST Markdown, Furo theme).

Build (what CI runs, warnings are errors, so a broken internal link or reference fails the build)::

    pip install -e '.[docs]'
    python -m sphinx -W --keep-going -b html docs docs/_build/html

Adding a page: write ``docs/NAME.md`` (a top-level page appears under "Topics and explanations" by itself,
through the glob in ``index.md``); a how-to goes in ``docs/how-to/``, a reference page in ``docs/reference/``.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent))  # the checkout's washbench, also when it is not installed

from washbench import __version__  # noqa: E402

project = "washbench"
author = "The washbench developers"
copyright = "the washbench developers, Apache-2.0"
release = __version__
version = __version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "washbench_reference",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**/README.md"]

# MyST: heading anchors so that [text](page.md#a-heading) links are checked; $...$ maths; ::: fences.
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist", "attrs_inline"]
myst_heading_anchors = 4

# autodoc: the Python API from docstrings, in source order, with types in the description.
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
# Type hints name third-party classes that have no page here; those are not broken links of ours.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|npt|pyarrow|pa|pydantic|rerun|rr|jsbsim|matplotlib|collections|typing|pathlib|os)\..*"),
    (r"py:.*", r"(NDArray|ArrayLike|Path|Any|Sequence|Mapping|Iterable|Iterator|Callable|Literal|Self)"),
    (r"py:class", r".*"),
    (r"py:data", r".*"),
    (r"py:obj", r".*"),
]



def _plain_bars(app, what, name, obj, options, lines):
    """Docstrings write absolute values as ``|x|``; in reStructuredText that would be a substitution."""
    for i, line in enumerate(lines):
        parts = line.split("``")  # even parts are outside inline literals
        lines[i] = "``".join(part.replace("|", "\\|") if k % 2 == 0 else part for k, part in enumerate(parts))


def setup(app):
    app.connect("autodoc-process-docstring", _plain_bars)


html_theme = "furo"
html_title = f"washbench {version}"
html_static_path: list[str] = []
