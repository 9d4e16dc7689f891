"""The seed paper's Tables 1 and 2 as printed (a reference file the package does not ship).

Alonso & Giménez (2007), Table 2: ASM (Knothe & Hung) beside Kalker's
asymptotic method (AMK), nu = 0.25, printed in two blocks whose labels are
swapped.  The reading, pinned by a test against Kalker's own table: the
first block (``b<a``, g = 0.1..0.9) is at ``a/b = g``, the second (``b>a``,
g = 1..0.1) at ``a/b = 1/g`` (``a`` along the rolling direction, as the
command line's ``--a-over-b``).  So Table 2's row g of the first block is
``fastsim_contact coefficients --shape ellipse --a-over-b g``, a row g of the
second ``--a-over-b 1/g``.

Table 1 (DLM beside AMK at a/b = 0.1, 1, 10) is printed in pairs whose first
number is Kalker's; the reference file states DLM's numbers (the second of
each pair) and AMK's in one sentence, which :func:`read_table1` reads.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from fastsim_ros.contact.errors import InvalidInputError


@dataclass(frozen=True)
class Table2Row:
    """One printed row of Table 2 at ``a_over_b`` (its block and printed ``g`` kept)."""

    block: str
    g: float
    a_over_b: float
    asm: tuple[float, float, float]
    amk: tuple[float, float, float]


def read_table2(path: Path | str) -> list[Table2Row]:
    """Return Table 2's rows from the reference file's markdown table, a/b mapped."""
    rows: list[Table2Row] = []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 8 or cells[0] not in ("b<a", "b>a"):
            continue
        try:
            g, *v = (float(c) for c in cells[1:])
        except ValueError:
            raise InvalidInputError(f"{path}: not a Table 2 row: {line!r}") from None
        a_over_b = g if cells[0] == "b<a" else 1.0 / g
        rows.append(Table2Row(cells[0], g, a_over_b, (v[0], v[1], v[2]), (v[3], v[4], v[5])))
    if len(rows) != 19:
        raise InvalidInputError(f"{path}: Table 2 has 19 rows, read {len(rows)}")
    return rows


@dataclass(frozen=True)
class Table1Row:
    """Table 1 at ``a_over_b``: DLM's ``(C11, C22, C23)`` and AMK's (Kalker's), as printed."""

    a_over_b: float
    dlm: tuple[float, float, float]
    amk: tuple[float, float, float]


_NUMBERS = r"([0-9.]+),\s*([0-9.]+),\s*([0-9.]+)"
_TRIPLE = rf"C11\s+{_NUMBERS};\s*C22\s+{_NUMBERS};\s*C23\s+{_NUMBERS}"


def read_table1(path: Path | str) -> list[Table1Row]:
    """Return Table 1's three rows from the reference file's sentence on it.

    ``a/b = g1, g2, g3 -> C11 .., .., ..; C22 ...; C23 ... (AMK: C11 ...; C22 ...;
    C23 ...)``, read across line breaks.
    """
    text = " ".join(Path(path).read_text(encoding="utf-8").split())
    m = re.search(rf"a/b = {_NUMBERS} -> {_TRIPLE} \(AMK: {_TRIPLE}\)", text)
    if m is None:
        raise InvalidInputError(f"{path}: Table 1's sentence (DLM and AMK values) not found")
    v = [float(x) for x in m.groups()]
    gs, dlm, amk = v[0:3], v[3:12], v[12:21]
    return [Table1Row(g, (dlm[i], dlm[3 + i], dlm[6 + i]), (amk[i], amk[3 + i], amk[6 + i]))
            for i, g in enumerate(gs)]
