#!/usr/bin/env bash
# Build (scripts/setup_env.sh), then solve the bundled flange-root contact patch
# (fastsim_ros/data/example_patch.csv, 50 kN) at one creepage with MAE + FastSim,
# the method the node runs, and with the exact theory it is validated against,
# through the installed console script.  Nothing needs to be sourced: the
# script's shebang is the venv's python, and PYTHONPATH points at the install.
# Extra arguments are passed on to both fastsim_contact runs (e.g. --json).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup_env.sh

site_packages=(install/fastsim_ros/lib/python3.*/site-packages)
export PYTHONPATH="$PWD/${site_packages[0]}${PYTHONPATH:+:$PYTHONPATH}"
contact=install/fastsim_ros/lib/fastsim_ros/fastsim_contact
patch=fastsim_ros/data/example_patch.csv
creepage=(--xi 1e-3 --eta 0 --phi 0.5 --mu 0.3)

echo "== creep forces on $patch, xi = 1e-3, phi = 0.5 1/m, mu = 0.3"
"$contact" forces --patch "$patch" "${creepage[@]}" --method mae "$@"
"$contact" forces --patch "$patch" "${creepage[@]}" --method fastsim_ellipse "$@"
"$contact" forces --patch "$patch" "${creepage[@]}" --method exact "$@"
