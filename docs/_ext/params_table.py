"""Sphinx directive ``fastsim-parameters``: the node's parameters as a table.

The table is built at documentation build time from
:data:`fastsim_ros.ros.params.PARAMETERS`, the declarations the node and the
replay check against, so the guide cannot drift from the code.  Options:
``:start: prefix`` keeps the parameters whose name starts with one of the
space-separated prefixes; ``:names: a b c`` keeps those names in that order.
"""

from __future__ import annotations

from typing import Any

from docutils import nodes
from docutils.parsers.rst import Directive, directives


def _default(value: Any) -> str:
    """Return a parameter's default as it is written in a params file."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, tuple):
        return "[" + ", ".join(str(v) for v in value) + "]"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _row(cells: list[nodes.Node | str]) -> nodes.row:
    row = nodes.row()
    for cell in cells:
        entry = nodes.entry()
        if isinstance(cell, str):
            entry += nodes.paragraph(text=cell)
        else:
            entry += nodes.paragraph("", "", cell)
        row += entry
    return row


class ParametersTable(Directive):
    """Emit the table of ``fastsim_ros.ros.params.PARAMETERS`` (name, type, default, ...)."""

    has_content = False
    option_spec = {"start": directives.unchanged, "names": directives.unchanged}

    def run(self) -> list[nodes.Node]:
        """Build the table node."""
        from fastsim_ros.ros.params import PARAMETERS, SPECS

        specs = list(PARAMETERS)
        if "names" in self.options:
            specs = [SPECS[name] for name in self.options["names"].split()]
        elif "start" in self.options:
            prefixes = tuple(self.options["start"].split())
            specs = [spec for spec in specs if spec.name.startswith(prefixes)]
        if not specs:
            raise self.error("fastsim-parameters: no parameter selected")
        headers = ["name", "type", "default", "allowed", "at run time", "what"]
        widths = [18, 8, 12, 18, 8, 36]
        table = nodes.table()
        group = nodes.tgroup(cols=len(headers))
        table += group
        for width in widths:
            group += nodes.colspec(colwidth=width)
        head = nodes.thead()
        head += _row(headers)
        group += head
        body = nodes.tbody()
        for spec in specs:
            body += _row([nodes.literal(text=spec.name), spec.kind,
                          nodes.literal(text=_default(spec.default)), spec.allowed(),
                          "yes" if spec.dynamic else "start only", spec.description])
        group += body
        return [table]


def setup(app: Any) -> dict[str, Any]:
    """Register the directive."""
    app.add_directive("fastsim-parameters", ParametersTable)
    return {"version": "1", "parallel_read_safe": True}
