"""A test hook: hold a replay's process at a named moment, so that a test can kill it there.

With ``FASTSIM_REPLAY_PAUSE=MOMENT:DIR`` in a process's environment (``DIR``
an existing directory), the first process to reach ``MOMENT`` (one of
:data:`MOMENTS`) claims it (makes ``DIR/claimed``, atomically), writes its
pid to ``DIR/pid`` (renamed into place whole) and sleeps up to
:data:`PAUSE_S` seconds before going on: the test kills it meanwhile, at a
known point rather than after a guessed delay.  Every other arrival goes on
at once.  Unset (every real run): one look-up in ``os.environ``.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

#: the environment variable
ENV = "FASTSIM_REPLAY_PAUSE"
#: where a replay can be held: ``warm-up`` inside the warm-up of a worker's kernels (its
#: first task, its staging directory made), ``replay`` after the warm-up with the input
#: read and the staged outputs half written, ``commit`` between the renames of the
#: outputs into place (the bag renamed, the rest not), ``committed`` every output in place,
#: the result not yet returned
MOMENTS = ("warm-up", "replay", "commit", "committed")
#: a moment of an overwriting run only (``--overwrite``): an earlier run's output moved
#: aside, its successor not yet in its place
REPLACE = "replace"
#: how long a held process sleeps before going on (bounds a test whose kill never came)
PAUSE_S = 60.0


def pause(moment: str) -> None:
    """Hold this process at ``moment`` if :data:`ENV` asks for it and no other process did."""
    spec = os.environ.get(ENV)
    if not spec:
        return
    want, _, directory = spec.partition(":")
    if want != moment:
        return
    where = Path(directory)
    try:
        (where / "claimed").mkdir()
    except OSError:   # claimed already (or no such directory): go on
        return
    tmp = where / "pid.tmp"
    tmp.write_text(str(os.getpid()))
    tmp.rename(where / "pid")
    deadline = time.monotonic() + PAUSE_S
    while time.monotonic() < deadline:
        time.sleep(0.02)
