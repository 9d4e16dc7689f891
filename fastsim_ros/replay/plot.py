"""The replay's plot (``--plot``): per contact, Fx and Fy against time and against creepage.

Against time with +-mu N dashed, mu the static coefficient in force at each
time: the given ``friction_coefficient``, or with friction estimation the
estimate of the rig cycle before (what the wrench was solved with); the
title says which.  Against the creepage that varies most on that contact
(``phi`` counted as ``phi * 5 mm``, a typical semi-axis, when comparing
spreads).  With friction estimation, a last row: the estimate with its
+-2 sigma band, and the adhesion utilisation, against time.  matplotlib is
imported only when a plot is drawn.
"""

from __future__ import annotations

from pathlib import Path

from fastsim_ros.replay.records import Series

#: semi-axis (m) that puts phi on the scale of xi and eta when picking the plot's abscissa
PHI_SCALE = 5e-3


def title(name: str, mu: float, law: str, estimates: Series | None) -> str:
    """Return the plot's title: which mu bounds the forces (given, or estimated: start, last)."""
    symbol = "mu" if law == "constant" else "mu_s"
    if estimates is None:
        return (f"{name}: creep forces of the rail on the wheel (+-{symbol} N, {symbol} = "
                f"{mu:g} given)")
    last = estimates.cols[1]
    end = f", {last[-1]:.3g} last" if len(last) else ", no estimate published"
    return (f"{name}: creep forces of the rail on the wheel (+-{symbol} N, {symbol} estimated "
            f"online: {mu:g} at the start{end})")


def write_plot(path: Path, name: str, contacts: tuple[str, ...], series: dict[str, Series],
               mu: float, law: str = "constant", estimates: Series | None = None) -> None:
    """Draw the contacts' series into the PNG ``path``.

    ``mu``: the given coefficient (the estimate's start); ``law``: the
    friction law (``mu_s`` is named where it is slip-dependent);
    ``estimates``: the friction estimate's samples (``t, mu, sigma,
    utilisation``) when estimation ran.
    """
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    symbol = "mu" if law == "constant" else "mu_s"
    rows = max(1, len(contacts)) + (estimates is not None)
    fig = Figure(figsize=(11, 3.2 * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, 2, squeeze=False)
    fig.suptitle(title(name, mu, law, estimates))
    for row, c in enumerate(contacts):
        t, xi, eta, phi, fx, fy, n, mu_t = (np.asarray(col) for col in series[c].cols)
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
        left.plot(t, mu_t * n * 1e-3, "k--", lw=0.8, label=f"+-{symbol} N")
        left.plot(t, -mu_t * n * 1e-3, "k--", lw=0.8)
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
    if estimates is not None:
        t, mu_e, sigma, used = (np.asarray(col) for col in estimates.cols)
        left, right = axes[-1]
        left.set_title(f"friction estimate: {symbol} against time")
        right.set_title("the wheelset's adhesion utilisation |F| / (mu N)")
        left.fill_between(t, mu_e - 2.0 * sigma, mu_e + 2.0 * sigma, color="C0", alpha=0.25,
                          lw=0, label="+-2 sigma")
        left.plot(t, mu_e, "-", color="C0", lw=1.0, label=symbol)
        left.set_ylabel(symbol)
        right.plot(t, used, ".", ms=2, color="C2")
        right.axhline(1.0, color="0.6", lw=0.6)
        right.set_ylabel("utilisation")
        for ax in (left, right):
            ax.set_xlabel("time since the first message (s)")
            ax.grid(True, lw=0.3)
        left.legend(loc="best", fontsize="small")
    fig.savefig(str(path), dpi=110, format="png")
