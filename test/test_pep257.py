"""Docstring style (pep257, ament convention) of the whole package."""

from pathlib import Path

from ament_pep257.main import main
import pytest

PACKAGE_ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257(monkeypatch):
    # Directories starting with '.' or '_' (.venv, __pycache__) are skipped by
    # ament_pep257 itself; colcon's output directories are excluded here.
    monkeypatch.chdir(PACKAGE_ROOT)
    # The ament convention, with summaries on the docstring's first line (D212
    # style, as numpy and scipy write them) rather than its second (D213).
    rc = main(argv=['.', 'test', '--exclude', 'build', 'install', 'log',
                    '--add-ignore', 'D213'])
    assert rc == 0, 'Found code style errors / warnings'
