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

# colcon copies the package into install/ and never removes what the sources no
# longer have: a module moved or renamed would stay there beside its new place, and
# an older version's egg-info would keep its entry points (a console script could
# then start the old module).  So the installed tree keeps only files the sources
# have (numba's caches in __pycache__ stay), and only the egg-info colcon writes now;
# setuptools' staging copy in build/ is made afresh (it would copy the old files back).
rm -rf build/fastsim_ros/build/lib
for tree in install/fastsim_ros/lib/python3.*/site-packages; do
    [[ -d "$tree" ]] || continue
    for pkg in fastsim_ros msg_adapters; do
        [[ -d "$tree/$pkg" ]] || continue
        while IFS= read -r -d '' file; do
            rel="${file#"$tree"/}"
            [[ -e "$root/$rel" ]] || rm -f "$file"
        done < <(find "$tree/$pkg" -type f -not -path '*/__pycache__/*' -print0)
    done
    rm -rf "$tree"/fastsim_ros-*.egg-info
done

# colcon and the interpreter it runs setup.py with must be the venv's.
export PATH="$venv/bin:$PATH"
colcon build \
    --build-base build --install-base install \
    --event-handlers console_cohesion- console_start_end- status- desktop_notification-

# The installed console scripts run with nothing sourced: the venv's python
# finds the installed package (and its entry-point metadata) through a .pth
# file, and .venv/bin links the scripts, so `.venv/bin/fastsim_node` works.
site="$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_path("purelib"))')"
installed=(install/fastsim_ros/lib/python3.*/site-packages)
echo "$root/${installed[0]}" > "$site/fastsim_ros_install.pth"
for script in fastsim_node fastsim_lifecycle_node fastsim_replay fastsim_contact; do
    ln -sf "$root/install/fastsim_ros/lib/fastsim_ros/$script" "$venv/bin/$script"
done

# Fill numba's on-disk cache for the installed kernels (a cold compile takes
# about 18 s, the node's compiled patch path and transient rolling some 20 s
# more; a cached load a fraction of a second), so that the first start of the
# node reaches its first wrench quickly.  No-op when cached.
(cd / && "$venv/bin/python" -c \
    'from fastsim_ros.contact import compiled; compiled.warm_up()
from msg_adapters import patch; patch.warm_up()
from fastsim_ros.replay import batch; batch.warm_up()
from fastsim_ros.pipeline import kernels; kernels.warm_up()')
# The replay's own loops (the window's scan, the records writer) compile on a
# replay's first patches: one bundled bag replayed through the installed command
# line fills their cache too (a cold first replay otherwise takes some 15 s more).
warm_out="$(mktemp -d)"
"$venv/bin/fastsim_replay" bags/hertz_ramp -o "$warm_out/out" \
    --params bags/hertz_ramp.params.yaml --no-progress > /dev/null
rm -rf "$warm_out"
