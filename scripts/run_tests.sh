#!/usr/bin/env bash
# Build (scripts/setup_env.sh), run every test of the package with
# `colcon test`, and report.  Exits non-zero if a test failed or errored, if
# colcon failed, or if no test ran at all.  The last line printed is
# "N passed, F failed[, S skipped]".
set -euo pipefail

# One stream, so that the closing line below really is the last line.
exec 2>&1

cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup_env.sh
export PATH="$PWD/.venv/bin:$PATH"

# colcon writes a placeholder result before running pytest; removing the old
# one as well means results of an earlier run can never be counted again.
rm -f build/fastsim_ros/pytest.xml

status=0
# pytest runs in the package root (pytest.ini: testpaths = test); its JUnit
# XML goes to build/fastsim_ros/pytest.xml.  console_direct+ streams its
# output.  --pytest-args must come last: it takes the rest of the line.
# Two workers (pytest-xdist), each taking whole test files (a file's fixtures,
# a contact table or a bag's replay, are built once): the suite is mostly one
# process at a time waiting on one core, and the machines have two.
colcon test \
    --build-base build --install-base install \
    --packages-select fastsim_ros \
    --event-handlers console_direct+ console_start_end- status- desktop_notification- \
    --pytest-args -q -n 2 --dist loadfile || status=$?

results_rc=0
results="$(colcon test-result --test-result-base build --verbose 2>&1)" || results_rc=$?
printf '%s\n' "$results"

summary="$(printf '%s\n' "$results" | grep -E '^Summary: [0-9]+ tests?, ' | tail -n 1 || true)"
if [[ -z "$summary" ]]; then
    echo "run_tests: no test results found under build/"
    echo "0 passed, 0 failed"
    exit 1
fi
read -r total errors failures skipped < <(
    printf '%s\n' "$summary" |
        sed -E 's/^Summary: ([0-9]+) tests?, ([0-9]+) errors?, ([0-9]+) failures?, ([0-9]+) skipped.*/\1 \2 \3 \4/')
failed=$((errors + failures))
passed=$((total - failed - skipped))

if [[ "$status" -ne 0 ]]; then
    echo "run_tests: colcon test exited with $status"
fi
if [[ "$total" -eq 0 ]]; then
    echo "run_tests: no test ran"
fi
closing="$passed passed, $failed failed"
if [[ "$skipped" -gt 0 ]]; then
    closing="$closing, $skipped skipped"
fi
echo "$closing"

if [[ "$status" -ne 0 || "$results_rc" -ne 0 || "$total" -eq 0 || "$failed" -ne 0 ]]; then
    exit 1
fi
