"""The package's import graph: no circle, and every arrow points down the layers.

Every module of ``fastsim_ros`` and ``msg_adapters`` is read from its source
(imports at the top and inside functions alike) and its imports of the two
packages resolved to modules: ``from fastsim_ros.pipeline import kernels``
is an arrow to ``fastsim_ros.pipeline.kernels``, ``from fastsim_ros.pipeline
import Pipeline`` one to the package ``fastsim_ros.pipeline``.  The layers,
lowest first: the physics (``contact/``) and the message adapters
(``msg_adapters/``), which import nothing of the rest; the leaf utilities
(``errors``, ``atomic``, ``numba_quietly``: nothing of the package but the
physics' errors); the geometry and the estimation; the parameter tables
(``ros/params``, ``ros/plausibility``); the pipelines; the front ends (the ROS
node, the command lines, the replay), which never import one another.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("fastsim_ros", "msg_adapters")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


MODULES = {_module_name(p): p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py"))}


def _imports(name: str, path: Path) -> set[str]:
    """Return the modules of the two packages that module ``name`` (file ``path``) imports."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(package.split(".")[:len(package.split(".")) - node.level + 1]
                                + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base
                       for a in node.names]
        for target in targets:
            # ``import fastsim_ros.contact.area`` names the module; a deeper name is an attribute
            while target and target not in MODULES:
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def _area(module: str) -> str:
    """Return the layer's area a module belongs to (the table below)."""
    for area in sorted(ALLOWED, key=len, reverse=True):
        if module == area or module.startswith(area + "."):
            return area
    raise KeyError(module)


UTILITIES = {"fastsim_ros.errors", "fastsim_ros.atomic", "fastsim_ros.numba_quietly"}
PHYSICS = {"fastsim_ros.contact"}
#: what each area may import of the two packages, besides itself
ALLOWED = {
    "fastsim_ros": set(),    # the package's __init__: the numba cache's directory only
    "fastsim_ros.contact": set(),
    "msg_adapters": set(),
    "fastsim_ros.errors": set(),
    "fastsim_ros.numba_quietly": set(),
    "fastsim_ros.atomic": PHYSICS,
    "fastsim_ros.geometry": PHYSICS | UTILITIES,
    "fastsim_ros.estimation": PHYSICS | UTILITIES | {"msg_adapters"},
    "fastsim_ros.ros.params": PHYSICS | UTILITIES,
    "fastsim_ros.ros.plausibility": PHYSICS | UTILITIES | {"fastsim_ros.ros.params"},
    "fastsim_ros.pipeline": (PHYSICS | UTILITIES
                             | {"fastsim_ros.geometry", "fastsim_ros.estimation", "msg_adapters",
                                "fastsim_ros.ros.params", "fastsim_ros.ros.plausibility"}),
    "fastsim_ros.ros": (PHYSICS | UTILITIES
                        | {"fastsim_ros.pipeline", "fastsim_ros.ros.params", "msg_adapters",
                           "fastsim_ros.ros.plausibility"}),
    "fastsim_ros.cli": (PHYSICS | UTILITIES
                        | {"fastsim_ros.geometry", "fastsim_ros.estimation",
                           "fastsim_ros.pipeline", "msg_adapters", "fastsim_ros.ros.params",
                           "fastsim_ros.ros.plausibility"}),
    "fastsim_ros.replay": (PHYSICS | UTILITIES
                           | {"fastsim_ros.pipeline", "msg_adapters", "fastsim_ros.ros.params",
                              "fastsim_ros.ros.plausibility"}),
}


def test_the_graph_is_read():
    """The reader finds the arrows it is meant to judge (a broken reader would pass all)."""
    assert "fastsim_ros.pipeline.steady" in GRAPH["fastsim_ros.pipeline"]
    assert "fastsim_ros.pipeline.kernels" in GRAPH["fastsim_ros.pipeline.steady"]
    assert "fastsim_ros.contact.area" in GRAPH["fastsim_ros.cli.patch"]
    assert "msg_adapters.cdr" in GRAPH["msg_adapters.patch"]
    assert set(GRAPH) == set(MODULES) and len(GRAPH) > 90


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Return the strongly connected components of more than one module (Tarjan's)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
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

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_circle():
    assert _cycles(GRAPH) == []


def test_the_cycle_finder_sees_a_circle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


@pytest.mark.parametrize("module", sorted(MODULES))
def test_arrows_point_down(module):
    area = _area(module)
    upward = sorted(t for t in GRAPH[module] if _area(t) != area
                    and not any(t == a or t.startswith(a + ".") for a in ALLOWED[area]))
    assert not upward, f"{module} ({area}) imports {upward}"


def test_the_top_level_holds_subpackages_and_a_few_modules():
    modules = {p.stem for p in (ROOT / "fastsim_ros").glob("*.py")}
    assert modules == {"__init__", "errors", "atomic", "numba_quietly"}


@pytest.mark.parametrize("module", ["fastsim_ros.ros", "fastsim_ros.ros.params",
                                    "fastsim_ros.ros.plausibility", "fastsim_ros.pipeline",
                                    "fastsim_ros.cli"])
def test_no_ros_import_outside_the_node(module):
    """The parameter tables, the pipelines and the command lines run without ROS."""
    code = (f"import sys, {module}; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'rclpy'))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"
