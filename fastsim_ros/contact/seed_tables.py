"""The seed paper's Tables 1 and 2 as printed (``shared/reference/seed_tables_1_2.md``).

Alonso & Giménez (2007), Table 2: ASM (Knothe & Hung) beside Kalker's
asymptotic method (AMK), nu = 0.25, printed in two blocks whose labels are
swapped.  The reading, pinned by a test against Kalker's own table: the
first block (``b<a``, g = 0.1..0.9) is at ``a/b = g``, the second (``b>a``,
g = 1..0.1) at ``a/b = 1/g`` (``a`` along the rolling direction, as the
command line's ``--a-over-b``).  So Table 2's row g of the first block is
``fastsim_contact coefficients --shape ellipse --a-over-b g``, a row g of the
second ``--a-over-b 1/g``.
"""

from __future__ import annotations

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
