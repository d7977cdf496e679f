"""The import graph of src/ktgf, lazy imports included: arrows point down the rooms and close no circle.

Every ``import`` and ``from ... import`` statement of every module is read from the source (also those
inside functions), and so is every ``importlib.import_module("ktgf....")`` with a literal name.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src"
ROOT = SRC / "ktgf"

#: Rooms from the bottom up; a module may import its own room and the rooms below it.
LAYERS = (
    ("_version", "errors", "_startup"),
    ("_array", "validation", "sweep", "io"),
    ("data",),
    ("closures",),
    ("hcs", "shear"),
    ("couette",),
    ("plotting",),
    ("calibration", "dem"),
    ("solver",),
    ("report",),
    ("cli", "__main__", "__init__"),
)
RANK = {room: i for i, rooms in enumerate(LAYERS) for room in rooms}


pytestmark = pytest.mark.contract


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_module(name: str) -> bool:
    p = SRC.joinpath(*name.split("."))
    return p.with_suffix(".py").is_file() or (p / "__init__.py").is_file()


def import_graph() -> dict[str, set[str]]:
    """module → the ktgf modules it imports (an imported name that is a submodule counts as that submodule)."""
    graph: dict[str, set[str]] = {}
    for path in ROOT.rglob("*.py"):
        name = _module_name(path)
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        targets: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
                mod = ".".join(base + ([node.module] if node.module else [])) if node.level else (node.module or "")
                if mod.split(".")[0] == "ktgf":
                    for alias in node.names:
                        sub = f"{mod}.{alias.name}"
                        targets.add(sub if _is_module(sub) else mod)
            elif isinstance(node, ast.Import):
                targets |= {a.name for a in node.names if a.name.split(".")[0] == "ktgf"}
            elif (isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", None)) == "import_module"
                  and node.args and isinstance(node.args[0], ast.Constant) and str(node.args[0].value).startswith("ktgf")):
                targets.add(str(node.args[0].value))
        graph[name] = {t for t in targets if t != name}
    return graph


def room(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def test_every_room_has_a_layer() -> None:
    rooms = {room(m) for m in import_graph()}
    assert rooms <= set(RANK), f"rooms without a layer in LAYERS: {sorted(rooms - set(RANK))}"


def test_no_import_runs_back_up() -> None:
    upward = sorted(f"{a} -> {b}" for a, bs in import_graph().items() for b in bs
                    if b != "ktgf" and RANK[room(b)] > RANK[room(a)])
    assert not upward, "imports that point up the rooms:\n" + "\n".join(upward)


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in list(graph):
        if v not in index:
            visit(v)
    return found


def test_no_module_imports_close_a_circle() -> None:
    graph = {m: {t for t in ts if t != "ktgf"} for m, ts in import_graph().items()}
    assert cycles(graph) == []


def test_the_cycle_finder_finds_a_circle() -> None:
    """The oracle of the test above, on a graph with a known circle and a tail."""
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
