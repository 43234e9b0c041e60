"""The structure docs/maintainers.md describes: the Fortran and Python module graphs have
no cycle, and the contact solvers do not depend on the observables. Read from the sources
(Fortran `use` statements, Python imports of the package's own modules, lazy ones
included)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "driver" / "layercontact"


def fortran_graph() -> tuple[dict[str, set[str]], dict[str, Path]]:
    """Module -> the modules it uses, and module -> its file, over src/."""
    files = sorted((ROOT / "src").rglob("*.f90")) + sorted((ROOT / "src").rglob("*.F90"))
    where, uses = {}, {}
    for path in files:
        text = path.read_text()
        for name in re.findall(r"^\s*module\s+(\w+)\s*$", text, flags=re.M | re.I):
            where[name.lower()] = path
            uses[name.lower()] = {u.lower() for u in re.findall(r"^\s*use\s+(\w+)", text, flags=re.M | re.I)}
    return {m: {u for u in used if u in where and u != m} for m, used in uses.items()}, where


def python_graph() -> dict[str, set[str]]:
    """Module of the package (dotted, relative to it; subpackages included) -> the package's
    modules it imports."""
    names = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        names[".".join(parts)] = path
    graph = {}
    for name, path in names.items():
        package = name.split(".")[:-1]
        found = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.ImportFrom) and node.level >= 1):
                continue
            base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
            targets = [node.module] if node.module else [alias.name for alias in node.names]
            for target in targets:
                dotted = ".".join([*base, *target.split(".")])
                if dotted in names:
                    found.add(dotted)
                elif dotted + ".__init__" in names:
                    found.add(dotted + ".__init__")
        graph[name] = {m for m in found if m != name}
    # the package's __init__ re-exports and __main__ is the entry point: nothing imports them back
    for entry in ("__init__", "__main__"):
        graph.pop(entry, None)
    return {m: {u for u in used if u not in ("__init__", "__main__")} for m, used in graph.items()}


def cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle of the graph, or None."""
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def test_the_fortran_modules_have_no_cycle():
    graph, _ = fortran_graph()
    assert len(graph) > 40  # the whole library was read
    assert cycle(graph) is None, cycle(graph)


def test_the_contact_solvers_do_not_use_the_observables():
    graph, where = fortran_graph()
    contact = {m for m, p in where.items() if p.parent.name == "contact"}
    observables = {m for m, p in where.items() if p.parent.name == "observables"}
    assert contact and observables
    used = {(m, u) for m in contact for u in graph[m] if u in observables}
    assert not used, used


def test_the_python_modules_have_no_cycle():
    graph = python_graph()
    assert {"api", "leakage", "_library", "sweeps.sweep", "sweeps.slurm"} <= set(graph)
    assert cycle(graph) is None, cycle(graph)


def test_the_cycle_finder_finds_one():
    """The check above can fail: a graph with a cycle is reported."""
    assert cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert cycle({"a": {"b"}, "b": set()}) is None
