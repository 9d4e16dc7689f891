#!/usr/bin/env python3
"""Write fastsim_ros/data/example_patch.csv: the flange-root sample patch (50 kN, steel).

The patch is the exact normal solution of ``samples.flange_root_gap`` on 40 x 40
cells, cropped to the contact; one row per cell in contact, ``x,y,pressure``
(m, m, Pa), origin at the point of first contact.
"""

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from fastsim_ros.contact import samples  # noqa: E402


def main() -> int:
    ar = samples.flange_root_patch(cells=40)
    jj, ii = np.nonzero(ar.mask)
    out = ROOT / "fastsim_ros" / "data" / "example_patch.csv"
    with open(out, "w") as f:
        f.write("# Flange-root contact patch: exact normal solution of a gap with 0.46 m wheel\n"
                "# radius along x and 0.3 m / 0.03 m lateral radii (tread / flange side), 50 kN,\n"
                "# G = 8e10 Pa, nu = 0.28. Made by: python scripts/make_example_patch.py\n")
        f.write("x,y,pressure\n")
        for j, i in zip(jj, ii):
            f.write(f"{float(ar.x[i])!r},{float(ar.y[j])!r},{float(ar.pressure[j, i])!r}\n")
    print(f"{out}: {jj.size} cells, N = {ar.load:.6g} N, area = {ar.area * 1e6:.4g} mm^2")
    return 0


if __name__ == "__main__":
    sys.exit(main())
