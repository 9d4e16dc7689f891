#!/usr/bin/env bash
# Prepare this checkout: .venv with requirements.txt, then `colcon build`.
# Idempotent: the venv is made only if missing, and pip runs only when
# requirements.txt changed since the last install (sha256 kept in
# .venv/.requirements.sha).  No ROS setup file needs to be sourced.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
root="$PWD"
venv="$root/.venv"
stamp="$venv/.requirements.sha"

if [[ ! -x "$venv/bin/python" ]]; then
    echo "setup_env: creating $venv"
    python3 -m venv "$venv"
fi

want="$(sha256sum requirements.txt | cut -d ' ' -f 1)"
have="$(cat "$stamp" 2>/dev/null || true)"
if [[ "$want" != "$have" ]]; then
    echo "setup_env: installing requirements.txt into .venv"
    "$venv/bin/python" -m pip install --disable-pip-version-check -q -r requirements.txt
    echo "$want" > "$stamp"
fi

# colcon and the interpreter it runs setup.py with must be the venv's.
export PATH="$venv/bin:$PATH"
colcon build \
    --build-base build --install-base install \
    --event-handlers console_cohesion- console_start_end- status- desktop_notification-
