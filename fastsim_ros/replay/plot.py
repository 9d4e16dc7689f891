"""The replay's plot (``--plot``): per contact, Fx and Fy against time and against creepage.

Against time with +-mu N dashed; against the creepage that varies most on
that contact (``phi`` counted as ``phi * 5 mm``, a typical semi-axis, when
comparing spreads).  matplotlib is imported only when a plot is drawn.
"""

from __future__ import annotations

from pathlib import Path

from fastsim_ros.replay.records import Series

#: semi-axis (m) that puts phi on the scale of xi and eta when picking the plot's abscissa
PHI_SCALE = 5e-3


def write_plot(path: Path, name: str, contacts: tuple[str, ...],
               series: dict[str, Series], mu: float) -> None:
    """Draw the contacts' series into the PNG ``path`` (``mu``: for the +-mu N lines)."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    rows = max(1, len(contacts))
    fig = Figure(figsize=(11, 3.2 * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, 2, squeeze=False)
    fig.suptitle(f"{name}: creep forces of the rail on the wheel (mu = {mu:g})")
    for row, c in enumerate(contacts):
        t, xi, eta, phi, fx, fy, n = (np.asarray(col) for col in series[c].cols)
        left, right = axes[row]
        left.set_title(f"{c}: against time")
        right.set_title(f"{c}: against creepage")
        if t.size == 0:
            for ax in (left, right):
                ax.text(0.5, 0.5, "no wrench", ha="center", va="center",
                        transform=ax.transAxes)
            continue
        left.plot(t, fx * 1e-3, ".", ms=2, label="Fx")
        left.plot(t, fy * 1e-3, ".", ms=2, label="Fy")
        left.plot(t, mu * n * 1e-3, "k--", lw=0.8, label="+-mu N")
        left.plot(t, -mu * n * 1e-3, "k--", lw=0.8)
        left.set_xlabel("time since the first message (s)")
        left.set_ylabel("force (kN)")
        left.legend(loc="best", fontsize="small")
        solved = np.isfinite(xi)
        spreads = [float(np.ptp(v[solved])) if solved.any() else 0.0
                   for v in (xi, eta, phi * PHI_SCALE)]
        k = int(np.argmax(spreads))
        label = ("xi", "eta", "phi (1/m)")[k]
        x = (xi, eta, phi)[k]
        right.plot(x[solved], fx[solved] * 1e-3, ".", ms=2, label="Fx")
        right.plot(x[solved], fy[solved] * 1e-3, ".", ms=2, label="Fy")
        right.axhline(0.0, color="0.6", lw=0.6)
        right.set_xlabel(label)
        right.set_ylabel("force (kN)")
        right.legend(loc="best", fontsize="small")
        for ax in (left, right):
            ax.grid(True, lw=0.3)
    fig.savefig(str(path), dpi=110, format="png")
