#!/usr/bin/python3
"""How much a standing elastic wave loses through the particle velocity update: Eq. 6 as printed ('pic',
v_p = Σ ψ_i v_i) loses a share per step, 'flip' (v_p += Σ ψ_i Δv_i) keeps it (MUSL either way): a free 50 mm square block of the Miao sandstone (elastic), l = 2 mm, 2×2 particles per cell, set moving in a
standing shear wave v_y = A sin(k x) (with its velocity gradient), no damping, no bodies. The total energy (kinetic +
elastic) left after `--time` is written per velocity update, Courant number and wavelength. The loss is per step, not per unit time: a
smaller C loses more in the same time, so a run whose result is set by stress waves (crack growth after the first
damage) depends on C and does not converge as C → 0 (doc/reference/algorithm.md, "The particle velocity update and C").

    /usr/bin/python3 scripts/paper/pic_dissipation.py --out out/pic_dissipation            # C = 1, 0.5, 0.25, 0.125
Writes OUT/pic_dissipation.csv (velocity_update, courant, wavelength_cells, steps, time_us, energy_left).
"""
import argparse
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "py"))
import yade_mpm as ym  # noqa: E402
from yade_mpm import rocks  # noqa: E402
from yade_mpm.scene import check_courant, setting_choices  # noqa: E402


def energy_left(courant, wavelength_cells, t_end, l=2e-3, amplitude=0.1, velocity_update="pic"):
    """Energy after t_end over the energy at the start, and the number of steps taken (velocity_update: the
    solver's setting, 'pic' or 'flip')."""
    rock = rocks.elastic(rocks.MIAO2018_SANDSTONE)
    E, nu = rocks.MIAO2018_SANDSTONE["young"], rocks.MIAO2018_SANDSTONE["poisson"]
    s = ym.make_solver((0.0, 0.0), (0.05, 0.05), l, margin=2)
    ym.add_region(s, rock, (0.0, 0.0), (0.05, 0.05), ppc=2)
    s.courant, s.velocityUpdate = courant, velocity_update
    k = 2 * np.pi / (wavelength_cells * l)
    x = s.view("x0")
    s.view("v1")[:] = amplitude * np.sin(k * x)
    s.view("C2")[:] = amplitude * k * np.cos(k * x)            # ∂v_y/∂x of the wave (C row-major: C[1][0])
    del x

    def energy():
        m, v, sg, V = (ym.get(s, n) for n in ("mass", "vel", "stress", "volume"))
        ss = (sg[:, :3] ** 2).sum(1) + 2 * (sg[:, 3:] ** 2).sum(1)
        tr = sg[:, :3].sum(1)
        return 0.5 * (m * (v ** 2).sum(1)).sum() + (V * ((1 + nu) * ss - nu * tr ** 2) / (2 * E)).sum()

    e0 = energy()
    while s.time < t_end:
        s.run(1)
    return energy() / e0, s.steps


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/pic_dissipation", help="output folder")
    ap.add_argument("--courant", default="1,0.5,0.25,0.125", help="comma-separated Courant numbers")
    ap.add_argument("--wavelengths", default="25,8", help="comma-separated wavelengths [cells]")
    ap.add_argument("--time", type=float, default=100e-6, help="simulated time [s] (default 100 µs)")
    allowed = setting_choices("velocityUpdate")
    ap.add_argument("--velocity-update", default=",".join(allowed),
                    help="comma-separated velocity updates (default: every choice of Solver.velocityUpdate)")
    a = ap.parse_args()
    try:
        cs = [float(c) for c in a.courant.split(",")]
        ws = [float(w) for w in a.wavelengths.split(",")]
    except ValueError:
        ap.error("--courant and --wavelengths take comma-separated numbers")
    try:
        cs = [check_courant(c) for c in cs]     # the solver's declared range
    except ValueError as e:
        ap.error(str(e))
    if not all(w >= 2 for w in ws) or not a.time > 0:
        ap.error("--wavelengths ≥ 2 cells, --time > 0")
    us = a.velocity_update.split(",")
    if not all(u in allowed for u in us):
        ap.error(f"--velocity-update = {a.velocity_update!r}: comma-separated, each one of {', '.join(allowed)}")
    os.makedirs(a.out, exist_ok=True)
    path = os.path.join(a.out, "pic_dissipation.csv")
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["velocity_update", "courant", "wavelength_cells", "steps", "time_us", "energy_left"])
        for u in us:
            for lam in ws:
                for c in cs:
                    left, steps = energy_left(c, lam, a.time, velocity_update=u)
                    w.writerow([u, c, lam, steps, a.time * 1e6, f"{left:.4f}"])
                    f.flush()
                    print(f"{u}: C = {c:<6} wavelength {lam:g} cells: {steps} steps, energy left {left:.4f}", flush=True)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
