"""The package's import graph (stdlib ``ast``): no cycle between modules, and no import that runs up the floors.

Every ``import`` and ``from ... import`` of a washbench module in ``washbench/`` counts, at the top of a file or
inside a function (both are dependencies). ``from pkg import name`` depends on the module ``pkg.name`` when that
is a module, otherwise on ``pkg`` itself; importing a submodule is not counted as depending on its package's
``__init__``. The floors are documented in ``docs/architecture.md``: a wing (a sub-package, or a top-level module)
imports only from wings on lower floors; modules of one wing may import each other, but never round a loop.

What is still knotted is listed below, edge by edge. The test fails when a cycle or an upward import appears that
is not listed, and when a listed one has gone (take it off the list): the lists can only shrink.

``python tests/test_imports.py`` prints the wings' graph and any cycle.
"""

from __future__ import annotations

import ast
import sys
from collections import defaultdict
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "washbench"

#: Each wing's floor (docs/architecture.md). A new sub-package or top-level module needs a floor here.
FLOORS: dict[str, int] = {
    "washbench": 0,  # the package itself (__init__: the version)
    "errors": 0,
    "io": 1,
    "numerics": 2,
    "flight": 3,
    "platform": 3,
    "perception": 3,
    "cueing": 4,
    "analysis": 5,
    "review": 6,
    "live": 7,
    "runs": 8,
    "cli_examples": 9,
    "cli": 10,
    "__main__": 11,
}

#: Known cycles, as the exact edges (importer, imported) that lie on them: none left.
KNOWN_CYCLE_EDGES: frozenset[tuple[str, str]] = frozenset()

#: Known imports that run up the floors: none left.
KNOWN_UPWARD_EDGES: frozenset[tuple[str, str]] = frozenset()


def modules(package: Path = PACKAGE) -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` file of the package (a package is its ``__init__``)."""
    out = {}
    for path in sorted(package.rglob("*.py")):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _nearest(name: str, known: dict[str, Path]) -> str | None:
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


def import_edges(known: dict[str, Path]) -> dict[str, set[str]]:
    """Importer -> the washbench modules it imports (see the module docstring for what counts)."""
    edges: dict[str, set[str]] = defaultdict(set)
    for name, path in known.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(tree):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - node.level + 1]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                for alias in node.names:
                    sub = f"{source}.{alias.name}"
                    targets.append(sub if sub in known else source)
            for target in targets:
                if target == "washbench" or target.startswith("washbench."):
                    resolved = _nearest(target, known)
                    if resolved and resolved != name:
                        edges[name].add(resolved)
    return edges


def cycle_edges(edges: dict[str, set[str]]) -> set[tuple[str, str]]:
    """Every edge that lies on a cycle: both ends in one strongly connected component (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    component: dict[str, int] = {}
    counter = [0]
    nodes = set(edges) | {b for bs in edges.values() for b in bs}

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component[w] = index[v]
                if w == v:
                    break

    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10 * len(nodes) + 100))
    try:
        for v in sorted(nodes):
            if v not in index:
                visit(v)
    finally:
        sys.setrecursionlimit(limit)
    return {(a, b) for a, bs in edges.items() for b in bs if component[a] == component[b]}


def wing(module: str) -> str:
    """``washbench.io.paths`` -> ``io``; ``washbench.cli`` -> ``cli``; ``washbench`` -> ``washbench``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def upward_edges(edges: dict[str, set[str]]) -> set[tuple[str, str]]:
    """Edges from one wing to another that is not on a lower floor."""
    return {
        (a, b)
        for a, bs in edges.items()
        for b in bs
        if wing(a) != wing(b) and FLOORS[wing(b)] >= FLOORS[wing(a)]
    }


KNOWN = modules()
EDGES = import_edges(KNOWN)


def test_the_graph_is_read() -> None:
    """The parser sees the package: many modules, many edges, imports inside functions included."""
    assert len(KNOWN) > 80 and sum(len(b) for b in EDGES.values()) > 200
    assert "washbench.runs.pipeline" in EDGES["washbench.cli"]  # imported inside _dispatch
    assert "washbench.numerics.rotations" in EDGES["washbench.platform.kinematics"]


def test_every_wing_has_a_floor() -> None:
    missing = sorted({wing(m) for m in KNOWN} - set(FLOORS))
    assert missing == [], f"give these a floor in FLOORS (and docs/architecture.md): {missing}"


def test_no_new_import_cycle() -> None:
    found = cycle_edges(EDGES)
    assert sorted(found - KNOWN_CYCLE_EDGES) == [], "new import cycle"
    assert sorted(KNOWN_CYCLE_EDGES - found) == [], "cycle gone: take these edges off KNOWN_CYCLE_EDGES"


def test_no_new_import_up_the_floors() -> None:
    found = upward_edges(EDGES)
    assert sorted(found - KNOWN_UPWARD_EDGES) == [], "import up the floors (docs/architecture.md)"
    assert sorted(KNOWN_UPWARD_EDGES - found) == [], "gone: take these edges off KNOWN_UPWARD_EDGES"


def test_the_checks_catch_a_cycle_and_an_upward_import() -> None:
    """On a made-up graph: a loop of three modules and an import from io up to runs are both found."""
    fake = {
        "washbench.io.a": {"washbench.io.b", "washbench.runs.x"},
        "washbench.io.b": {"washbench.io.c"},
        "washbench.io.c": {"washbench.io.a"},
        "washbench.runs.x": {"washbench.io.a"},
        "washbench.cueing.k": {"washbench.numerics.r"},
    }
    loop = cycle_edges(fake)
    assert {("washbench.io.a", "washbench.io.b"), ("washbench.io.c", "washbench.io.a")} <= loop
    assert ("washbench.cueing.k", "washbench.numerics.r") not in loop
    assert upward_edges(fake) == {("washbench.io.a", "washbench.runs.x")}


if __name__ == "__main__":
    wings: dict[str, set[str]] = defaultdict(set)
    for a, bs in EDGES.items():
        for b in bs:
            if wing(a) != wing(b):
                wings[wing(a)].add(wing(b))
    for w in sorted(FLOORS, key=lambda k: (FLOORS[k], k)):
        print(f"floor {FLOORS[w]:>2}  {w:<13} -> {', '.join(sorted(wings.get(w, ()), key=lambda k: -FLOORS[k]))}")
    for a, b in sorted(cycle_edges(EDGES)):
        print(f"cycle edge: {a} -> {b}")
