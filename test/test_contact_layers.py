"""The physics core's dependencies point down (docs/guide_physics.md: what may import what).

Each module's imports (top-level and inside functions) are read from its source
and compared with ``ALLOWED``, the table the guide gives (checked equal); and
the compiled fast path is imported and run with SciPy made unimportable.
"""

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

CONTACT = Path(__file__).resolve().parents[1] / "fastsim_ros" / "contact"

#: third-party packages and package modules each module may import (the guide's table)
ALLOWED = {
    "errors": set(),
    "checks": {"errors"},
    "coefficients": set(),
    "rules": set(),
    "area": {"numpy", "checks", "errors"},
    "traction": {"numpy", "area"},
    "influence": {"numpy"},
    "tables": {"numpy", "errors"},
    "pairs": {"numpy", "errors", "rules"},
    "slope_reduction": {"errors"},
    "wear": {"errors"},
    "friction": {"numpy", "checks", "errors", "rules", "slope_reduction"},
    "fastsim": {"numpy", "area", "checks", "errors", "friction", "rules", "traction"},
    "mae": {"numpy", "area", "checks", "coefficients", "equivalent", "fastsim", "friction",
            "rules", "tables", "traction"},
    "equivalent": {"numpy", "area", "checks", "coefficients", "fastsim", "friction", "rules",
                   "tables", "traction"},
    "mae_calibrated": {"numpy", "area", "checks", "coefficients", "equivalent", "errors",
                       "fastsim", "friction", "knee", "lobes", "mae", "pairs", "rules", "tables",
                       "traction"},
    "fastrip": {"numpy", "area", "checks", "coefficients", "equivalent", "errors", "fastsim",
                "tables", "traction"},
    "dlm": {"numpy", "area", "asm", "checks", "coefficients", "errors", "fastsim", "friction",
            "influence", "traction"},
    "asm": {"numpy", "area", "checks", "coefficients", "equivalent", "errors", "fastsim",
            "friction", "influence", "tables", "traction"},
    "knee": {"numpy", "errors"},
    "lobes": {"numpy"},
    "kernels": {"numpy", "numba", "knee", "lobes", "rules"},
    "compiled": {"numpy", "kernels", "area", "checks", "errors", "friction", "knee", "rules",
                 "slip_power", "tables", "pairs", "mae", "equivalent"},
    "rolling": {"numpy", "scipy", "area", "checks", "errors", "influence"},
    "partial_slip": {"numpy", "threadpoolctl", "area", "errors", "friction", "rolling",
                     "traction"},
    "exact": {"numpy", "scipy", "area", "checks", "coefficients", "errors", "friction",
              "partial_slip", "rolling", "traction"},
    "normal": {"numpy", "scipy", "area", "checks", "errors", "influence"},
    "samples": {"numpy", "area", "errors", "normal"},
    "transient": {"numpy", "numba", "area", "checks", "compiled", "errors", "friction",
                  "kernels"},
    "exact_transient": {"numpy", "area", "checks", "errors", "influence", "partial_slip",
                        "rolling", "traction"},
    "seed_tables": {"errors"},
    "slip_power": {"numpy", "numba", "kernels"},
    "polach": {"numpy", "kernels", "area", "checks", "compiled", "errors", "friction",
               "slope_reduction", "tables"},
}


def imports_of(path):
    """Return the third-party packages and ``fastsim_ros.contact`` modules a file imports."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            if node.module == "fastsim_ros.contact":
                names = [f"fastsim_ros.contact.{a.name}" for a in node.names]
            else:
                names = [node.module]
        for name in names:
            if name.startswith("fastsim_ros.contact."):
                found.add(name.split(".")[2])
            elif name.split(".")[0] not in sys.stdlib_module_names and name != "__future__":
                found.add(name.split(".")[0])
    return found


GUIDE = CONTACT.parents[1] / "docs" / "guide_physics.md"
THIRD_PARTY = ("numpy", "numba", "scipy", "threadpoolctl")


def test_the_guide_states_the_table():
    """The guide's module table names every module with the imports ``ALLOWED`` gives it."""
    rows = {}
    for line in GUIDE.read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 3 and re.fullmatch(r"`\w+\.py`", cells[0]):
            uses = cells[2].split("(")[0]
            rows[cells[0][1:-4]] = (set(re.findall(r"`(\w+)`", uses))
                                    | {w for w in THIRD_PARTY if re.search(rf"\b{w}\b", uses)})
    assert rows == ALLOWED


def test_every_module_is_in_the_table():
    modules = {p.stem for p in CONTACT.glob("*.py") if p.stem != "__init__"}
    assert modules == set(ALLOWED)


@pytest.mark.parametrize("module", sorted(ALLOWED))
def test_imports_point_down(module):
    extra = imports_of(CONTACT / f"{module}.py") - ALLOWED[module]
    assert not extra, f"{module} imports {sorted(extra)}"


BLOCK_SCIPY = """
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name == "scipy" or name.startswith("scipy."):
            raise ImportError(f"{name} blocked by the test")
sys.meta_path.insert(0, Block())
import numpy as np
from fastsim_ros.contact import compiled
from fastsim_ros.contact.area import ellipse
ar = ellipse(6e-3, 4e-3, nx=20, load=1e4)
for solver in (compiled.MaeSolver(0.28, 8e10), compiled.EquivalentEllipseSolver(0.28, 8e10)):
    f = solver.solve(ar, 1e-3, 0.0, 0.1, mu=0.3)
    assert np.isfinite(f.fx) and f.fx < 0.0
print(sorted(m for m in sys.modules if m.startswith("scipy")))
"""


def test_the_compiled_path_runs_without_scipy():
    done = subprocess.run([sys.executable, "-c", BLOCK_SCIPY], capture_output=True, text=True,
                          cwd=CONTACT.parents[1])
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_the_public_names_resolve_from_the_package():
    import fastsim_ros.contact as contact
    for name in contact.__all__:
        assert getattr(contact, name).__name__ == name
    with pytest.raises(AttributeError):
        contact.no_such_name  # noqa: B018


def test_importing_the_package_loads_no_solver():
    code = ("import sys, fastsim_ros.contact; "
            "print(sorted(m for m in sys.modules if m.startswith(('scipy', 'numba', "
            "'fastsim_ros.contact.'))))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=CONTACT.parents[1])
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"
