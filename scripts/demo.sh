#!/usr/bin/env bash
# The main job on bundled data: set up (scripts/setup_env.sh: .venv, colcon
# build, numba cache), then replay the bundled recording bags/flange_shift
# (tread to flange-root patches from the normal solver, with a stretch of
# two-point contact) through the node's pipeline with the installed
# fastsim_replay, exactly as a rig engineer replays a recorded run.
# It prints the replay summary and writes, under demo_output/:
#   flange_shift/      a rosbag2 MCAP bag: the inputs plus wrenches, creepages,
#                      frames, wheelset wrench, markers and diagnostics
#                      (open it in Foxglove and plot /contact/left/wrench.wrench.force.x)
#   flange_shift.png   forces against time and against creepage, per contact
#   flange_shift.csv   one row per wrench
# Extra arguments go to fastsim_replay (e.g. --jobs 2 with more bags).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup_env.sh

out=demo_output
bag=flange_shift
rm -rf "$out/$bag" "$out/$bag.png" "$out/$bag.csv"
.venv/bin/fastsim_replay "bags/$bag" -o "$out" --params "bags/$bag.params.yaml" \
    --plot --csv "$@"
echo "demo: wrote $PWD/$out/$bag/ (bag), $PWD/$out/$bag.png (plot), $PWD/$out/$bag.csv"
