"""Code style (flake8, setup.cfg) of the whole package."""

from pathlib import Path

from ament_flake8.main import main_with_errors
import pytest

PACKAGE_ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8(monkeypatch):
    # Check the whole package with the [flake8] section of setup.cfg (max line
    # length 99; excludes .venv, build, install, log) instead of ament's
    # default configuration file.
    monkeypatch.chdir(PACKAGE_ROOT)
    rc, errors = main_with_errors(argv=['--config', 'setup.cfg'])
    assert rc == 0, \
        'Found %d code style errors / warnings:\n' % len(errors) + \
        '\n'.join(errors)
