"""The shape of the house as a checked contract: the rooms' layers (import-linter, pyproject.toml's
[tool.importlinter]), no import cycle between any two modules, and the top of gaitbot/ holding
packages and at most three small modules."""

from __future__ import annotations

import grimp
from importlinter import cli

from helpers import REPO_ROOT


def test_the_layers_contract_is_kept(monkeypatch):
    monkeypatch.chdir(REPO_ROOT)
    assert cli.lint_imports(config_filename=str(REPO_ROOT / "pyproject.toml"), no_cache=True, no_logo=True) == 0


def _strongly_connected(edges: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components, iteratively."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    found: list[list[str]] = []
    counter = 0
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges[child]))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    found.append(component)
    return found


def test_no_import_cycles():
    graph = grimp.build_graph("gaitbot", cache_dir=None)
    edges = {m: set(graph.find_modules_directly_imported_by(m)) for m in graph.modules}
    cycles = [sorted(c) for c in _strongly_connected(edges) if len(c) > 1]
    assert cycles == []


def test_the_cycle_finder_finds_a_cycle():
    assert sorted(map(sorted, _strongly_connected({"a": {"b"}, "b": {"a", "c"}, "c": set()}))) == [["a", "b"], ["c"]]


def test_the_top_of_the_package_holds_rooms():
    top = REPO_ROOT / "gaitbot"
    modules = sorted(p.name for p in top.glob("*.py"))
    assert modules == ["__init__.py", "__main__.py", "errors.py", "fields.py"]
    rooms = sorted(p.name for p in top.iterdir() if (p / "__init__.py").is_file())
    assert rooms == ["app", "bus", "check", "drive", "gait", "inputs", "plot", "robot", "servos", "sim", "stream"]
