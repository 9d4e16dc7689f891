"""The user guide in docs/ builds with Sphinx, warnings as errors, and says what the code says.

The build runs into a temporary directory (``sphinx -W -b html docs OUT``),
as a user builds it.  The parameters page is generated from
``fastsim_ros.ros.params.PARAMETERS`` at build time: every declared parameter
appears in it with its default.  Nothing in the repository cites a file
outside it.
"""

from __future__ import annotations

import html
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

from fastsim_ros.ros.params import PARAMETERS

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: the contract and reference files kept beside the repository, never part of it
OUTSIDE = re.compile(r"INTERFACE\.md|METHOD\.md|TARGETS\.md|shared/reference|\.\./shared/")

needs_sphinx = pytest.mark.skipif(
    importlib.util.find_spec("sphinx") is None or importlib.util.find_spec("myst_parser") is None,
    reason="sphinx and myst-parser are not installed (requirements.txt pins them)")


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Build the guide once into a temporary directory and return it."""
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-d", str(out / ".doctrees"), str(DOCS), str(out)],
        cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, f"sphinx failed:\n{done.stdout}\n{done.stderr}"
    assert not done.stderr.strip(), done.stderr
    return out


@needs_sphinx
def test_the_guide_builds_without_warnings(site: Path) -> None:
    """Every page of the toctree is built, the API pages from the docstrings included."""
    for page in ("index", "guide_node", "guide_profiles", "guide_estimation", "guide_transient",
                 "guide_replay", "guide_cli", "guide_real_rails", "guide_wear", "guide_physics",
                 "reports", "api", "changelog", "validation", "validation_wider"):
        assert (site / f"{page}.html").is_file(), page
    api = (site / "api.html").read_text(encoding="utf-8")
    # autodoc read the physics core and a ROS front end (its ROS imports mocked)
    assert "CalibratedMaeSolver" in api and "fastsim_ros.ros.node" in api


@needs_sphinx
def test_the_parameters_table_is_the_declarations(site: Path) -> None:
    """Every declared parameter is in the generated table, with its description."""
    page = (site / "guide_node.html").read_text(encoding="utf-8")
    text = html.unescape(re.sub(r"<[^>]+>", "", page))
    for spec in PARAMETERS:
        assert spec.name in text, spec.name
        assert spec.description in text, spec.name
        assert spec.allowed() in text, spec.name


def test_nothing_cites_a_file_outside_the_repository() -> None:
    """No tracked text file names the contract files kept outside the repository."""
    files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True,
                           check=True).stdout.split()
    if not files:
        pytest.skip("not a git checkout")
    # this test and the README's test name the files they look for
    checkers = {Path(__file__).resolve(), Path(__file__).resolve().with_name("test_readme.py")}
    found = []
    for name in files:
        path = ROOT / name
        text_file = path.suffix in (".py", ".md", ".rst", ".yaml", ".txt", ".sh", ".cfg", ".xml",
                                    ".ini", "")
        if path.resolve() in checkers or not text_file:
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue
        found += [f"{name}:{n}" for n, line in enumerate(text.splitlines(), 1)
                  if OUTSIDE.search(line)]
    assert not found, "cites a file outside the repository: " + ", ".join(found[:20])
