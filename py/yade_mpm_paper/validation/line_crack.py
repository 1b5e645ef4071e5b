"""The pressurised line crack (paper Sec. 3.2, Figs. 7–9), measured: the elastic opening and the stress ahead
of the tips against Sneddon, and with damage the crack extension and its comparison with the paper's points
(Fig. 9), shared by scripts/paper/penny_crack.py (the runs) and scripts/paper/penny_crack_compare.py (tables
and plots over several runs)."""
import math

import numpy as np

from yade_mpm.fields import get
from yade_mpm_paper.validation import sneddon

PAPER_DA = [(0.1, 7), (0.2, 22), (0.4, 72)]   # Fig. 9: (t [s], Δa [cells of 0.02 m])
PAPER_CELL = 0.02                             # the paper's grid spacing [m]


def face_opening(s, geo):
    """Half crack opening (u_top − u_bot)/2 per column along the crack: (x − xc, u_y)."""
    u = get(s, "pos") - geo["x0"]
    t, b = geo["top"], geo["bot"]
    ot, ob = np.argsort(geo["x0"][t, 0]), np.argsort(geo["x0"][b, 0])
    x = geo["x0"][t[ot], 0] - geo["xc"]
    return x, 0.5 * (u[t[ot], 1] - u[b[ob], 1])


def elastic_profiles(s, geo, P, h, half_crack, young, poisson):
    """The elastic run against Sneddon at pressure P [Pa] (grid spacing h, crack half-length c [m], the rock's
    young [Pa] and poisson): the half opening u_y along the crack (x, uy) beside Eq. 43 (ua), its relative error at
    the centre and its relative L2 error; σ_yy, σ_xx on the crack line ahead of both tips (mean at each |x − xc|:
    xs, syy, sxx) beside Eq. 44 (sa) and the relative L2 error of σ_yy from 2 cells to 1 m ahead of the tip."""
    x, uy = face_opening(s, geo)
    ua = sneddon.opening_displacement(x, P, young, poisson, half_crack)
    centre = np.argsort(np.abs(x))[:2]
    uy_centre_err = (uy[centre].mean() - ua[centre].mean()) / ua[centre].mean()
    uy_l2 = math.sqrt(np.sum((uy - ua) ** 2) / np.sum(ua ** 2))
    # σ on the crack line ahead of both tips: the two particle rows at y = yc ± dp/2
    pos, st = geo["x0"], get(s, "stress")
    line = np.abs(pos[:, 1] - geo["yc"]) < geo["dp"] * 0.75
    xr = pos[line, 0] - geo["xc"]
    ahead = np.abs(xr) > half_crack
    xa = np.abs(xr[ahead])
    syy, sxx = st[line, 1][ahead], st[line, 0][ahead]
    order = np.argsort(xa)
    xa, syy, sxx = xa[order], syy[order], sxx[order]
    # mean over the 4 particles (2 rows × 2 tips) at each |x|
    xu, inv = np.unique(np.round(xa, 9), return_inverse=True)
    syy_m = np.bincount(inv, syy) / np.bincount(inv)
    sxx_m = np.bincount(inv, sxx) / np.bincount(inv)
    sa = sneddon.stress_ahead(xu, P, half_crack)
    far = (xu > half_crack + 2 * h) & (xu < half_crack + 1.0)   # beyond the smoothed tip zone
    syy_l2 = math.sqrt(np.sum((syy_m[far] - sa[far]) ** 2) / np.sum(sa[far] ** 2))
    return dict(uy_centre_err=uy_centre_err, uy_l2=uy_l2, syy_l2_far=syy_l2, x=x, uy=uy, ua=ua,
                xs=xu, syy=syy_m, sxx=sxx_m, sa=sa)


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
