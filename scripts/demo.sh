#!/usr/bin/env bash
# Build (scripts/setup_env.sh), then compute the creep coefficients of the
# example contact patch with the exact solver, through the installed console
# script.  Nothing needs to be sourced: the script's shebang is the venv's
# python, and PYTHONPATH points at the package's install tree.
# Extra arguments are passed on to fastsim_contact.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup_env.sh

site_packages=(install/fastsim_ros/lib/python3.*/site-packages)
export PYTHONPATH="$PWD/${site_packages[0]}${PYTHONPATH:+:$PYTHONPATH}"
exec install/fastsim_ros/lib/fastsim_ros/fastsim_contact coefficients \
    --patch fastsim_ros/data/example_patch.csv --method exact "$@"
