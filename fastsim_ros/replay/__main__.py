"""``python -m fastsim_ros.replay``: the same as ``fastsim_replay``."""

import sys

from fastsim_ros.replay.cli import main

sys.exit(main())
