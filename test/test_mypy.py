"""Static types (mypy, mypy.ini) of the package's modules."""

from pathlib import Path
import subprocess
import sys

import pytest

PACKAGE_ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.linter
def test_mypy():
    # mypy.ini at the package root holds the configuration.
    completed = subprocess.run(
        [sys.executable, '-m', 'mypy', '--config-file', 'mypy.ini',
         'fastsim_ros', 'msg_adapters'],
        cwd=PACKAGE_ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        text=True, check=False)
    assert completed.returncode == 0, \
        'mypy exited with %d:\n%s' % (completed.returncode, completed.stdout)
