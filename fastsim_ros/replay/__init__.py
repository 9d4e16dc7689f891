"""``fastsim_replay``: replay recorded bags offline through the node's pipeline.

Usage (docs/guide_replay.md)::

    fastsim_replay IN [IN ...] -o OUT [--params FILE] [--namespace NS] [--plot] [--csv]
                   [--overwrite] [--jobs N | --scheduler ADDRESS]

Each ``IN`` (a rosbag2 directory, or a single ``.mcap``) named ``NAME`` (the
directory's name, or the file's without ``.mcap``) gives:

- ``OUT/NAME/``: a rosbag2 bag (version 9, MCAP, zstd chunk compression)
  with the input's topics copied (an input message on one of the node's
  output topics is not copied) and the node's outputs on the node's topic
  names, each logged at the log time of the patch that gave it:
  ``/contact/<name>/wrench``, ``creepage``, ``frame`` (and ``traction``
  when asked for), ``/wheelset/wrench``, ``/contact/markers`` and
  ``/diagnostics`` (one array each time the log time passes a whole second
  since the first message, stamped with that message's log time, and one
  at the end).  Output connections offer the node's publisher QoS
  (``output_reliability``, keep last ``qos_depth``: reliable, 10 by
  default).  The metadata's ``custom_data`` holds ``fastsim.parameters``
  (JSON of every checked parameter, defaults filled), ``fastsim.input``
  (the input's path) and ``fastsim.replay`` (this program).
- with ``--plot``, ``OUT/NAME.png``: per contact, Fx and Fy against time
  (with +-mu N dashed, mu the one in force: the given one, or with friction
  estimation the estimate each wrench was solved with; the title says
  which) and against the creepage that varies most on that contact
  (``phi`` counted as ``phi * 5 mm``, a typical semi-axis, when comparing
  spreads); with friction estimation a last row, the estimate with +-2
  sigma and the wheelset's adhesion utilisation against time.
- with ``--csv``, ``OUT/NAME.csv``: one row per wrench, header
  :data:`CSV_HEADER`; floats in Python's shortest round-trip form.  A
  ``no_contact`` row (an empty patch, zero wrench) has ``N, Fx, Fy, Mz`` =
  0 and ``xi, eta, phi, V, slip_fraction`` blank (undefined: no contact).
  With ``wear_outputs: true`` the columns
  :data:`~fastsim_ros.replay.records.WEAR_COLUMNS` follow (the
  ``contact/<name>/energy`` and ``damage`` values, docs/guide_wear.md) and
  the summary has a wear line per contact.
- with ``--csv`` and ``friction_estimation: on``, ``OUT/NAME.friction.csv``:
  one row per ``friction/estimate`` message, header
  :data:`~fastsim_ros.replay.records.FRICTION_CSV_HEADER` (``stamp_ns, mu,
  sigma, utilisation, status``; the utilisation the wheelset's, ``sum |(Fx,
  Fy)| / (mu sum N)``).  A target of the input with ``--csv`` whether or not
  estimation runs (an existing one is refused, or replaced with
  ``--overwrite``: none stays beside a CSV of another run).

The summary (stdout), per input: the contacts' patches, wrenches and
rejections; each input topic the node could take but did not (a patch
topic of a contact not configured, or under another namespace, the
measured wrench with estimation off, poses and loads with patches from
topics) with its messages and the parameter or flag that takes it; the
twists; with friction estimation the estimate's path (its start, the steps
of ``mu_s`` it saw, where it settled before each, its last value and
sigma, the estimates by status); each output topic with its messages and
where they went (the bag and a CSV, or the bag only); the replay's speed.

Messages are fed to :class:`~fastsim_ros.pipeline.Pipeline` in the bag's
log-time order, raw CDR as read.  Topic names resolve as ROS resolves them:
a bag's relative names are in the root namespace, the node's in
``--namespace`` (default ``/``: patches on ``NS/contact/<name>/patch``,
outputs under ``NS``, ``/diagnostics`` absolute).  Without ``--params``
every parameter has its default and the contacts are those with a
``NS/contact/<name>/patch`` topic in the bag, in the bag's order (the
summary names them).  Everything is written under a temporary name inside ``OUT``
and renamed at the end; on failure, Ctrl-C or SIGTERM nothing is left of
an unfinished input (inputs already done, whose summaries were printed, stay).
A target that exists is refused before any work, unless ``--overwrite``:
then each earlier output is moved aside once its successor is complete
and removed at the end, or moved back if the run fails.
A progress bar (tqdm, on stderr) appears when stderr is a terminal, ``--jobs``
is 1 and a bag takes more than a second.

Exit status: 0 all done; 2 bad flags, a bad params file, two inputs with the
same NAME or a target that exists without ``--overwrite`` (all before any
work), or a bad, corrupt, truncated or empty input (the others are still
done); 1 an output that could not be written or an internal error; 130
interrupted.  Every problem is one
line on stderr naming the file.

``--jobs N`` replays N inputs at a time on this machine (a fork pool);
``--scheduler ADDRESS`` each input as a task on a Dask distributed cluster
(:mod:`~fastsim_ros.replay.cluster`).  IN and OUT may be fsspec URLs
(:mod:`~fastsim_ros.replay.storage`).

The package, each module one concern (dependencies point down):

- :mod:`~fastsim_ros.replay.cli`: flags, checks before any work, the summary;
- :mod:`~fastsim_ros.replay.executors` (this process, a local pool) and
  :mod:`~fastsim_ros.replay.cluster` (Dask): where tasks run, the one seam
  between the command line and one input's replay;
- :mod:`~fastsim_ros.replay.run`: one input, replayed and committed
  atomically (:mod:`~fastsim_ros.replay.storage` for URLs);
- :mod:`~fastsim_ros.replay.bulk`: an indexed MCAP input by the chunk,
  :mod:`~fastsim_ros.replay.batch` (the pipeline's rules over runs of
  messages), :mod:`~fastsim_ros.replay.encode` (outputs in bulk),
  :mod:`~fastsim_ros.replay.mcap` (MCAP by the chunk),
  :mod:`~fastsim_ros.replay.kernels` (their compiled loops);
- :mod:`~fastsim_ros.replay.records` (CSV rows, plot samples),
  :mod:`~fastsim_ros.replay.plot`, :mod:`~fastsim_ros.replay.results`
  (:class:`Result`, its summary), :mod:`~fastsim_ros.replay.bagio`
  (rosbags reading and writing), :mod:`~fastsim_ros.replay.errors`.
"""

from fastsim_ros.pipeline import Pipeline, output_topics
from fastsim_ros.replay.bagio import input_name
from fastsim_ros.replay.cli import main, parser
from fastsim_ros.replay.errors import BadInput, OutputError
from fastsim_ros.replay.records import CSV_HEADER
from fastsim_ros.replay.results import Profile, Result
from fastsim_ros.replay.run import (PARAMETERS_KEY, PROG, Task, bag_contacts, replay_bag,
                                    resolve, run_task, targets)

__all__ = ["BadInput", "CSV_HEADER", "OutputError", "PARAMETERS_KEY", "PROG", "Pipeline",
           "Profile", "Result", "Task", "bag_contacts", "input_name", "main", "output_topics",
           "parser", "replay_bag", "resolve", "run_task", "targets"]
