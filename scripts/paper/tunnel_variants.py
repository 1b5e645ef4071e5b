#!/usr/bin/env python3
"""Variants of the arch-tunnel scene (paper Sec. 4) for the Fig. 17 ordering study in doc/validation/tunnel.md:
the axial stress at 0.25 / 0.5 / 0.75 / 1.0 mm (... up to --end-time) of platen displacement for one
case with the rock made elastic, DP without damage or the full DP–GK, and the filler's friction changed.

    yade -n -x scripts/paper/tunnel_variants.py --case filled_flaw --rock dp --spacing 0.002 --end-time 0.01
    yade -n -x scripts/paper/tunnel_variants.py --case filled_flaw --filler-friction 1.0 --spacing 0.001

The stress is the platen's contact reaction per metre / specimen width at the first step whose platen
displacement reaches each mark (no averaging: compare variants of this script with each other, not with
tunnel_spalling.py's curve, which averages over 0.01 mm). One JSON line `RESULT {...}` on stdout; with
--csv FILE it is also appended as a row. Scene, rock and filler come from yade_mpm_paper.cases / rocks."""
import argparse
import json
import os
import time

from yade_mpm import ContactParams, rocks, runner
from yade_mpm_paper import cases

MARKS_MM = (0.25, 0.5, 0.75, 1.0, 1.5, 2.0)
ROCKS = ("dpgk", "dp", "elastic")


def parse():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", default="filled_flaw", help=f"one of {', '.join(cases.TUNNEL_CASES)} (default filled_flaw)")
    ap.add_argument("--rock", default="dpgk", help="dpgk = rocks.pan2020_sandstone() (default), dp = the same without damage, "
                    "elastic = its E, ν, ρ only")
    ap.add_argument("--filler-friction", type=float, default=cases.FILLER_FRICTION,
                    help=f"μ_con of the rigid filler [-] (ContactParams.mu; default {cases.FILLER_FRICTION})")
    ap.add_argument("--spacing", type=float, default=0.002, help="grid spacing l [m] (default 0.002; paper 0.001)")
    ap.add_argument("--end-time", type=float, default=0.01, help="loading time [s], (0, 0.02] (default 0.01 = 1 mm)")
    ap.add_argument("--csv", default=None, help="append the result as a row of this CSV file")
    a = ap.parse_args()
    if a.case not in cases.TUNNEL_CASES:
        ap.error(f"--case {a.case!r} must be one of {cases.TUNNEL_CASES}")
    if a.rock not in ROCKS:
        ap.error(f"--rock {a.rock!r} must be one of {ROCKS}")
    try:
        ContactParams(mu=a.filler_friction)            # the range is declared once (pkg-mpm/contact/ContactParams.hpp)
    except ValueError as e:
        ap.error(f"--filler-friction: {e}")
    if not (0 < a.end_time <= cases.TUNNEL_END_TIME):
        ap.error(f"--end-time {a.end_time!r} s must be in (0, {cases.TUNNEL_END_TIME}]")
    return a


def rock(kind):
    if kind == "dp":
        return rocks.pan2020_sandstone(damage=False)
    if kind == "elastic":
        return rocks.elastic(rocks.PAN2020_SANDSTONE)
    return rocks.pan2020_sandstone()


def main():
    a = parse()
    from yade import O
    s, b = cases.arch_tunnel(a.case, a.spacing, material=rock(a.rock), filler_friction=a.filler_friction)
    marks = [m for m in MARKS_MM if m * 1e-3 <= cases.PLATEN_SPEED * a.end_time * (1 + 1e-9)]
    at = {}

    def record(solver):
        d = b["platen_displacement"]()
        for m in marks:
            if m not in at and d >= m * 1e-3 - 1e-12:
                at[m] = b["axial_stress"]() / 1e6

    label = f"{a.case}/{a.rock}/mu={a.filler_friction:g}/l={a.spacing * 1e3:g}mm"
    t0 = time.time()
    runner.run(s, end_time=a.end_time, progress=60, label=label, outputs=[runner.Output(record, steps=1)], advance=O.step)
    res = dict(case=a.case, rock=a.rock, filler_friction=a.filler_friction, spacing_m=a.spacing, particles=s.numParticles,
               steps=s.steps, wall_time_s=round(time.time() - t0, 1), stress_MPa_at_mm={f"{m:g}": at.get(m) for m in marks})
    print("RESULT", json.dumps(res), flush=True)
    if a.csv:
        cols = ["case", "rock", "filler_friction", "spacing_m", "particles", "steps", "wall_time_s"]
        row = [res[k] for k in cols] + [at.get(m) for m in marks]
        new = not os.path.exists(a.csv)
        with open(a.csv, "a") as f:
            if new:
                f.write(",".join(cols + [f"stress_MPa_at_{m:g}mm" for m in marks]) + "\n")
            f.write(",".join("" if v is None else str(v) for v in row) + "\n")


if __name__ == "__main__":
    main()
