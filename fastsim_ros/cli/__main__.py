"""``python -m fastsim_ros.cli``: the same as ``fastsim_contact``."""

import sys

from fastsim_ros.cli import main

sys.exit(main())
