"""Reading the text files of ``fastsim_contact``: the patch CSV and its lines and fields.

One reader for every file the commands take (``forces``' and ``coefficients``'
``--patch``, ``estimate``'s ``--measured``): at most :data:`MAX_PATCH_BYTES`,
UTF-8 text, CSV rows with their line numbers, finite numbers; each refusal
one line naming the file, the line and the problem.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from fastsim_ros.cli.options import LIMITS, MAX_CELLS
from fastsim_ros.contact import area as areas
from fastsim_ros.contact.errors import ContactError, InvalidInputError

#: the most cells the grid of a patch file may span (its cells' bounding box at
#: their spacing): 400 x 400, the largest ``--cells`` grid
MAX_PATCH_CELLS = MAX_CELLS * MAX_CELLS
#: the largest patch file read (bytes): far more than MAX_PATCH_CELLS rows need
MAX_PATCH_BYTES = 64 * 2**20


def text_lines(path: Path, what: str = "patch file") -> list[str]:
    """Return the lines of a text file: at most MAX_PATCH_BYTES, UTF-8 (a BOM is dropped).

    ``what`` names the file in the errors (``patch file``, ``measured file``).
    """
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_PATCH_BYTES + 1)
    except OSError as e:
        raise InvalidInputError(f"cannot read {what} {path}: {e.strerror}") from None
    if len(raw) > MAX_PATCH_BYTES:
        raise InvalidInputError(f"{path}: larger than {MAX_PATCH_BYTES // 2**20} MiB, more "
                                f"than a {what} may be")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise InvalidInputError(f"{path}: not UTF-8 text (byte 0x{raw[e.start]:02x} at "
                                f"offset {e.start})") from None
    if "\x00" in text:
        raise InvalidInputError(f"{path}: a NUL byte: not a text file")
    return text.splitlines()


def csv_rows(path: Path, lines: list[str]) -> Iterator[tuple[int, list[str]]]:
    """Yield ``(line number, fields)`` of the non-blank, non-comment lines."""
    # comment lines become blank ones, so that the reader's line numbers stay the file's
    reader = csv.reader("" if ln.lstrip().startswith("#") else ln for ln in lines)
    try:
        for fields in reader:
            if any(c.strip() for c in fields):
                yield reader.line_num, fields
    except csv.Error as e:
        raise InvalidInputError(f"{path}, line {reader.line_num}: {e}") from None


def number(path: Path, line: int, name: str, text: str) -> float:
    """Return the finite number ``text``, field ``name`` of ``path``'s line ``line``."""
    try:
        v = float(text)
    except ValueError:
        shown = text.strip()[:30] or "an empty field"
        raise InvalidInputError(f"{path}, line {line}: {name} is not a number: "
                                f"{shown!r}") from None
    if not math.isfinite(v):
        raise InvalidInputError(f"{path}, line {line}: NaN or infinite {name} {text.strip()!r}")
    return v


def read_patch(path: Path, *, max_cells: int = MAX_PATCH_CELLS) -> areas.GridArea:
    """Read a patch CSV (header ``x,y,pressure``; m, m, Pa) into a grid area.

    Refused (:class:`InvalidInputError`, one line naming the file, the line
    and the problem): a file that cannot be read, is larger than
    :data:`MAX_PATCH_BYTES` or is not UTF-8 text (a UTF-8 BOM is fine), a
    wrong header, a row without exactly three values, a value that is not a
    finite number, a negative pressure, a coordinate beyond
    ``LIMITS["coordinate"]``, cells off one regular grid, and cells whose grid
    would span more than ``max_cells`` cells (checked before it is allocated).
    """
    rows = csv_rows(path, text_lines(path))
    first = next(rows, None)
    if first is None:
        raise InvalidInputError(f"{path}: empty (no header x,y,pressure)")
    if [c.strip() for c in first[1]] != ["x", "y", "pressure"]:
        shown = ",".join(first[1])[:40]
        raise InvalidInputError(f"{path}, line {first[0]}: the header must be x,y,pressure, "
                                f"not {shown!r}")
    values: list[tuple[float, float, float]] = []
    coordinate_max = LIMITS["coordinate"][1]
    for line, fields in rows:
        if len(fields) != 3:
            kind = "a short row" if len(fields) < 3 else "a long row"
            raise InvalidInputError(f"{path}, line {line}: {kind}: {len(fields)} values where "
                                    "x,y,pressure needs 3")
        x, y, p = (number(path, line, name, text)
                   for name, text in zip(("x", "y", "pressure"), fields))
        if p < 0.0:
            raise InvalidInputError(f"{path}, line {line}: negative pressure {p:g} Pa")
        if max(abs(x), abs(y)) > coordinate_max:
            raise InvalidInputError(f"{path}, line {line}: coordinate ({x:g}, {y:g}) m beyond "
                                    f"the {coordinate_max:g} m the command line accepts")
        values.append((x, y, p))
        if len(values) > max_cells:
            raise InvalidInputError(f"{path}: more than {max_cells:,} cells")
    if not values:
        raise InvalidInputError(f"{path}: no cells")
    data = np.array(values)
    try:
        patch = areas.from_cells(data[:, 0], data[:, 1], data[:, 2], max_cells=max_cells)
    except ContactError as e:
        raise type(e)(f"{path}: {e}") from None
    lo, hi = LIMITS["length"]
    if not (lo <= patch.dx <= hi and lo <= patch.dy <= hi):
        raise InvalidInputError(f"{path}: cells of {patch.dx:.4g} m x {patch.dy:.4g} m: cell "
                                f"sizes must lie in [{lo:g}, {hi:g}] m")
    return patch
