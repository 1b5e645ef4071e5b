"""The pressurised line crack with damage (paper Sec. 3.2, Fig. 9): the measured crack extension and its
comparison with the paper's points, shared by scripts/paper/penny_crack.py (the runs) and
scripts/paper/penny_crack_compare.py (tables and plots over several runs)."""
import math

import numpy as np

from yade_mpm.fields import get

PAPER_DA = [(0.1, 7), (0.2, 22), (0.4, 72)]   # Fig. 9: (t [s], Δa [cells of 0.02 m])
PAPER_CELL = 0.02                             # the paper's grid spacing [m]


def crack_extension(s, geo, band):
    """Δa [cells of this grid] at the left and right tips: contiguous columns of grid cells beyond the
    initial tip holding at least one fully damaged (D = 1) particle within |y − yc| < band [m]
    (geo: the crack geometry of ``cases.line_crack``)."""
    pos, dmg = get(s, "pos"), get(s, "damage")
    broken = (dmg >= 1.0) & (np.abs(pos[:, 1] - geo["yc"]) < band)
    res = []
    for side in (-1, 1):
        d = side * (pos[broken, 0] - geo["xc"]) - geo["half_length"]
        cols = set(np.floor(d[d >= 0] / geo["h"]).astype(int).tolist())
        k = 0
        while k in cols:
            k += 1
        res.append(k)
    return res


def interp_da(rows, t):
    """Δa (left, right) of the last record (t, …, left, right) at or before paper time t."""
    best = None
    for r in rows:
        if r[0] <= t + 1e-9:
            best = r
    return (best[2], best[3]) if best else (0, 0)


def paper_comparison(rows, h):
    """Δa in cells of the paper's grid (0.02 m) at the paper's times, its deviations from Fig. 9 (RMS and
    largest, cells), and the initiation time (first record with Δa ≥ 1 cell of this grid at either tip)."""
    cells = h / PAPER_CELL
    da = [0.5 * sum(interp_da(rows, t)) * cells for t, _ in PAPER_DA]
    dev = [d - n for d, (_, n) in zip(da, PAPER_DA)]
    init = next((r[0] for r in rows if max(r[2], r[3]) >= 1), None)
    return dict(da_paper_cells=da, deviation_cells=dev, rms_deviation_cells=math.sqrt(sum(x * x for x in dev) / len(dev)),
                max_abs_deviation_cells=max(abs(x) for x in dev), initiation_t_paper_s=init,
                symmetric=all(abs(r[2] - r[3]) <= 1 for r in rows),
                monotonic=all(b[2] >= a[2] and b[3] >= a[3] for a, b in zip(rows, rows[1:])))
