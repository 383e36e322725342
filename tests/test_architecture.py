"""The folder tree is the architecture: the import graph built from the source has no cycle and no import
from a lower layer to a higher one (``press`` < ``planning.model`` < ``planning.solver`` < the edges:
reports, sweep, trade-off, web, CLI); nothing outside ``press/`` knows a link length; tolerances live in
one module, and no function is longer than 80 lines."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("press", "planning")
LAYERS = (  # module prefix -> layer, the most specific prefix wins
    ("planning.tolerances", -1),  # the numbers every layer shares (the machine's geometry too)
    ("press", 0),
    ("planning.model", 1),
    ("planning.solver", 2),
    ("planning.reports", 3),
    ("planning.sweep", 3),
    ("planning.line_sweep", 3),
    ("planning.tradeoff", 3),
    ("planning.timeline", 3),
    ("planning.web", 3),
    ("planning.cli", 3),
    ("planning.interrupts", 3),
    ("planning.__main__", 3),
)


def _modules() -> dict[str, Path]:
    out = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            parts = path.relative_to(ROOT).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            out[name] = path
    return out


def _type_checking_only(node: ast.AST) -> bool:
    return isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)


def _imports(path: Path, modules: dict[str, Path]) -> set[str]:
    """Every project module ``path`` imports, at any depth of the file (function-level imports count; an
    ``if TYPE_CHECKING:`` block does not run and does not count)."""
    found: set[str] = set()

    def visit(node: ast.AST) -> None:
        if _type_checking_only(node):
            return
        if isinstance(node, ast.Import):
            for alias in node.names:
                found.add(_known(alias.name, modules))
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                found.add(_known(f"{node.module}.{alias.name}", modules))
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(path.read_text(encoding="utf-8")))
    return {m for m in found if m}


def _known(name: str, modules: dict[str, Path]) -> str:
    """The longest project module that ``name`` (a module or a name in one) lies in, '' outside the project."""
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        candidate = ".".join(parts[:k])
        if candidate in modules:
            return candidate
    return ""


def _layer(module: str) -> int | None:
    best = None
    for prefix, layer in LAYERS:
        if (module == prefix or module.startswith(prefix + ".")) and (best is None or len(prefix) > len(best[0])):
            best = (prefix, layer)
    return None if best is None else best[1]


def _graph() -> dict[str, set[str]]:
    modules = _modules()
    return {name: _imports(path, modules) - {name} for name, path in modules.items()}


def test_no_import_cycles():
    graph = _graph()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[list[str]] = []

    def strongconnect(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            strongconnect(v)
    assert cycles == []


def test_no_import_from_a_lower_layer_to_a_higher_one():
    upward = []
    for module, imported in _graph().items():
        here = _layer(module)
        for other in imported:
            there = _layer(other)
            if here is not None and there is not None and there > here:
                upward.append(f"{module} -> {other}")
    assert sorted(upward) == []


def test_the_graph_sees_function_level_imports():
    """The test above would miss a violation hidden in a function: the graph must see those imports."""
    graph = _graph()
    assert "planning.reports.check" in graph["planning.cli"]  # imported inside a function of the CLI
    assert "planning.solver.outcomes" in graph["planning.cli"]


LINK_LENGTHS = re.compile(r"\bR\b|rod_length|crank_radius")


def test_the_solver_knows_no_link_length():
    """The NLPs, the bound, the verification and the search reach the geometry through the mechanism."""
    hits = [
        f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
        for path in sorted((ROOT / "planning" / "solver").rglob("*.py"))
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1)
        if LINK_LENGTHS.search(line)
    ]
    assert hits == []


HALF_TURN = re.compile(r"(?<!2 \* )(?<!2\.0 \* )\b(np|math)\.pi\b(?! */ *180)")


def test_bdc_is_where_the_mechanism_says():
    """pi appears in the planner only as a whole turn, 2 pi: BDC (a half turn on an in-line crank-slider) is
    where the mechanism says, and an offset crank-slider's is not at pi."""
    files = sorted((ROOT / "planning").rglob("*.py")) + [ROOT / "press" / "dynamics.py"]
    hits = [
        f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
        for path in files
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1)
        if HALF_TURN.search(line)
    ]
    assert hits == []


CASADI_MODULES = {  # the wrapper and the modules that build expressions for it
    "planning.solver.ipopt",
    "planning.solver.lifting",
    "planning.solver.nlp",
    "planning.solver.halves_nlp",
    "planning.solver.free_nlp",
    "planning.solver.pendulum_nlp",
    "planning.solver.pendulum_swing",  # a swing's symbols and the rows every law's swing shares
    "planning.solver.pendulum_free",  # the optimal law's swings
    "planning.solver.pendulum_drive",
    "planning.solver.pendulum_robots",  # its rows (the dense checks beside them load no CasADi)
    "planning.solver.bound",
    "planning.solver.upper_bound",
    "planning.solver.compiled",  # the derivatives compiled by CasADi's code generator
    "planning.solver.peak_shaving",  # the peak-shaving linear programme (HiGHS through casadi.conic)
}


def test_only_the_solver_wrapper_and_the_nlp_builders_import_casadi():
    """The pure functions of ``press/`` and ``planning/model/`` take CasADi symbols without importing it, so
    ``check`` and the case reader never load it."""
    importers = set()
    for name, path in _modules().items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Import) and any(a.name.split(".")[0] == "casadi" for a in node.names):
                importers.add(name)
            if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "casadi":
                importers.add(name)
    assert importers == CASADI_MODULES


SMALLEST_LITERAL = 1e-4  # a float literal below this is a tolerance (or a floor against division by zero)
MAX_FUNCTION_LINES = 80


def test_tolerances_live_in_their_module():
    """``planning/tolerances.py`` holds every tolerance, each named with its unit and reason; nothing else in
    ``planning/`` or ``press/`` writes one as a literal, and the module imports nothing of the project's."""
    found = []
    for name, path in _modules().items():
        if name == "planning.tolerances":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            small = isinstance(node, ast.Constant) and isinstance(node.value, float)
            if small and 0 < abs(node.value) < SMALLEST_LITERAL:
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value!r}")
    assert found == []
    assert _graph()["planning.tolerances"] == set()


def test_no_function_is_longer_than_80_lines():
    """A function that does one thing fits on a screen (the style guide)."""
    long = []
    for path in sorted((ROOT / "planning").rglob("*.py")) + sorted((ROOT / "press").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}: {lines} lines")
    assert long == []
