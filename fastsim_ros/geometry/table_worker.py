"""A child interpreter that solves contact-table nodes: one pickle in on stdin, one out.

Run by :func:`fastsim_ros.geometry.table._solve_in_children` as ``python -m
fastsim_ros.geometry.table_worker``: stdin holds ``(wheelset, load, chunks,
sides)``, stdout gets the list of each chunk's solved nodes.
"""

from __future__ import annotations

import pickle
import sys

from fastsim_ros.geometry.table import _solve_nodes


def main() -> int:
    """Solve the chunks on stdin; write their nodes to stdout."""
    wheelset, load, chunks, sides = pickle.loads(sys.stdin.buffer.read())
    parts = [_solve_nodes((wheelset, load, chunk, sides)) for chunk in chunks]
    sys.stdout.buffer.write(pickle.dumps(parts, protocol=pickle.HIGHEST_PROTOCOL))
    sys.stdout.buffer.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
