"""The layering rules, read from the source: no OpenCascade in the geometry layer, no
import cycles between modules, no private names imported across modules.

* ``algorithms/`` imports neither OCP nor cadquery nor build123d, at any level.
* Module-level imports form no cycle. The one allowed cycle is the type <->
  operations pattern of :class:`NurbsCurve` / :class:`NurbsSurface`: their methods
  import the operation modules (knots, degree, bezier...) inside the method body,
  which import the types at the top. Lazy imports elsewhere must not close a cycle.
* No module imports a ``_private`` name of another module of the package (the
  allow-list below is empty: a new private cross-import fails here; make the name
  public in its module instead).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGES = {"surfprep": REPO / "surfprep", "surfprep.algorithms": REPO / "algorithms",
            "surfprep.plugin": REPO / "plugin"}
#: modules whose method bodies may import the modules that import them (type <-> operations)
TYPE_MODULES = {"surfprep.algorithms.curve", "surfprep.algorithms.surface"}
#: (importing module, imported module, name): private names allowed across modules
ALLOWED_PRIVATE: set[tuple[str, str, str]] = set()
FORBIDDEN_IN_ALGORITHMS = ("OCP", "cadquery", "build123d")


def _modules() -> dict[str, Path]:
    mods = {}
    for package, folder in PACKAGES.items():
        for path in folder.rglob("*.py"):
            parts = list(path.relative_to(folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            mods[".".join([package, *parts])] = path
    return mods


MODULES = _modules()


def _resolve(module: str, is_package: bool, level: int, name: str | None) -> str:
    if level == 0:
        return name or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[:len(base) - (level - 1)]
    return ".".join(base + ([name] if name else []))


def _imports(module: str) -> list[tuple[str, str | None, bool]]:
    """``(imported module, imported name or None, at module level)`` of every import."""
    path = MODULES[module]
    tree = ast.parse(path.read_text())
    is_package = path.name == "__init__.py"
    out: list[tuple[str, str | None, bool]] = []

    def walk(nodes, top: bool) -> None:
        for node in nodes:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                walk(node.body, False)
            elif isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                continue                                   # for type checkers only
            elif isinstance(node, ast.ImportFrom):
                target = _resolve(module, is_package, node.level, node.module)
                out.extend((target, alias.name, top) for alias in node.names)
            elif isinstance(node, ast.Import):
                out.extend((alias.name, None, top) for alias in node.names)
            else:
                for field in ("body", "orelse", "finalbody", "handlers"):
                    walk(getattr(node, field, []), top)

    walk(tree.body, True)
    return out


def _edges(include_lazy: bool) -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for module in MODULES:
        for target, name, top in _imports(module):
            if not (top or include_lazy):
                continue
            if include_lazy and not top and module in TYPE_MODULES:
                continue                                   # the documented pattern
            full = f"{target}.{name}" if name else target
            hit = full if full in MODULES else target
            if hit in MODULES and hit != module:
                graph[module].add(hit)
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
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
                found.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    return found


def test_the_package_is_found():
    assert "surfprep.algorithms.curve" in MODULES and "surfprep.plugin.cli" in MODULES
    assert len(MODULES) > 100


@pytest.mark.parametrize("include_lazy", [False, True], ids=["module level", "with lazy"])
def test_no_import_cycle(include_lazy):
    assert _cycles(_edges(include_lazy)) == []


def test_the_cycle_check_sees_a_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _cycles(graph) == [["a", "b", "c"]]


def test_no_private_name_imported_across_modules():
    private = set()
    for module in MODULES:
        for target, name, _ in _imports(module):
            if name and name.startswith("_") and not name.startswith("__") \
                    and target.startswith("surfprep"):
                private.add((module, target, name))
    assert private == ALLOWED_PRIVATE


def test_algorithms_never_import_opencascade():
    offenders = [(module, target) for module in MODULES if module.startswith("surfprep.algorithms")
                 for target, _, _ in _imports(module)
                 if target.split(".")[0] in FORBIDDEN_IN_ALGORITHMS]
    assert offenders == []
