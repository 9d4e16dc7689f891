"""``fastsim_contact``: one-off contact computations from the command line.

Four commands: ``coefficients`` prints an area's generalised
creepage coefficients, ``forces`` the creep forces at given creepages,
``wheelset`` a wheelset's patches and creep forces from wheel and rail profiles
(:mod:`fastsim_ros.cli.wheelset`), and ``estimate`` fits the friction law to
measured creep forces (:mod:`fastsim_ros.cli.estimate`); ``coefficients`` and
``forces`` are :mod:`fastsim_ros.cli.patch`, the flags, limits and checks they
share :mod:`fastsim_ros.cli.options`, the reading of their text files
:mod:`fastsim_ros.cli.patch_files`.  SI units throughout.  ``--json`` prints
exactly one JSON object on stdout.  Bad input gives one line on stderr and
exit status 2, never a traceback, and no non-finite number is ever printed as
a result.

Which solver each ``--method`` runs: :mod:`fastsim_ros.cli.patch`.

Defaults are one set, the node's (:func:`~fastsim_ros.cli.options.node_default` reads
:data:`fastsim_ros.ros.params.PARAMETERS`): method (``coefficients``: ``exact``,
the exact theory's numbers), Poisson ratio, shear modulus, friction law,
bound; each ``--help`` shows them.  Values that are valid but implausible
for wheel-rail contact in the stated unit (semi-axes, patch extent and
pressure, load, creepages, friction, shear modulus:
:data:`fastsim_ros.ros.plausibility.PLAUSIBILITY`) are refused before any solve,
in one line naming the likely unit mistake, unless ``--allow-implausible``.

What the command line accepts is bounded (:data:`~fastsim_ros.cli.options.LIMITS`,
:data:`~fastsim_ros.cli.patch_files.MAX_PATCH_CELLS`,
:data:`~fastsim_ros.cli.options.MAX_STRIP_CELLS`,
:data:`~fastsim_ros.cli.options.MAX_EXACT_FORCE_CELLS`): every real contact lies
far inside, and inside them no intermediate quantity can overflow or underflow,
and no grid or operator outgrows memory; each bound is checked before the
arrays it limits are allocated.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from fastsim_ros.cli import estimate, patch, wheelset
from fastsim_ros.cli.options import Parser, finite
from fastsim_ros.contact.errors import ContactError
from fastsim_ros.errors import UsageError

#: each command's run (the arguments to a result) and readable table of the result
_COMMANDS: dict[str, tuple[Callable[[argparse.Namespace], dict[str, Any]],
                           Callable[[dict[str, Any]], None]]] = {
    "coefficients": (patch.coefficients, patch.print_coefficients),
    "forces": (patch.forces, patch.print_forces),
    "wheelset": (wheelset.run, wheelset.print_table),
    "estimate": (estimate.run, estimate.print_table),
}


def build_parser() -> argparse.ArgumentParser:
    """Return the parser of the commands and their fixed flags."""
    parser = Parser(prog="fastsim_contact",
                    description="Creepage coefficients and creep forces of a contact area.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    patch.add_parsers(sub)
    wheelset.add_parser(sub, finite)
    estimate.add_parser(sub, finite)
    return parser


def _run(argv: Sequence[str] | None) -> tuple[argparse.Namespace, dict[str, Any]]:
    args = build_parser().parse_args(argv)
    with np.errstate(all="ignore"):
        return args, _COMMANDS[args.command][0](args)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``fastsim_contact``: 0 on success, 2 on bad input, 1 on an internal error."""
    try:
        # a warning is never the answer: the checks and the finite-result guard are
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            args, result = _run(argv)
        text = json.dumps(result, allow_nan=False) if args.json else None
    except (UsageError, ContactError) as e:
        print(f"fastsim_contact: error: {e}", file=sys.stderr)
        return 2
    except SystemExit as e:  # --help
        return int(e.code or 0)
    except KeyboardInterrupt:
        return 130
    except MemoryError:
        print("fastsim_contact: error: out of memory", file=sys.stderr)
        return 2
    except Exception as e:  # a bug, not bad input: still one line, no traceback
        print(f"fastsim_contact: internal error: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    try:
        if text is not None:
            print(text)
        else:
            _COMMANDS[args.command][1](result)
        sys.stdout.flush()
    except BrokenPipeError:  # e.g. piped into head
        _quiet_stdout()
        return 0
    except OSError as e:  # a full disk, a closed descriptor: one line, not a traceback
        _quiet_stdout()
        print(f"fastsim_contact: error: cannot write the answer: {e.strerror or e}",
              file=sys.stderr)
        return 1
    return 0


def _quiet_stdout() -> None:
    """Point stdout at the null device: the interpreter's last flush at exit fails again."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass
