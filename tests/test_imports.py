"""The package's import graph (stdlib ``ast``): no cycle between modules, and no import that runs up the floors.

Every ``import`` and ``from ... import`` of a washbench module in ``washbench/`` counts, at the top of a file or
inside a function (both are dependencies). ``from pkg import name`` depends on the module ``pkg.name`` when that
is a module, otherwise on ``pkg`` itself; importing a submodule is not counted as depending on its package's
``__init__``. The floors are documented in ``docs/architecture.md``: a wing (a sub-package, or a top-level module)
imports only from wings on lower floors; modules of one wing may import each other, but never round a loop.

What is still knotted is listed below, edge by edge. The test fails when a cycle or an upward import appears that
is not listed, and when a listed one has gone (take it off the list): the lists can only shrink.

``python tests/test_imports.py`` prints the wings' graph and any cycle.

Where an import goes: in the module's header, unless deferring it into a function keeps a heavy third-party
dependency off the path of a command that does not need it. Such an import says so on its line,
``# deferred: <dependency>`` (a name in ``DEFERRED_FOR``), and the claim is checked: the imported module must bring
in, through the imports of its header, a washbench module that imports that dependency and that the importing
module's header does not already load. ``# deferred: signals`` marks the one other reason: the import runs where a
Ctrl-C or SIGTERM arriving during it is handled (``washbench.__main__``).
"""

from __future__ import annotations

import ast
import functools
import re
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
    "pilot": 5,
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

#: The heavy dependencies a washbench import inside a function may be deferred for (``# deferred: <name>``).
DEFERRED_FOR = (
    "matplotlib", "rerun", "jsbsim", "numba", "pyarrow", "numpy", "pydantic", "dask", "daqp", "piqp",
    "scipy.signal", "scipy.linalg", "scipy.optimize", "scipy.sparse",
)  # fmt: skip
#: The deferral that names no dependency: the import must run under the command's signal handling.
DEFERRED_FOR_SIGNALS = "signals"
DEFERRED_TAG = re.compile(r"# deferred: ([A-Za-z_][\w.]*)(?:\s|$)")


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
        tree = parsed(path)
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


def _is_type_checking(node: ast.AST) -> bool:
    return isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)


def _imported_names(node: ast.Import | ast.ImportFrom, package: str) -> list[str]:
    """Dotted names an import statement loads: ``from scipy import sparse`` -> ``scipy``, ``scipy.sparse``."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if node.level:
        base = package.split(".")[: len(package.split(".")) - node.level + 1]
        source = ".".join(base + ([node.module] if node.module else []))
    else:
        source = node.module or ""
    return [source, *(f"{source}.{alias.name}" for alias in node.names)]


def header_imports(known: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> every dotted name its header imports (what runs at import: not in functions, not TYPE_CHECKING)."""
    out: dict[str, set[str]] = {}
    for name, path in known.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found: set[str] = set()
        stack = list(parsed(path).body)
        while stack:
            node = stack.pop()
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)) or _is_type_checking(node):
                continue
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                found.update(_imported_names(node, package))
            stack.extend(ast.iter_child_nodes(node))
        out[name] = found
    return out


@functools.cache
def parsed(path: Path) -> ast.Module:
    """The syntax tree of one of the package's files, parsed once for all the checks here."""
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _imports_in_functions(tree: ast.Module) -> list[ast.Import | ast.ImportFrom]:
    """The import statements anywhere inside a function or lambda of ``tree`` (each once, in one walk)."""
    found: list[ast.Import | ast.ImportFrom] = []
    stack: list[tuple[ast.AST, bool]] = [(tree, False)]
    while stack:
        node, inside = stack.pop()
        inside = inside or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
        if inside and isinstance(node, (ast.Import, ast.ImportFrom)):
            found.append(node)
        stack.extend((child, inside) for child in ast.iter_child_nodes(node))
    return found


def lazy_names(known: dict[str, Path]) -> dict[tuple[str, str], str]:
    """(package, name) -> the submodule it comes from, for names a package's ``__init__`` provides lazily
    (declared under ``if TYPE_CHECKING:`` there, loaded by its module ``__getattr__``)."""
    out = {}
    for name, path in known.items():
        if path.name != "__init__.py":
            continue
        for node in parsed(path).body:
            if _is_type_checking(node):
                for sub in ast.walk(node):
                    if isinstance(sub, ast.ImportFrom) and sub.module and not sub.level:
                        out.update({(name, alias.name): sub.module for alias in sub.names})
    return out


def _loaded_by(module: str, known: dict[str, Path], header: dict[str, set[str]]) -> set[str]:
    """The washbench modules importing ``module`` loads: its header's imports, followed, and their packages."""
    seen: set[str] = set()
    todo = [module]
    while todo:
        m = todo.pop()
        if m in seen or m not in known:
            continue
        seen.add(m)
        parts = m.split(".")
        todo.extend(".".join(parts[:i]) for i in range(1, len(parts)))  # a package's __init__ runs first
        todo.extend(n for n in (_nearest(t, known) for t in header[m] if t.startswith("washbench")) if n)
    return seen


def deferred_imports(known: dict[str, Path]) -> list[tuple[str, int, str, list[str], str | None]]:
    """Every import of a washbench module inside a function: (file, line, importer, targets, ``# deferred:`` tag)."""
    lazy = lazy_names(known)
    root = known["washbench"].parents[1]
    out = []
    for name, path in known.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        lines = path.read_text(encoding="utf-8").splitlines()
        for node in _imports_in_functions(parsed(path)):
            names = _imported_names(node, package)
            if not any(n == "washbench" or n.startswith("washbench.") for n in names):
                continue
            targets = set()
            for n in names[1:] if isinstance(node, ast.ImportFrom) else names:
                source, _, attr = n.rpartition(".")
                n = lazy.get((source, attr), n)
                targets.add(n if n in known else _nearest(n, known) or n)
            text = " ".join(lines[node.lineno - 1 : node.end_lineno])
            tag = DEFERRED_TAG.search(text)
            out.append((str(path.relative_to(root)), node.lineno, name, sorted(targets),
                        tag.group(1) if tag else None))  # fmt: skip
    return sorted(out)


def deferral_problems(known: dict[str, Path]) -> list[str]:
    """What is wrong with the package's imports inside functions (the module docstring's rule), one line each."""
    header = header_imports(known)
    problems = []
    for file, line, importer, targets, tag in deferred_imports(known):
        where = f"{file}:{line}: {', '.join(targets)}"
        if tag is None:
            problems.append(f"{where}: move it to the header, or mark it '# deferred: <dependency>'")
        elif tag == DEFERRED_FOR_SIGNALS:
            continue
        elif tag not in DEFERRED_FOR:
            problems.append(f"{where}: '# deferred: {tag}' is not a heavy dependency of DEFERRED_FOR")
        else:
            already = _loaded_by(importer, known, header)
            brought = set().union(*(_loaded_by(t, known, header) for t in targets)) - already
            if not any(n == tag or n.startswith(f"{tag}.") for m in brought for n in header[m]):
                problems.append(f"{where}: deferred for {tag}, but it brings in no module that imports {tag}"
                                f" and {importer} does not already load: move it to the header")  # fmt: skip
    return problems


@functools.cache
def graph() -> tuple[dict[str, Path], dict[str, set[str]]]:
    """The package's modules and their import edges, read when a test first needs them (1 s: not while every test
    worker collects)."""
    known = modules()
    return known, import_edges(known)


def test_the_graph_is_read() -> None:
    """The parser sees the package: many modules, many edges, imports inside functions included."""
    KNOWN, EDGES = graph()
    assert len(KNOWN) > 80 and sum(len(b) for b in EDGES.values()) > 200
    assert "washbench.runs.pipeline" in EDGES["washbench.cli"]  # imported inside _dispatch
    assert "washbench.numerics.rotations" in EDGES["washbench.platform.kinematics"]


def test_every_wing_has_a_floor() -> None:
    KNOWN, _ = graph()
    missing = sorted({wing(m) for m in KNOWN} - set(FLOORS))
    assert missing == [], f"give these a floor in FLOORS (and docs/architecture.md): {missing}"


def test_no_new_import_cycle() -> None:
    found = cycle_edges(graph()[1])
    assert sorted(found - KNOWN_CYCLE_EDGES) == [], "new import cycle"
    assert sorted(KNOWN_CYCLE_EDGES - found) == [], "cycle gone: take these edges off KNOWN_CYCLE_EDGES"


def test_no_new_import_up_the_floors() -> None:
    found = upward_edges(graph()[1])
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


def test_imports_in_functions_are_deferred_for_a_heavy_dependency() -> None:
    """A washbench import inside a function is marked ``# deferred: <dependency>``, and the mark is true."""
    KNOWN, _ = graph()
    assert len(deferred_imports(KNOWN)) > 20  # the parser sees them (the CLI's commands, the compiled kernels)
    assert deferral_problems(KNOWN) == []


def test_the_deferral_check_catches_an_unmarked_or_false_deferral(tmp_path: Path) -> None:
    """On a made-up package: an unmarked import, a false claim and an unknown name are each reported."""
    pkg = tmp_path / "washbench"
    (pkg / "kern").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "kern" / "__init__.py").write_text("")
    (pkg / "kern" / "fast.py").write_text("from numba import njit\n")
    (pkg / "kern" / "slow.py").write_text("import json\n")
    (pkg / "use.py").write_text(
        "def a():\n    from washbench.kern import fast  # deferred: numba\n"
        "def b():\n    from washbench.kern import slow  # deferred: numba\n"
        "def c():\n    import washbench.kern.slow\n"
        "def d():\n    from washbench.kern.fast import njit  # deferred: speed\n"
    )
    found = deferral_problems(modules(pkg))
    assert [p.split(": ")[0] for p in found] == ["washbench/use.py:4", "washbench/use.py:6", "washbench/use.py:8"]
    assert "brings in no module that imports numba" in found[0] and "move it to the header" in found[1]
    assert "not a heavy dependency" in found[2]



#: The modules whose header may import numba: the one that hands its decorators to the compiled modules, prepared
#: first (washbench.numerics.jit), and the suite's preloader, which names kernel signatures with numba's types.
NUMBA_IN_HEADER = {"washbench.numerics.jit", "washbench.runs.preload"}


def test_numba_s_decorators_come_prepared_from_one_module() -> None:
    """A module compiled at its import takes ``njit``/``prange`` from :mod:`washbench.numerics.jit`, which sets
    numba's cache folder and makes its start light before any kernel is defined, not from numba itself (where that
    start would be left to the module to remember)."""
    known, _ = graph()
    header = header_imports(known)
    direct = {m for m, names in header.items() if any(n == "numba" or n.startswith("numba.") for n in names)}
    assert direct == NUMBA_IN_HEADER
    prepared = {m for m, names in header.items() if "washbench.numerics.jit.njit" in names}
    assert len(prepared) >= 10  # the kernels: rotations, filters, the washout kernel, platforms, perception, metrics
    jit_source = known["washbench.numerics.jit"].read_text(encoding="utf-8")
    assert "\nprepare()\n" in jit_source


if __name__ == "__main__":
    KNOWN, EDGES = graph()
    wings: dict[str, set[str]] = defaultdict(set)
    for a, bs in EDGES.items():
        for b in bs:
            if wing(a) != wing(b):
                wings[wing(a)].add(wing(b))
    for w in sorted(FLOORS, key=lambda k: (FLOORS[k], k)):
        print(f"floor {FLOORS[w]:>2}  {w:<13} -> {', '.join(sorted(wings.get(w, ()), key=lambda k: -FLOORS[k]))}")
    for a, b in sorted(cycle_edges(EDGES)):
        print(f"cycle edge: {a} -> {b}")
    for problem in deferral_problems(KNOWN):
        print(problem)
